#!/usr/bin/env bash
# Installs the Debian packages mpmtb needs, if any is missing (Debian 12).
# Runs apt-get as root, or through sudo; does nothing when all are present.
# --cluster adds what the cluster test needs (ctest label `cluster`, run by the
# main job, scripts/suite.sh, not by CI): Slurm's controller and node daemons,
# munge for their authentication, and GNU parallel.
set -euo pipefail
packages=(g++ make cmake ccache libeigen3-dev libfmt-dev libcli11-dev libtomlplusplus-dev
          nlohmann-json3-dev libgtest-dev libbenchmark-dev python3-matplotlib python3-numpy
          python3-vtk9)
if [ "${1:-}" = --cluster ]; then
  packages=(slurmctld slurmd slurm-client munge parallel)
fi
# python3-vtk9 (about 60 packages, 250 MB installed: Qt, MPI) only lets the frame
# test read .vtp files with VTK's own reader; without it the test falls back to a
# strict reader of our own and says so.
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
[ ${#missing[@]} -eq 0 ] && exit 0
echo "mpmtb: installing missing Debian packages: ${missing[*]}" >&2
sudo=""
if [ "$(id -u)" -ne 0 ]; then
  command -v sudo >/dev/null || { echo "mpmtb: run as root or install: ${missing[*]}" >&2; exit 1; }
  sudo="sudo"
fi
export DEBIAN_FRONTEND=noninteractive
$sudo apt-get update -qq
$sudo apt-get install -y -qq --no-install-recommends "${missing[@]}"
