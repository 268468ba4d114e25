#!/usr/bin/env bash
# Coverage-guided fuzzing of the scene parser and `--set` overrides with
# libFuzzer (needs clang; Debian: apt-get install clang). Builds ./build-fuzz
# (clang, -O1, AddressSanitizer + UndefinedBehaviorSanitizer) and runs
# tests/fuzz/scene_fuzz.cpp from a seed corpus of cases/scenes/*.toml.
# Usage: scripts/fuzz.sh [RUNS [SECONDS]]  (defaults: 200000 inputs, at most 120 s).
# FUZZ_TREE=build-asan reuses the tree scripts/sanitize.sh built with clang
# (sanitizers and libFuzzer coverage together) instead of building ./build-fuzz.
# A finding is saved as $FUZZ_TREE/crash-* and makes the script fail.
set -euo pipefail
cd "$(dirname "$0")/.."
runs=${1:-200000} seconds=${2:-120}
tree=${FUZZ_TREE:-build-fuzz}
cxx=${CXX_FUZZ:-clang++}
command -v "$cxx" >/dev/null || { echo "fuzz: $cxx not found; skipped" >&2; exit 0; }
source scripts/ccache.sh
if ! grep -q '^MPMTB_FUZZ:BOOL=ON' "$tree/CMakeCache.txt" 2>/dev/null; then
  # A tree configured without the fuzz target (e.g. a GCC sanitizer tree) is left alone.
  [ -f "$tree/CMakeCache.txt" ] && tree=build-fuzz
  cmake -S . -B "$tree" -DCMAKE_CXX_COMPILER="$cxx" -DCMAKE_BUILD_TYPE=Debug \
    -DCMAKE_CXX_FLAGS_DEBUG="-O1 -gline-tables-only" -DMPMTB_SANITIZE=address,undefined,fuzzer-no-link \
    -DMPMTB_FUZZ=ON -DMPMTB_BUILD_BENCH=OFF "${launcher[@]}" >/dev/null
fi
cmake --build "$tree" -j "$(nproc)" --target mpmtb_scene_fuzz
mkdir -p "$tree/corpus"
cd "$tree"
ASAN_OPTIONS=detect_leaks=1 ./tests/mpmtb_scene_fuzz -runs="$runs" -max_total_time="$seconds" \
  -max_len=8192 -timeout=10 -rss_limit_mb=2048 -dict=../tests/fuzz/scene.dict -print_final_stats=1 \
  corpus ../cases/scenes
