#!/usr/bin/env bash
# Regenerates results/gallery/: runs three canonical scenes with ParaView frames
# into build/gallery-runs/ (not kept in git) and draws them with
# analysis/render.py. About 3 minutes on 2 cores, most of it the pinned block.
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
echo "mpmtb: gallery in $out ($(du -sh "$out" | cut -f1))"
