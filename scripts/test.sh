#!/usr/bin/env bash
# Installs what is missing, builds, and runs the default test set: the unit,
# verification and end-to-end labels, and the provenance gate (label gate: the
# reference set compared with results/baseline/, scripts/gate.sh). Long sweeps
# carry other labels and run from scripts/suite.sh.
set -euo pipefail
cd "$(dirname "$0")/.."
# Only what the default set runs: not the sweep tests or the benchmarks.
MPMTB_TARGETS="mpmtb mpmtb_unit_tests mpmtb_verification_tests" bash scripts/build.sh
cd build
ctest -L 'unit|verification|e2e|gate' --output-on-failure -j "$(nproc)"
cd ..
# Sanitizer stage: the unit tests again, built with ASan + UBSan in ./build-asan.
bash scripts/sanitize.sh
# Bounded coverage-guided fuzz of the scene parser (libFuzzer; skipped without clang).
FUZZ_TREE=build-asan bash scripts/fuzz.sh 200000 60
