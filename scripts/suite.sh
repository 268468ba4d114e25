#!/usr/bin/env bash
# The main job: installs what is missing, builds, runs the comparison suites and
# regenerates the figures and results/README.md.
#
#   bash scripts/suite.sh          quick default (about 11 minutes on 2 cores after
#                                  the build): the work-precision diagrams (every
#                                  run timed alone), the quick convergence and
#                                  stability suites, the figures
#   bash scripts/suite.sh --full   also every transfer x kernel on the canonical
#                                  scenes: the vibrating bar (1D, 2D, 3D), the
#                                  colliding disks (2D) and spheres (3D), the free
#                                  rotating body (2D, 3D), the single material
#                                  point under each stress-update order, the sand
#                                  column, the pinned block; the cluster test and
#                                  the gallery (see README.md for both times)
#
# The suites run at their quick level either way (`mpmtb suite all --full` is
# the long level, hours on 2 cores). The timed runs of the speed-accuracy suite
# run one at a time whatever --jobs says; leave the machine otherwise idle for
# timings worth plotting.
set -euo pipefail
cd "$(dirname "$0")/.."
full=0
for arg in "$@"; do
  case "$arg" in
    --full) full=1 ;;
    -h | --help) sed -n '2,20p' "$0"; exit 0 ;;
    *) echo "suite.sh: unknown argument '$arg' (allowed: --full)" >&2; exit 2 ;;
  esac
done
bash scripts/build.sh
mpmtb=build/cases/mpmtb
start=$SECONDS
sweep() {  # scene dim
  rm -rf "results/$1/$2d"
  # Refused combinations are recorded as `invalid` and an unstable run (exit 3)
  # as `unstable`: both are data; only a failure of the program stops the suite.
  "$mpmtb" run "$1" --dim "$2" --transfer all --kernel all --out "results/$1/$2d" || [ $? -eq 3 ]
}
if [ "$full" -eq 1 ]; then
  for dim in 1 2 3; do sweep bar "$dim"; done
  sweep disks 2
  sweep spheres 3
  sweep rotating 2
  sweep rotating 3
  # The stress-update orders on Bardenhagen's single material point (1D, FLIP,
  # every kernel): USL loses energy every step, USF and MUSL keep it bounded.
  for order in usl usf musl; do
    rm -rf "results/single_point/1d-$order"
    "$mpmtb" run single_point --transfer flip --kernel all --update-order "$order" \
      --out "results/single_point/1d-$order" || [ $? -eq 3 ]
  done
  # Granular column collapse (sand, 2D, aspect ratio 2): every transfer with the
  # quadratic kernel; measured_runout is the front's run-out over the width.
  rm -rf results/column/2d
  "$mpmtb" run column --transfer all --kernel quadratic \
    --set 'bodies.0.max=[0.125,0.25,0.0]' --out results/column/2d || [ $? -eq 3 ]
  # The pinned block (32,768 particles, damage): one method, about a minute.
  rm -rf results/pinned_block/3d
  "$mpmtb" run pinned_block --transfer mls --kernel all --out results/pinned_block/3d || [ $? -eq 3 ]
fi
# The suites at the quick level: convergence and stability (every transfer x
# kernel, runs side by side), then speed-accuracy, the work-precision diagrams
# (each run timed alone: median of 3 repetitions of at least 0.5 s of stepping).
# One run per child process, resumable (results/suites).
"$mpmtb" suite all --quick --out results/suites
if [ "$full" -eq 1 ]; then
  # The suites on a real scheduler: the quick convergence suite as 3 shards under
  # GNU parallel and as a Slurm job array on a single-node Slurm that the test
  # starts and stops, tables compared byte for byte with a local run (ctest label
  # `cluster`; skipped with the reason where Slurm cannot start).
  bash scripts/setup-deps.sh --cluster
  (cd build && ctest -L cluster --output-on-failure)
  bash scripts/gallery.sh
fi
/usr/bin/python3 analysis/plot_all.py --results results
echo "mpmtb: results in results/README.md ($((SECONDS - start)) s after the build)"
