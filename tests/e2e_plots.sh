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
# The implicit integrators as the third axis of a method (issue 19): on the
# stability map beside the explicit ones (APIC takes them, MLS-MPM does not), and
# Newmark's work-precision series beside the explicit ones.
"$mpmtb" suite stability --case bar_fixed --case translate --transfer mls --transfer apic \
  --kernel linear --kernel cubic --quiet --out "$work/suites"
"$mpmtb" suite speed-accuracy --case bar_2d --transfer apic --transfer pic --kernel quadratic \
  --integrator explicit --integrator newmark --quiet --out "$work/suites"
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
# The integrator axis in the tables, the report and the figures' legends.
grep -q "^case,transfer,kernel,integrator,cfl,level," "$work/suites/speed_accuracy/bar_2d.csv" ||
  { echo "no integrator column in the work-precision table"; exit 1; }
grep -q "^bar_2d,apic,quadratic,newmark,16,2," "$work/suites/speed_accuracy/bar_2d.csv" ||
  { echo "no Newmark run at CFL 16"; exit 1; }
grep -q "apic-quadratic/newmark. CFL 16" "$work/README.md" ||
  { echo "no Newmark run in the report"; exit 1; }
for i in newmark backward-euler; do
  grep -q "| .apic-cubic/$i. | .*>=" "$work/README.md" ||
    { echo "apic-cubic/$i missing from the stability table"; exit 1; }
done
/usr/bin/python3 - "$source_dir/analysis" "$work/suites" <<'PY'
import sys
sys.path.insert(0, sys.argv[1])
import matplotlib
matplotlib.use("Agg")
import suite_plots as sp
import work_precision as wp
import mpmtb_plots as mp
# The work-precision legend names each implicit series with its CFL; the
# stability map has a row per integrator.
rows = mp.read_table(f"{sys.argv[2]}/speed_accuracy/bar_2d.csv")[1]
labels = {wp.line_label(*k) for k in wp.lines_of(wp.usable(rows))}
for cfl in (1, 4, 16):
    assert f"apic/newmark CFL {cfl}" in labels, labels
assert {"apic", "pic"} <= labels, labels
stable = sp.read_rows(f"{sys.argv[2]}/stability/stable_cfl.csv")
methods = sp.methods_of(stable)
for i in ("explicit", "backward-euler", "newmark"):
    assert ("apic", "cubic", i) in methods, methods
PY
for run in $("$mpmtb" list transfers); do
  grep -q "$run-linear" "$work/README.md" || { echo "$run-linear missing from the index"; exit 1; }
done
echo "e2e: $(echo $figures | wc -w) figures"
