#!/usr/bin/env bash
# Installs what is missing, builds, and runs the default test set: the unit,
# verification and end-to-end labels, and the provenance gate (label gate: the
# reference set compared with results/baseline/, scripts/gate.sh). Long sweeps
# carry other labels and run from scripts/suite.sh. Then the sanitizer stage and
# a bounded fuzz run of the scene parser.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup-deps.sh
# The sanitizer tree (scripts/sanitize.sh) builds from the start, in the
# background at the lowest CPU priority: the Release build and its tests keep
# the cores, and the sanitizer build takes one whenever they leave it idle (a
# link, the last files of a target, ctest's gaps and its tail). The two trees'
# compilations alone fill 2 cores for about 15 minutes, so every idle second counts.
mkdir -p build-asan
asan_log=build-asan/stage-build.log
# Its own process group (job control, set -m), so that a failure below stops
# the whole build; not its own session (setsid), which the kernel's autogroup
# scheduling would give an equal share of the cores whatever its nice value.
set -m
SANITIZE_STAGE=build nice -n 19 bash scripts/sanitize.sh >"$asan_log" 2>&1 &
asan_build=$!
set +m
trap 'kill -- -"$asan_build" 2>/dev/null || true' EXIT
# Only what the default set runs: not the sweep tests or the benchmarks.
MPMTB_TARGETS="mpmtb mpmtb_unit_tests mpmtb_verification_tests" bash scripts/build.sh
(cd build && ctest -L 'unit|verification|e2e|gate' --output-on-failure -j "$(nproc)")
# Sanitizer stage: the unit tests again, built with ASan + UBSan in ./build-asan.
echo "sanitizer stage: waiting for its build (log: $asan_log)"
if ! wait "$asan_build"; then
  cat "$asan_log"
  echo "sanitizer stage: the build failed (above)"
  exit 1
fi
trap - EXIT
tail -n 1 "$asan_log"
# Bounded coverage-guided fuzz of the scene parser (libFuzzer; skipped without
# clang), one process, beside the sanitized tests' two shards: three processes
# keep both cores busy until the last ends.
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
