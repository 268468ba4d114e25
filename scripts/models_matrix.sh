#!/usr/bin/env bash
# Every constitutive model through every transfer on the colliding disks (2D)
# and the pinned block (3D); writes one CSV table per scene under
# results/models/ (the raw runs go to $WORK, default build/models_matrix).
#
# Usage: scripts/models_matrix.sh [tag]
# Knobs (environment), defaults in brackets:
#   MODELS     [neo-hookean linear-elastic fixed-corotated snow damage]
#   TRANSFERS  [pic flip apic mls]        KERNEL [quadratic]
#   DISKS_T_END [3.5]                     DISKS_SIGMA_CRIT [40] (damage)
#   BLOCK_T_END [0.2]  BLOCK_CELLS [48]   (48: the scene's 32,768 particles)
#   BLOCK_TRANSFERS [$TRANSFERS]          THREADS [2]
#   SCENES [disks pinned_block]
# An `unstable` or `invalid` run is a row of the table, not a failure.
#
# Columns: drift_energy = (total(t_end) - collider work - total(0)) / max(K + S),
# total = kinetic + strain + gravity + dissipated (summary drift.energy);
# dissipated_rel = dissipated(t_end) / max(K + S); damaged_fraction = volume
# fraction with d >= 1/2 at t_end (damage only).
set -euo pipefail
cd "$(dirname "$0")/.."
tag=${1:-}
mpmtb=${MPMTB:-build/cases/mpmtb}
work=${WORK:-build/models_matrix}
models=${MODELS:-neo-hookean linear-elastic fixed-corotated snow damage}
transfers=${TRANSFERS:-pic flip apic mls}
block_transfers=${BLOCK_TRANSFERS:-$transfers}
kernel=${KERNEL:-quadratic}
threads=${THREADS:-2}
scenes=${SCENES:-disks pinned_block}
mkdir -p "$work" results/models

run() {  # scene model transfer out [args...]
  local scene=$1 model=$2 transfer=$3 out=$4
  shift 4
  rm -rf "$out"
  mkdir -p "$(dirname "$out")"
  local rc=0
  "$mpmtb" run "$scene" --transfer "$transfer" --kernel "$kernel" --threads "$threads" \
    --out "$out" "$@" > "$out.log" 2>&1 || rc=$?
  # 2: invalid, 3: unstable (both recorded in summary.json); anything else is a crash.
  if [ "$rc" -ne 0 ] && [ "$rc" -ne 2 ] && [ "$rc" -ne 3 ]; then
    echo "mpmtb failed ($rc) on $scene $model $transfer: see $out.log" >&2
    return 1
  fi
}

# The pinned block's material is a damage model: the other models get a copy of
# the scene without the damage parameter.
block_scene() {  # model -> scene file
  local f="$work/pinned_block_$1.toml"
  sed -e "s/^model = \"damage\"/model = \"$1\"/" cases/scenes/pinned_block.toml > "$f"
  [ "$1" = damage ] || sed -i -e '/^sigma_crit/d' "$f"
  echo "$f"
}

for scene in $scenes; do
  for model in $models; do
    if [ "$scene" = disks ]; then
      extra=(--model "$model" --t-end "${DISKS_T_END:-3.5}")
      [ "$model" = damage ] && extra+=(--set "materials.elastic.sigma_crit=${DISKS_SIGMA_CRIT:-40}")
      list=$transfers
      file=disks
    else
      extra=(--t-end "${BLOCK_T_END:-0.2}" --cells "${BLOCK_CELLS:-48}")
      list=$block_transfers
      file=$(block_scene "$model")
    fi
    for transfer in $list; do
      echo "models_matrix: $scene $model $transfer" >&2
      run "$file" "$model" "$transfer" "$work/$scene$tag/$model-$transfer" "${extra[@]}"
    done
  done
  /usr/bin/python3 - "$work/$scene$tag" "results/models/$scene$tag.csv" <<'EOF'
import csv, json, os, sys
root, out = sys.argv[1], sys.argv[2]
cols = ["model", "transfer", "kernel", "status", "reason", "particles", "steps", "t",
        "dt_min", "dt_max", "wave_speed_max", "threads", "particle_steps_per_second",
        "drift_energy", "drift_energy_max", "drift_momentum", "dissipated_rel",
        "damaged_fraction", "collider_work", "J_min"]
rows = []
for run in sorted(os.listdir(root)):
    path = os.path.join(root, run)
    if not os.path.isdir(path) or not os.path.exists(os.path.join(path, "summary.json")):
        continue
    j = json.load(open(os.path.join(path, "summary.json")))
    model, transfer = run.rsplit("-", 1)
    r = {"model": model, "transfer": transfer, "kernel": j.get("kernel", ""),
         "status": j.get("status", ""), "reason": j.get("reason", "")}
    for k in ["particles", "steps", "t", "dt_min", "dt_max", "wave_speed_max", "threads",
              "particle_steps_per_second", "J_min"]:
        r[k] = j.get(k, "")
    d = j.get("drift", {})
    r["drift_energy"], r["drift_energy_max"] = d.get("energy", ""), d.get("energy_max", "")
    r["drift_momentum"] = d.get("momentum", "")
    series = os.path.join(path, "series.csv")
    if os.path.exists(series):
        s = list(csv.DictReader(open(series)))
        mech = max(float(x["kinetic"]) + float(x["strain"]) for x in s)
        last = s[-1]
        r["dissipated_rel"] = float(last["dissipated"]) / mech if mech > 0 else ""
        for k in ["damaged_fraction", "collider_work"]:
            r[k] = float(last[k]) if last.get(k) else ""
    rows.append(r)
tmp = out + ".tmp"
with open(tmp, "w", newline="") as f:
    w = csv.DictWriter(f, fieldnames=cols)
    w.writeheader()
    for r in rows:
        w.writerow({k: ("{:.6g}".format(v) if isinstance(v, float) else v)
                    for k, v in r.items()})
os.replace(tmp, out)
print(f"models_matrix: {len(rows)} runs -> {out}", file=sys.stderr)
EOF
done
