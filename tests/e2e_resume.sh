#!/usr/bin/env bash
# End to end tests of runs that never lose work (label e2e; a few seconds each).
#   signal:    the pinned block stopped with SIGTERM (or SIGINT) mid-way exits
#              143 (130) with complete series rows on disk and a summary that
#              says `interrupted` and how to resume; resumed, its series.csv,
#              final frame and frame list equal an uninterrupted run's byte for
#              byte (same thread count).
#   kill:      SIGKILL after a periodic checkpoint (--checkpoint-every): the
#              resumed run cuts the rows written after it and still equals the
#              uninterrupted run byte for byte.
#   transfers: --wall-limit (exit 124) stops after the first step; resumed runs
#              of the transfers that keep per-particle state between steps
#              (FLIP, PolyPIC, XPIC, ASFLIP) and of a scene with an analytic
#              reference equal uninterrupted ones byte for byte, summary
#              error norms included.
set -euo pipefail
mode=$1 mpmtb=$2 work=$3
rm -rf "$work" && mkdir -p "$work"
fail() { echo "FAIL: $*" >&2; exit 1; }

# Runs `mpmtb run ARGS` and checks its exit status.
expect_rc() {
  local want=$1 rc=0
  shift
  "$mpmtb" run "$@" 2>"$work/stderr" || rc=$?
  [ "$rc" = "$want" ] || { cat "$work/stderr" >&2; fail "exit $rc, expected $want: $*"; }
}

# Every line of a series has the header's column count (no half row on disk).
complete_rows() {
  awk -F, 'NR == 1 { n = NF } NF != n || substr($0, length($0)) == "," { bad = 1 } END { exit bad }' "$1" ||
    fail "$1 holds an incomplete row"
}

# The same run output, byte for byte: series, frame list and last frame.
same_output() {
  cmp "$1/series.csv" "$2/series.csv" || fail "series.csv of $2 differs from $1"
  if [ -f "$1/particles.pvd" ]; then
    cmp "$1/particles.pvd" "$2/particles.pvd" || fail "particles.pvd differs"
    local last
    last=$(ls "$1/frames" | tail -n 1)
    cmp "$1/frames/$last" "$2/frames/$last" || fail "final frame $last differs"
  fi
}

summary_field() {  # file key
  /usr/bin/python3 -c 'import json,sys; print(json.load(open(sys.argv[1])).get(sys.argv[2], ""))' "$1" "$2"
}

# Starts a run in the background and waits until its series holds `rows` rows.
start_and_wait() {  # dir rows args...
  local dir=$1 rows=$2
  shift 2
  "$mpmtb" run "$@" --out "$dir" 2>"$dir.stderr" &
  pid=$!
  for _ in $(seq 1 600); do
    [ -f "$dir/series.csv" ] && [ "$(wc -l <"$dir/series.csv")" -gt "$rows" ] && return 0
    kill -0 "$pid" 2>/dev/null || fail "the run ended before $rows rows"
    sleep 0.02
  done
  fail "no $rows rows after 12 s"
}

# The pinned block, 32,768 particles, 1 thread: long enough to stop mid-way.
block=(pinned_block --t-end 0.04 --set time.output_interval=0.001 --threads 1 --frames-dt 0.01)

case "$mode" in
signal)
  expect_rc 0 "${block[@]}" --out "$work/whole"
  for sig in TERM INT; do
    dir=$work/stopped_$sig
    start_and_wait "$dir" 5 "${block[@]}"
    kill -s "$sig" "$pid"
    rc=0 && wait "$pid" || rc=$?
    want=$([ "$sig" = TERM ] && echo 143 || echo 130)
    [ "$rc" = "$want" ] || fail "SIG$sig: exit $rc, expected $want"
    [ "$(summary_field "$dir/summary.json" status)" = interrupted ] || fail "status not interrupted"
    grep -q "SIG$sig received" "$dir/summary.json" || fail "the reason does not name SIG$sig"
    grep -q "mpmtb run --resume $dir" "$dir/summary.json" || fail "no resume command"
    [ -f "$dir/checkpoint/state.bin" ] || fail "no checkpoint"
    complete_rows "$dir/series.csv"
    expect_rc 0 --resume "$dir"
    same_output "$work/whole" "$dir"
    [ ! -e "$dir/checkpoint" ] || fail "a finished run keeps its checkpoint"
  done
  # A finished run has nothing to resume: a clear refusal.
  expect_rc 2 --resume "$work/whole"
  grep -q "no checkpoint" "$work/stderr" || fail "resume of a finished run: $(cat "$work/stderr")"
  ;;
kill)
  expect_rc 0 "${block[@]}" --out "$work/whole"
  dir=$work/killed
  start_and_wait "$dir" 30 "${block[@]}" --checkpoint-every 0.01
  kill -s KILL "$pid"
  wait "$pid" || true
  [ -f "$dir/checkpoint/state.bin" ] || fail "no periodic checkpoint"
  complete_rows "$dir/series.csv"
  expect_rc 0 --resume "$dir"
  same_output "$work/whole" "$dir"
  ;;
transfers)
  for transfer in flip polypic xpic asflip; do
    run=(disks --transfer "$transfer" --cells 16 --t-end 0.2 --threads 2 --frames-every 10)
    expect_rc 0 "${run[@]}" --out "$work/$transfer-whole"
    expect_rc 124 "${run[@]}" --wall-limit 1e-9 --out "$work/$transfer"
    [ "$(summary_field "$work/$transfer/summary.json" steps)" = 1 ] || fail "wall limit: not 1 step"
    expect_rc 0 --resume "$work/$transfer"
    same_output "$work/$transfer-whole" "$work/$transfer"
  done
  # A reference's accumulated error norms survive the restart.
  run=(bar --cells 16 --t-end 2 --set time.output_interval=0.05)
  expect_rc 0 "${run[@]}" --out "$work/bar-whole"
  expect_rc 124 "${run[@]}" --wall-limit 1e-9 --out "$work/bar"
  expect_rc 0 --resume "$work/bar"
  same_output "$work/bar-whole" "$work/bar"
  /usr/bin/python3 - "$work/bar-whole/summary.json" "$work/bar/summary.json" <<'PY'
import json, sys
a, b = (json.load(open(p)) for p in sys.argv[1:])
for key in ("error", "measured", "drift", "J_min", "J_max", "steps", "dt_min", "dt_max"):
    assert a[key] == b[key], (key, a[key], b[key])
PY
  ;;
*) fail "unknown mode $mode" ;;
esac
echo "e2e resume $mode: ok"
