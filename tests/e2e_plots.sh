#!/usr/bin/env bash
# End to end: a short sweep through the CLI, then the plotting scripts on its
# tables; every figure the index embeds must exist and be a non-empty PNG.
set -euo pipefail
mpmtb=$1 source_dir=$2 work=$3
rm -rf "$work" && mkdir -p "$work/bar"
"$mpmtb" run bar --transfer all --kernel all --t-end 2 --out "$work/bar/1d" 2>/dev/null
"$mpmtb" run bar --dim 2 --kernel quadratic --transfer all --t-end 2 --out "$work/bar/2d" 2>/dev/null
# Small suites: every figure kind of the suites (convergence and dt
# refinement, stability map, failure modes, Pareto and throughput).
"$mpmtb" suite convergence --case bar --kernel quadratic --kernel cubic --transfer mls \
  --transfer pic --quiet --out "$work/suites"
"$mpmtb" suite stability --case bar_fixed --case translate --transfer mls --kernel linear \
  --kernel cubic --quiet --out "$work/suites"
"$mpmtb" suite speed-accuracy --case bar_2d --transfer apic --transfer pic --kernel quadratic \
  --quiet --out "$work/suites"
/usr/bin/python3 "$source_dir/analysis/plot_all.py" --results "$work"
test -s "$work/README.md"
figures=$(grep -o '([^)]*\.png)' "$work/README.md" | tr -d '()')
[ -n "$figures" ] || { echo "no figures in the index"; exit 1; }
for f in $figures; do
  head -c 8 "$work/$f" | od -An -tx1 | grep -q "89 50 4e 47" || { echo "not a PNG: $f"; exit 1; }
done
for f in suites/convergence/bar.png suites/convergence/bar_dt.png \
  suites/stability/stability_map.png suites/stability/failure_modes.png \
  suites/speed_accuracy/bar_2d_work_precision.png suites/speed_accuracy/throughput.png; do
  grep -q "($f)" "$work/README.md" || { echo "$f missing from the index"; exit 1; }
done
grep -q "### Observed orders" "$work/README.md" || { echo "no orders table"; exit 1; }
grep -q "### Largest stable CFL" "$work/README.md" || { echo "no stability table"; exit 1; }
grep -q "### Cheapest method for a tolerance: bar_2d" "$work/README.md" ||
  { echo "no cheapest-method table"; exit 1; }
# The work-precision table: every point timed (median of 3 with its spread).
/usr/bin/python3 - "$work/suites/speed_accuracy/bar_2d.csv" <<'PY'
import csv, sys
rows = list(csv.DictReader(open(sys.argv[1])))
assert rows, "empty work-precision table"
for r in rows:
    assert r["status"] == "ok", r
    lo, med, hi = float(r["time_min_s"]), float(r["time_s"]), float(r["time_max_s"])
    assert 0 < lo <= med <= hi, r
    assert int(r["repeats"]) >= 3 and int(r["passes"]) >= 1, r
PY
for run in $("$mpmtb" list transfers); do
  grep -q "$run-linear" "$work/README.md" || { echo "$run-linear missing from the index"; exit 1; }
done
echo "e2e: $(echo $figures | wc -w) figures"
