#!/usr/bin/env bash
# Regenerates results/gallery/: runs the canonical scenes with ParaView frames
# into build/gallery-runs/ (not kept in git) and draws them with
# analysis/render.py. About 9 minutes on 2 cores, most of it the pinned blocks
# and fiber_tension at 128 cells.
# Expects the build of scripts/build.sh (build/cases/mpmtb).
set -euo pipefail
cd "$(dirname "$0")/.."
mpmtb=build/cases/mpmtb
runs=build/gallery-runs
out=results/gallery
render() { /usr/bin/python3 analysis/render.py "$@" >/dev/null; }
mkdir -p "$out"
"$mpmtb" run bar --frames-dt 0.2 --quiet --out "$runs/bar"
"$mpmtb" run disks --cells 40 --frames-dt 0.05 --quiet --out "$runs/disks"
"$mpmtb" run pinned_block --frames-dt 0.005 --quiet --out "$runs/pinned_block" || [ $? -eq 3 ]
render "$runs/bar" --size 900x600 --out "$out/bar_velocity.png"
render "$runs/disks" --frame 35 --size 800x700 --out "$out/disks_stress.png"  # t = 1.75, in contact
render "$runs/pinned_block" --size 800x700 --out "$out/pinned_block_damage.png"
render "$runs/pinned_block" --view iso --size 800x700 --out "$out/pinned_block_damage_iso.png"
render "$runs/pinned_block" --cut z=0.25 --field von_mises --frame 20 --size 800x700 \
  --out "$out/pinned_block_stress_cut.png"  # t = 0.1, the ball inside the block
render "$runs/pinned_block" --size 480x420 --out "$runs/last.png" --anim-size 480x420 --fps 8 \
  --gif "$out/pinned_block_damage.gif"
# The pinned block with a grain (aniso-damage: across the grain as strong as the
# isotropic block, 121 times stronger along it), next to the isotropic one.
grain=(--set materials.block.model=aniso-damage --set materials.block.alpha=10
  --set materials.block.sigma_crit=2.42e6 --set materials.block.fiber_E=2e5)
for g in x y; do
  fiber='[1,0,0]'; [ $g = y ] && fiber='[0,1,0]'
  "$mpmtb" run pinned_block "${grain[@]}" --set "bodies.0.fiber=$fiber" --frames-dt 0.01 \
    --quiet --out "$runs/pinned_block_grain_$g" || [ $? -eq 3 ]
  render "$runs/pinned_block_grain_$g" --size 600x520 --out "$runs/grain_$g.png"
done
render "$runs/pinned_block" --size 600x520 --out "$runs/grain_none.png"
/usr/bin/python3 analysis/side_by_side.py "$out/pinned_block_grain.png" \
  "isotropic (damage)=$runs/grain_none.png" "grain along x=$runs/grain_x.png" \
  "grain along y=$runs/grain_y.png" >/dev/null
# fiber_tension: the crack against the fibre angle (2D, 128 cells, issue 20's
# acceptance grid; about a minute each).
panels=()
for theta in 0 30 60; do
  c=$(/usr/bin/python3 -c "import math; print(math.cos(math.radians($theta)))")
  s=$(/usr/bin/python3 -c "import math; print(math.sin(math.radians($theta)))")
  "$mpmtb" run fiber_tension --cells 128 --set "bodies.0.fiber=[$c,$s,0]" --frames-dt 0.1 --quiet \
    --out "$runs/fiber_tension_$theta"
  render "$runs/fiber_tension_$theta" --field damage --size 450x400 --out "$runs/fiber_$theta.png"
  panels+=("fibres at $theta deg=$runs/fiber_$theta.png")
done
/usr/bin/python3 analysis/side_by_side.py "$out/fiber_tension_damage.png" "${panels[@]}" >/dev/null
echo "mpmtb: gallery in $out ($(du -sh "$out" | cut -f1))"
