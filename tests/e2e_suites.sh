#!/usr/bin/env bash
# End to end tests of `mpmtb suite` (label e2e; each well under a minute).
#   stability: the 1D bar's largest stable CFL per kernel lies within +-25 % of
#              the von Neumann estimate (shared/REFERENCE.md) for the transfers
#              whose grid update is the analysed one (APIC, MLS-MPM), PIC's
#              matches the same analysis with its grid-particle-grid projection
#              (derived below), and every run beyond the limit is a data point
#              `unstable` with a reason, not a crash.
#   implicit:  on the same bar, the explicit integrator's largest stable CFL is
#              the von Neumann estimate (+-25 %) while backward Euler and Newmark
#              stay stable at every CFL tried, up to 100; backward Euler's energy
#              decays at the rate its amplification predicts, Newmark keeps it
#              (APIC: within 10 %; FLIP's particle update loses 10-30 %).
#   resume:    a quick convergence suite killed with SIGKILL mid-run and run
#              again gives the same tables as an uninterrupted one and reruns
#              only the unfinished runs.
#   shards:    the same suite as 3 shards (--shard K/N), in any order, repeated,
#              one stopped by SIGTERM and re-run, then --collect: the same
#              tables byte for byte, the shards disjoint and covering.
set -euo pipefail
mode=$1 mpmtb=$2 work=$3
rm -rf "$work" && mkdir -p "$work"

case "$mode" in
stability)
  "$mpmtb" suite stability --quick --case bar_fixed --transfer apic --transfer mls \
    --transfer pic --integrator explicit --jobs 2 --quiet --out "$work"
  /usr/bin/python3 - "$work/stability" <<'PY'
import cmath, csv, math, sys
root = sys.argv[1]


def weight(kernel, r, l):
    """N(r) and dN/dx_p for the kernels of shared/REFERENCE.md (dx = 1); l is uGIMP's
    particle half-width 1/(2 ppc) (Bardenhagen & Kober 2004, eq. 40)."""
    a, s = abs(r), math.copysign(1.0, r)
    if kernel == "cpdi":
        # CPDI1 at F = I (kernels/cpdi.hpp): the hat at the domain's corners r -+ l,
        # averaged; the gradient (hat(r + l) - hat(r - l)) / (2l) (uGIMP's).
        hat = lambda x: max(0.0, 1 - abs(x))
        return (hat(r - l) + hat(r + l)) / 2, (hat(r + l) - hat(r - l)) / (2 * l)
    if kernel in ("gimp", "cpgimp"):  # cpGIMP at F = I is uGIMP
        if a < l:
            return 1 - (r * r + l * l) / (2 * l), -r / l
        if a < 1 - l:
            return 1 - a, -s
        return ((1 + l - a) ** 2 / (4 * l), -s * (1 + l - a) / (2 * l)) if a < 1 + l else (0.0, 0.0)
    if kernel == "linear":
        return (1 - a, -s) if a < 1 else (0.0, 0.0)
    if kernel == "quadratic":
        if a < 0.5:
            return 0.75 - a * a, -2 * r
        return ((1.5 - a) ** 2 / 2, -(1.5 - a) * s) if a < 1.5 else (0.0, 0.0)
    if a < 1:
        return a ** 3 / 2 - a * a + 2 / 3, 1.5 * a * r - 2 * r
    return ((2 - a) ** 3 / 6, -(2 - a) ** 2 / 2 * s) if a < 2 else (0.0, 0.0)


def pic_limit(kernel, ppc):
    """(derived) Critical CFL of PIC in 1D, von Neumann on an infinite lattice.

    Per Fourier mode theta, with ppc particles per cell at (j + 1/2)/ppc,
    lumped mass rho dx and particle quadrature: stiffness
    K = c^2/dx^2 <|sum_i e^{i theta i} dN_i(x_p)|^2>, and PIC's
    grid -> particle -> grid projection of the velocity
    P = <|sum_i e^{i theta i} N_i(x_p)|^2>. Symplectic Euler on
    v' = P v - dt K u, u' = u + dt v' is stable iff (K dt^2) <= 2 (1 + P)
    (Jury test on the 2x2 amplification matrix; P = 1 recovers the
    lossless grid scheme's omega dt <= 2).
    """
    xs = [(j + 0.5) / ppc for j in range(ppc)]
    l = 0.5 / ppc
    best = math.inf
    for n in range(1, 721):
        theta = math.pi * n / 720
        K = P = 0.0
        for x in xs:
            g = sum(cmath.exp(1j * theta * i) * weight(kernel, x - i, l)[1] for i in range(-3, 5))
            q = sum(cmath.exp(1j * theta * i) * weight(kernel, x - i, l)[0] for i in range(-3, 5))
            K += abs(g) ** 2 / ppc
            P += abs(q) ** 2 / ppc
        best = min(best, math.sqrt(2 * (1 + P) / K))
    return best

