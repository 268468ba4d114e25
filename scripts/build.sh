#!/usr/bin/env bash
# Configures and builds mpmtb (Release) in ./build. Extra arguments go to cmake.
# MPMTB_TARGETS (space-separated) builds only those targets (scripts/test.sh).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup-deps.sh
source scripts/ccache.sh
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release -DMPMTB_WERROR=ON "${launcher[@]}" "$@" >/dev/null
read -r -a targets <<<"${MPMTB_TARGETS:-all}"
cmake --build build -j "$(nproc)" --target "${targets[@]}"
