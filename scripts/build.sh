#!/usr/bin/env bash
# Configures and builds mpmtb (Release) in ./build. Extra arguments go to cmake.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup-deps.sh
source scripts/ccache.sh
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release -DMPMTB_WERROR=ON "${launcher[@]}" "$@" >/dev/null
cmake --build build -j "$(nproc)"
