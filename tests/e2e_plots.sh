#!/usr/bin/env bash
# End to end: a short sweep through the CLI, then the plotting scripts on its
# tables; every figure the index embeds must exist and be a non-empty PNG.
set -euo pipefail
mpmtb=$1 source_dir=$2 work=$3
rm -rf "$work" && mkdir -p "$work/bar"
"$mpmtb" run bar --transfer all --kernel all --t-end 2 --out "$work/bar/1d" 2>/dev/null
"$mpmtb" run bar --dim 2 --kernel quadratic --transfer all --t-end 2 --out "$work/bar/2d" 2>/dev/null
/usr/bin/python3 "$source_dir/analysis/plot_all.py" --results "$work"
test -s "$work/README.md"
figures=$(grep -o '([^)]*\.png)' "$work/README.md" | tr -d '()')
[ -n "$figures" ] || { echo "no figures in the index"; exit 1; }
for f in $figures; do
  head -c 8 "$work/$f" | od -An -tx1 | grep -q "89 50 4e 47" || { echo "not a PNG: $f"; exit 1; }
done
for run in $("$mpmtb" list transfers); do
  grep -q "$run-linear" "$work/README.md" || { echo "$run-linear missing from the index"; exit 1; }
done
echo "e2e: $(echo $figures | wc -w) figures"