stable = list(csv.DictReader(open(f"{root}/stable_cfl.csv")))
runs = list(csv.DictReader(open(f"{root}/bar_fixed.csv")))
assert runs and stable, "empty tables"
bad = [r for r in runs if r["status"] not in ("ok", "unstable")]
assert not bad, f"runs neither ok nor unstable: {bad[:3]}"
# The estimate assumes the particles integrate the stiffness well: ppc >= 2
# (with one particle per cell the quadratic B-spline's limit drops to 1.0).
checked = 0
for s in stable:
    if s["transfer"] == "pic":
        # The CFL grid has steps of 0.1: the last stable value lies within one
        # step below the derived limit (a slowly growing mode may pass 4 periods
        # just above it).
        limit = pic_limit(s["kernel"], int(s["ppc"]))
        c = float(s["stable_cfl"])
        assert limit - 0.1 - 0.02 <= c <= limit + 0.05 * limit, \
            f"pic-{s['kernel']} ppc {s['ppc']}: stable CFL {c}, derived limit {limit:.3f}"
        continue
    if int(s["ppc"]) < 2:
        continue
    low, high = float(s["vn_low"]), float(s["vn_high"])
    name = f"{s['transfer']}-{s['kernel']} ppc {s['ppc']}"
    assert s["stable_cfl"], f"{name}: no stable CFL"
    c = float(s["stable_cfl"])
    assert 0.75 * low <= c <= 1.25 * high, \
        f"{name}: largest stable CFL {c} outside [{0.75*low}, {1.25*high}]"
    assert s["first_unstable_cfl"], f"{name}: no unstable CFL found"
    assert s["failure"] in ("nan", "J<=0", "left-domain", "energy-growth"), s
    # Well beyond the limit every run must be reported unstable with a reason.
    for r in runs:
        if (r["transfer"], r["kernel"], r["ppc"]) == (s["transfer"], s["kernel"], s["ppc"]) \
                and float(r["cfl"]) >= 1.25 * high:
            assert r["status"] == "unstable" and r["reason"] and r["fail_step"], r
    checked += 1
# APIC and MLS-MPM with 5 kernels (both refuse CPDI: its D_p is full), 2 ppc each.
assert checked == 2 * 5 * 2, f"checked {checked} method x ppc combinations"
print(f"stability: {checked} limits within +-25 % of the von Neumann estimate, "
      "PIC's on its derived limit")
PY
  ;;
implicit)
  "$mpmtb" suite stability --quick --case bar_fixed --transfer apic --transfer flip \
    --kernel quadratic --kernel cubic --jobs 2 --quiet --out "$work"
  /usr/bin/python3 - "$work/stability" <<'PY'
import csv, json, math, os, sys
root = sys.argv[1]
stable = list(csv.DictReader(open(f"{root}/stable_cfl.csv")))
runs = list(csv.DictReader(open(f"{root}/bar_fixed.csv")))
explicit = {(s["transfer"], s["kernel"]): s for s in stable
            if s["integrator"] == "explicit" and s["ppc"] == "2"}
