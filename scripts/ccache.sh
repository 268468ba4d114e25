# Sourced by the build scripts: compile through ccache when it is installed
# (scripts/setup-deps.sh installs it), with paths hashed relative to the
# checkout so that every clone of the project shares one cache. Sets `launcher`
# to the cmake arguments (empty without ccache).
launcher=()
if command -v ccache >/dev/null 2>&1; then
  export CCACHE_BASEDIR="${CCACHE_BASEDIR:-$PWD}" CCACHE_NOHASHDIR=1
  export CCACHE_MAXSIZE="${CCACHE_MAXSIZE:-20G}"
  # The precompiled headers (MPMTB_PCH) are cacheable only with these.
  export CCACHE_SLOPPINESS="${CCACHE_SLOPPINESS:-pch_defines,time_macros,include_file_mtime,include_file_ctime}"
  launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
fi
