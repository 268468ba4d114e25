# Sourced by the build scripts: compile through ccache when it is installed
# (scripts/setup-deps.sh installs it), with paths hashed relative to the
# checkout so that every clone of the project shares one cache. Sets `launcher`
# to the cmake arguments (empty without ccache).
launcher=()
if command -v ccache >/dev/null 2>&1; then
  export CCACHE_BASEDIR="${CCACHE_BASEDIR:-$PWD}" CCACHE_NOHASHDIR=1
  export CCACHE_MAXSIZE="${CCACHE_MAXSIZE:-20G}"
  launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
fi
