#!/usr/bin/env bash
# Installs what is missing, builds, and runs the default test set: the unit and
# verification tests (as label shards: the same tests in a few processes,
# tests/CMakeLists.txt), the end-to-end label, and the provenance gate (label
# gate: the reference set compared with results/baseline/, scripts/gate.sh). Long sweeps
# carry other labels and run from scripts/suite.sh. Then the sanitizer stage and
# a bounded fuzz run of the scene parser.
set -euo pipefail
cd "$(dirname "$0")/.."
# Only what the default set runs: not the sweep tests or the benchmarks.
MPMTB_TARGETS="mpmtb mpmtb_unit_tests mpmtb_verification_tests" bash scripts/build.sh
(cd build && ctest -L 'shards|e2e|gate' --output-on-failure -j "$(nproc)")
# Sanitizer stage: the unit tests again, built with ASan + UBSan in ./build-asan.
# (Built in the background at nice 19 beside the Release tree instead, it gained
# nothing: the default tests ran 25 % longer with it, 258 s against 206.)
SANITIZE_STAGE=build bash scripts/sanitize.sh
# Bounded coverage-guided fuzz of the scene parser (libFuzzer; skipped without
# clang), one process, beside the sanitized tests' two shards: three processes
# keep both cores busy until the last ends (its time cap, 120 s, allows for the
# shared cores: 200,000 inputs take about 40 s alone).
fuzz_log=build-asan/stage-fuzz.log
set -m
FUZZ_TREE=build-asan bash scripts/fuzz.sh 200000 120 >"$fuzz_log" 2>&1 &
fuzz=$!
set +m
trap 'kill -- -"$fuzz" 2>/dev/null || true' EXIT
SANITIZE_STAGE=test bash scripts/sanitize.sh
if ! wait "$fuzz"; then
  cat "$fuzz_log"
  echo "fuzz: failed (above)"
  exit 1
fi
trap - EXIT
grep -E '^(Done|fuzz:)' "$fuzz_log" || tail -n 3 "$fuzz_log"
