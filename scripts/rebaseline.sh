#!/usr/bin/env bash
# Regenerates results/baseline/ on purpose: runs the gate's reference set
# (scripts/gate.sh --into) and keeps the files `mpmtb compare` reads (every
# summary.json and table, not the time series, logs or completion markers).
# A new baseline is a change of the published results: its commit message must
# say why, and CHANGELOG.md must get an entry under "Changed results".
#   bash scripts/rebaseline.sh [--mpmtb PATH]
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
work="$(mktemp -d "${TMPDIR:-/tmp}/mpmtb-rebaseline.XXXXXX")"
trap 'rm -rf "$work"' EXIT
bash "$root/scripts/gate.sh" "$@" --into "$work"
base="$root/results/baseline"
rm -rf "$base/runs" "$base/suites"  # README.md stays
(cd "$work" && find runs suites -type f \( -name summary.json -o -name '*.csv' \) ! -name series.csv \
  -print0 | xargs -0 cp --parents -t "$base")
echo "rebaseline: results/baseline/ regenerated ($(find "$base" -type f | wc -l) files)."
echo "rebaseline: commit it with a message that says WHY the results changed, and add an"
echo "            entry to CHANGELOG.md (\"Changed results\": what moved, by how much, why)."
