#!/usr/bin/env bash
# The main job: installs what is missing, builds, runs the comparison suite on
# its quick default and regenerates the figures and results/README.md.
# Every transfer x kernel on the vibrating bar (1D, 2D, 3D), the colliding
# disks (2D) and spheres (3D) and the free rotating body (2D, 3D); the single
# material point under each stress-update order; the sand column with every
# transfer; the pinned block struck by a ball (3D, damage) with MLS-MPM and
# every kernel; then the quick suites and the figures.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/build.sh
mpmtb=build/cases/mpmtb
sweep() {  # scene dim
  rm -rf "results/$1/$2d"
  # Refused combinations are recorded as `invalid` and an unstable run (exit 3)
  # as `unstable`: both are data; only a failure of the program stops the suite.
  "$mpmtb" run "$1" --dim "$2" --transfer all --kernel all --out "results/$1/$2d" || [ $? -eq 3 ]
}
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
# The suites (convergence, stability, speed-accuracy) at the quick level: every
# transfer x kernel, one run per child process, resumable (results/suites).
"$mpmtb" suite all --quick --out results/suites
# The suites on a real scheduler: the quick convergence suite as 3 shards under
# GNU parallel and as a Slurm job array on a single-node Slurm that the test
# starts and stops, tables compared byte for byte with a local run (ctest label
# `cluster`, a few minutes; skipped with the reason where Slurm cannot start).
bash scripts/setup-deps.sh --cluster
(cd build && ctest -L cluster --output-on-failure)
bash scripts/gallery.sh
/usr/bin/python3 analysis/plot_all.py --results results
echo "mpmtb: results in results/README.md"
