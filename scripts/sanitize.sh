#!/usr/bin/env bash
# The sanitizer stage of CI (called by scripts/test.sh): builds the program and
# the unit tests with AddressSanitizer + UndefinedBehaviorSanitizer in
# ./build-asan (warnings as errors) and runs the fast unit tests under them.
# Any report fails the test that triggered it.
# With clang (the default when installed; CXX_SANITIZE picks another compiler)
# the same tree also builds the scene fuzz target, with libFuzzer's coverage on
# the parser (cases/), which scripts/fuzz.sh then runs (FUZZ_TREE=build-asan):
# one instrumented build for both stages.
# Line tables only: full debug info tripled the compile time of the solver's
# instantiations under the sanitizers, which dominates the stage. The library
# (methods/, where the tests spend their time) is built with -O1, everything
# else (parser, driver, tests) with -O0, which compiles at half the cost and
# runs their light code fast enough.
# UBSan's checks for null, alignment, vptr, pointer-overflow and object-size
# are left out: together they cost a third of the stage's compile time (52.7 s
# -> 37.9 s for the APIC solver's file), and ASan reports what they would catch
# that matters here (a null dereference, a read past an object, as SEGV or
# buffer overflow with the stack). Every other UBSan check stays: float-to-int
# overflow, signed overflow, shifts, bounds of fixed arrays, bool and enum
# values, unreachable code, integer division by zero.
# The solvers are compiled for a reduced set of transfer x kernel combinations
# (-DMPMTB_COMBINATIONS=reduced, methods/core/combinations.hpp): every transfer
# with the quadratic B-spline and every kernel with FLIP and MLS-MPM (PIC for
# CPDI), 19 of the 49, so that each transfer's code, each kernel's code and both
# scatter forms of the solver (force apart or folded into the momentum) per
# kernel run here once; the Release tree compiles and tests all 49. Measured
# (2 cores, nice 19, load 1.6-2.0, cold, no ccache): the build 352 s -> 294 s
# (compile CPU 607 -> 506 s, the 8 transfer files 263 -> 135 s); the tests below
# 1305 -> 744 tests, 52 -> 35 s. Tests that name an uncompiled combination skip.
# The heaviest tests (grids of 128^2 and 64^3 and more, runs of thousands of
# steps) are left out: they run the same code as their small 1D, 2D and 3D
# siblings, which do run here.
# SANITIZE_STAGE=build only builds the tree, SANITIZE_STAGE=test only runs its
# tests (scripts/test.sh, which runs the fuzz stage beside the tests); unset,
# both.
set -euo pipefail
cd "$(dirname "$0")/.."
start=$(date +%s)
stage=${SANITIZE_STAGE:-all}
case "$stage" in build | test | all) ;; *)
  echo "sanitize.sh: SANITIZE_STAGE=$stage; allowed: build, test, all" >&2
  exit 2 ;;
esac
source scripts/ccache.sh
cxx=${CXX_SANITIZE:-clang++}
command -v "$cxx" >/dev/null || cxx=g++
sanitizers=address,undefined targets=(mpmtb mpmtb_unit_tests) extra=()
no_sanitize=null,alignment,vptr,pointer-overflow,object-size
# The library (methods/) without ASan's use-after-scope checks: they cost a
# fifth of the solver files' compile time (clang 14, flip.cpp 44 s to 36 s), and
# what this stage looks for there is indexing out of bounds, which stays checked
# (heap, stack and globals). The parser, suites and I/O (cases/) keep them.
methods_flags="-O1"
if [[ $cxx == *clang* ]]; then
  debug_flags="-O0 -gline-tables-only"
  methods_flags+=";-fno-sanitize-address-use-after-scope"
  targets+=(mpmtb_scene_fuzz) extra=(-DMPMTB_FUZZ=ON)
else
  debug_flags="-O0 -g1"
fi
if [ "$stage" != test ]; then
  cmake -S . -B build-asan -DCMAKE_CXX_COMPILER="$cxx" -DCMAKE_BUILD_TYPE=Debug \
    -DCMAKE_CXX_FLAGS_DEBUG="$debug_flags" -DMPMTB_METHODS_OPT="$methods_flags" \
    -DMPMTB_SANITIZE="$sanitizers" -DMPMTB_NO_SANITIZE="$no_sanitize" \
    -DMPMTB_WERROR=ON -DMPMTB_BUILD_BENCH=OFF -DMPMTB_COMBINATIONS=reduced \
    "${extra[@]}" "${launcher[@]}" "$@" >/dev/null
  cmake --build build-asan -j "$(nproc)" --target "${targets[@]}"
  echo "sanitizer stage: built with $cxx in $(( $(date +%s) - start )) s"
fi
[ "$stage" != build ] || exit 0
export ASAN_OPTIONS=abort_on_error=0:detect_leaks=1:strict_string_checks=1
export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
# The shards share the cores: OpenMP threads sleep at barriers (tests/CMakeLists.txt).
export OMP_WAIT_POLICY=passive
# gtest patterns of the left-out tests (see above).
heavy='*ThreadCountDoesNotChangeTheResult/2d*:*ThreadCountDoesNotChangeTheResult/3d*'
heavy+=':RotatingBody.*:TransferIdentities.MlsWithTheLinearHatIsApic:*Determinism*:GimpRuns.*'
heavy+=':*RigidTranslationMakesNoStrainEnergy/3d*'
# Runs of many steps whose per-step code the short tests above already cover.
heavy+=':Xpic.EnergyKept*:Polypic.KeepsAtLeast*:Tpic.WithTheLinearHat*:Tpic.AngularMomentumDrift*'
# Free flight under every order: the 1D cases run the same stages.
heavy+=':*FreeFlightConservesMassAndMomentum/2d*:*FreeFlightConservesMassAndMomentum/3d*'
# CPDI's 3D steps (64 nodes per particle, node by node: 6 to 44 s each here)
# and its 1D thread-count runs: the 1D and 2D steps run the same kernel code.
heavy+=':AllCombinations/StepTest.*/3d_*_cpdi:*ThreadCountDoesNotChangeTheResult/1d_*_cpdi'
# The implicit solve's 3D thread-count run (1.6 s in Release): the 2D ones run
# the same scatter code.
heavy+=':ImplicitThreads.HangingBlock3D'
# A thousand steps of a spinning body (16 s here, a tenth of the stage): the
# other AnisoDamage tests run the same per-step code.
heavy+=':AnisoDamageStep.FibersRotateWithARigidlyRotatingBody'
# The scene parser's own fuzz test with a tenth of its inputs (10 s to 1 s):
# libFuzzer then runs 200,000 coverage-guided inputs through it in this tree.
export MPMTB_FUZZ_INPUTS=2000
# One process per shard, not one per test: each sanitized process costs about a
# second to start, which over a thousand tests would dominate the stage.
cd build-asan/tests
shards=$(nproc)
pids=()
for ((k = 0; k < shards; ++k)); do
  GTEST_TOTAL_SHARDS=$shards GTEST_SHARD_INDEX=$k ./mpmtb_unit_tests --gtest_filter="-$heavy" \
    --gtest_brief=1 >"shard$k.log" 2>&1 &
  pids+=($!)
done
failed=0
for ((k = 0; k < shards; ++k)); do
  if ! wait "${pids[k]}"; then
    failed=1
    cat "shard$k.log"
  fi
  tail -n 3 "shard$k.log"
done
echo "sanitizer stage: $(( $(date +%s) - start )) s"
[ "$failed" -eq 0 ] || { echo "sanitizer stage: failures (see above)"; exit 1; }