implicit = [s for s in stable if s["integrator"] != "explicit"]
assert len(explicit) == 4 and len(implicit) == 2 * 4, (len(explicit), len(implicit))
# bar_fixed: fixed at both ends, mode 1: omega = pi c / L, c = sqrt(E / rho) = 10 (nu = 0).
omega = math.pi * 10 / 25
for s in implicit:
    name = f"{s['transfer']}-{s['kernel']}/{s['integrator']}"
    e = explicit[(s["transfer"], s["kernel"])]
    lo, hi = float(e["vn_low"]), float(e["vn_high"])
    # The explicit limit is where von Neumann puts it, and the sweep found it.
    assert e["first_unstable_cfl"] and 0.75 * lo <= float(e["stable_cfl"]) <= 1.25 * hi, e
    # The implicit integrator: no CFL tried failed, the largest tried is >= 50x the explicit limit.
    mine = [r for r in runs if (r["transfer"], r["kernel"], r["integrator"], r["ppc"]) ==
            (s["transfer"], s["kernel"], s["integrator"], s["ppc"])]
    cfls = sorted(float(r["cfl"]) for r in mine)
    assert len(mine) == 8 and cfls[0] <= 1 and cfls[-1] >= 50, (name, cfls)
    assert all(r["status"] == "ok" for r in mine), [r for r in mine if r["status"] != "ok"]
    assert not s["first_unstable_cfl"] and float(s["stable_cfl"]) == cfls[-1], s
    assert float(s["stable_cfl"]) >= 25 * float(e["stable_cfl"]), (s, e)
    assert not s["vn_low"] and not s["vn_high"], s
    for r in mine:
        cfl = float(r["cfl"])
        d = os.path.join(root, "runs", "bar_fixed",
                         f"{s['transfer']}-{s['kernel']}-{s['integrator']}",
                         f"ppc2-cfl{cfl:.3f}", "summary.json")
        summary = json.load(open(d))
        kept = 1 + summary["drift"]["energy"]  # E(end) / E(0)
        if s["integrator"] == "backward-euler":
            # Per step the mode's energy falls by 1 / (1 + (omega dt)^2)
            # (integrators/integrator.hpp): where that leaves a measurable
            # energy (CFL <= 1), the run loses it at that rate; beyond, the
            # mode is gone (below 1e-6) and the run keeps at most what the grid
            # does not see (FLIP's particle modes, ~1e-5 here).
            dt = summary["dt_min"]
            predicted = (1 + (omega * dt) ** 2) ** -summary["steps"]
            if cfl <= 1:
                assert 0.8 * predicted <= kept <= 1.25 * predicted, (name, cfl, kept, predicted)
            elif cfl >= 5:
                assert predicted < 1e-6 and kept < 1e-3, (name, cfl, kept, predicted)
        elif s["transfer"] == "apic":
            # |A| = 1 per mode: the grid keeps the energy; APIC's transfer loses
            # a few per cent over the run.
            assert abs(kept - 1) <= 0.1 and summary["drift"]["energy_max"] <= 0.1, \
                (name, cfl, summary["drift"])
        else:
            # FLIP's particle update loses more (10-30 % here), still orders of
            # magnitude above backward Euler's.
            assert 0.5 <= kept <= 1.1, (name, cfl, summary["drift"])
print(f"implicit: {len(implicit)} implicit methods stable up to CFL "
      f"{min(float(s['stable_cfl']) for s in implicit):g}, the explicit limits on the "
      "von Neumann estimate; backward Euler damps as predicted, Newmark keeps the energy")
PY
  ;;
resume)
  args=(suite convergence --quick --case bar --transfer mls --transfer pic --jobs 2)
  "$mpmtb" "${args[@]}" --quiet --out "$work/a"
  "$mpmtb" "${args[@]}" --quiet --out "$work/b" &
  pid=$!
  runs="$work/b/convergence/runs"
  for _ in $(seq 1 600); do
    # (find fails until the suite has made the folder: with pipefail that
    # failure would end this script under set -e)
    n=$(find "$runs" -name done.json 2>/dev/null | wc -l || true)
    [ "$n" -ge 12 ] && break
    sleep 0.02
  done
  kill -9 "$pid"
  wait "$pid" 2>/dev/null || true
  # The children die with the suite (PR_SET_PDEATHSIG); under load that takes a
  # moment, and a child must not finish a run after the count below.
  for _ in $(seq 1 200); do
    pgrep -f -- "--out $work/b/" >/dev/null || break
    sleep 0.05
  done
  sleep 0.2
  find "$runs" -name done.json | sort | xargs md5sum > "$work/before.md5"
  finished=$(wc -l < "$work/before.md5")
  total=$(find "$work/a/convergence/runs" -name done.json | wc -l)
  [ "$finished" -lt "$total" ] || { echo "the suite finished before the kill"; exit 1; }
  [ ! -e "$work/b/convergence/orders.csv" ] || { echo "tables written before the end"; exit 1; }
  "$mpmtb" "${args[@]}" --out "$work/b" 2> "$work/resume.log"
  grep -q "$total runs: $finished finished before, $((total - finished)) to run" "$work/resume.log" \
    || { echo "expected $finished of $total finished before:"; cat "$work/resume.log"; exit 1; }
  md5sum --quiet -c "$work/before.md5" || { echo "a finished run was redone"; exit 1; }
  for t in bar.csv bar_dt.csv orders.csv; do
    cmp "$work/a/convergence/$t" "$work/b/convergence/$t" || { echo "$t differs"; exit 1; }
  done
  echo "resume: killed after $finished of $total runs; resumed tables identical"
  ;;
