#!/usr/bin/env bash
# The sanitizer stage of CI (called by scripts/test.sh): builds the program and
# the unit tests with AddressSanitizer + UndefinedBehaviorSanitizer in
# ./build-asan (-O1, debug info, warnings as errors) and runs the fast unit
# tests under them. Any report fails the test that triggered it.
# The heaviest tests (grids of 128^2 and 64^3 and more, runs of thousands of
# steps) are left out: they run the same code as their small 1D, 2D and 3D
# siblings, which do run here.
set -euo pipefail
cd "$(dirname "$0")/.."
start=$(date +%s)
source scripts/ccache.sh
cmake -S . -B build-asan -DCMAKE_BUILD_TYPE=Debug -DCMAKE_CXX_FLAGS_DEBUG="-O1 -g" \
  -DMPMTB_SANITIZE=address,undefined -DMPMTB_WERROR=ON -DMPMTB_BUILD_BENCH=OFF "${launcher[@]}" "$@" \
  >/dev/null
cmake --build build-asan -j "$(nproc)" --target mpmtb mpmtb_unit_tests
export ASAN_OPTIONS=abort_on_error=0:detect_leaks=1:strict_string_checks=1
export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
heavy='ThreadCountDoesNotChangeTheResult/[23]d|RotatingBody|MlsWithTheLinearHatIsApic'
heavy+='|RigidTranslationMakesNoStrainEnergy/3d|Determinism|GimpRuns'
# Runs of many steps whose per-step code the short tests above already cover.
heavy+='|Xpic.EnergyKept|Polypic.KeepsAtLeast|Tpic.WithTheLinearHat|Tpic.AngularMomentumDrift'
# Free flight under every order: the 1D cases run the same stages.
heavy+='|FreeFlightConservesMassAndMomentum/[23]d'
cd build-asan
ctest -L unit -E "$heavy" --output-on-failure -j "$(nproc)"
echo "sanitizer stage: $(( $(date +%s) - start )) s"