shards)
  # A suite split into 3 shards, run out of order, one twice, one stopped by
  # SIGTERM (as a batch system's time limit does, to every process of the job)
  # and run again, then collected: the tables equal one local run's byte for
  # byte, and the shards' runs are disjoint and cover the list.
  args=(suite convergence --quick --case bar --transfer mls --transfer pic)
  "$mpmtb" "${args[@]}" --jobs 2 --quiet --out "$work/local"
  total=$(find "$work/local/convergence/runs" -name done.json | wc -l)
  out=$work/sharded
  expect_status() {  # status command...: runs the command, checks its exit status
    local want=$1 got=0
    shift
    "$@" || got=$?
    [ "$got" -eq "$want" ] || { echo "exit status $got, expected $want: $*"; exit 1; }
  }
  for bad in 4/3 0/3 x 3 1/0 2/3x; do
    expect_status 2 "$mpmtb" "${args[@]}" --shard "$bad" --out "$work/bad" 2>"$work/err"
    grep -q -- "--shard '$bad'" "$work/err" || { echo "no field named:"; cat "$work/err"; exit 1; }
  done
  expect_status 2 "$mpmtb" "${args[@]}" --shard 1/3 --collect --out "$work/bad" 2>"$work/err"
  [ ! -e "$work/bad" ] || { echo "bad input wrote $work/bad"; exit 1; }
  # Nothing has run: --collect lists every run and writes no table.
  expect_status 4 "$mpmtb" "${args[@]}" --collect --out "$out" 2>"$work/collect0.log"
  [ "$(grep -c ': no done.json$' "$work/collect0.log")" -eq "$total" ] ||
    { echo "collect did not list all $total runs:"; head "$work/collect0.log"; exit 1; }
  [ ! -e "$out/convergence/orders.csv" ] || { echo "tables written with runs missing"; exit 1; }
  "$mpmtb" "${args[@]}" --shard 3/3 --jobs 2 --out "$out" 2>"$work/shard3.log"
  "$mpmtb" "${args[@]}" --shard 1/3 --jobs 2 --out "$out" 2>"$work/shard1.log"
  "$mpmtb" "${args[@]}" --shard 1/3 --jobs 2 --out "$out" 2>"$work/shard1b.log"
  runs_of() { sed -n 's/.*shard [0-9]\/3: \([0-9]*\) runs:.*/\1/p' "$1"; }
  n1=$(runs_of "$work/shard1.log") n3=$(runs_of "$work/shard3.log")
  grep -q "$n1 runs: $n1 finished before, 0 to run" "$work/shard1b.log" ||
    { echo "shard 1 run twice redid runs:"; cat "$work/shard1b.log"; exit 1; }
  expect_status 4 "$mpmtb" "${args[@]}" --collect --out "$out" 2>"$work/collect1.log"
  [ "$(grep -c ': no done.json$' "$work/collect1.log")" -eq $((total - n1 - n3)) ] ||
    { echo "collect should list the $((total - n1 - n3)) runs of shard 2"; exit 1; }
  # Shard 2, one run at a time, stopped by SIGTERM to its whole process group.
  before=$(find "$out/convergence/runs" -name done.json | wc -l)
  setsid "$mpmtb" "${args[@]}" --shard 2/3 --jobs 1 --out "$out" 2>"$work/shard2.log" &
  pid=$!
  for _ in $(seq 1 1000); do
    [ "$(find "$out/convergence/runs" -name done.json | wc -l)" -ge $((before + 3)) ] && break
    sleep 0.01
  done
  kill -TERM -- -"$pid"
  got=0
  wait "$pid" || got=$?
  [ "$got" -eq 143 ] || { echo "shard 2 after SIGTERM: status $got, expected 143"; exit 1; }
  find "$out/convergence/runs" -name done.json | sort | xargs md5sum >"$work/before.md5"
  kept=$(wc -l <"$work/before.md5")
  [ "$kept" -lt "$total" ] || { echo "shard 2 finished before SIGTERM"; exit 1; }
  "$mpmtb" "${args[@]}" --shard 2/3 --jobs 2 --out "$out" 2>"$work/shard2b.log"
  n2=$(runs_of "$work/shard2b.log")
  md5sum --quiet -c "$work/before.md5" || { echo "a finished run was redone"; exit 1; }
  [ $((n1 + n2 + n3)) -eq "$total" ] ||
    { echo "shards hold $n1 + $n2 + $n3 runs, the suite $total"; exit 1; }
  [ "$(find "$out/convergence/runs" -name done.json | wc -l)" -eq "$total" ] ||
    { echo "the shards' runs overlap or miss some"; exit 1; }
  "$mpmtb" "${args[@]}" --collect --quiet --out "$out"
  for t in bar.csv bar_dt.csv orders.csv; do
    cmp "$work/local/convergence/$t" "$out/convergence/$t" || { echo "$t differs"; exit 1; }
  done
  echo "shards: $n1 + $n2 + $n3 = $total runs, shard 2 stopped by SIGTERM and resumed;" \
    "collected tables identical to a local run"
  ;;
*)
  echo "usage: e2e_suites.sh stability|implicit|resume|shards MPMTB WORKDIR" >&2
  exit 2
  ;;
esac
