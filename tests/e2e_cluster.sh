#!/usr/bin/env bash
# The suites on a real scheduler (ctest label `cluster`; scripts/suite.sh runs
# it, CI does not: it takes minutes). Usage: e2e_cluster.sh MPMTB SOURCE_DIR WORKDIR
#
#   1. the quick convergence suite run once locally: the reference tables;
#   2. the same through scripts/parallel-suite.sh as 3 shards on 3 local job
#      slots of GNU parallel: the tables must equal the reference byte for byte;
#   3. a single-node Slurm (Debian's slurmctld, slurmd and munge) configured and
#      started under WORKDIR, stopped at the end: scripts/slurm/submit.sh submits
#      the suite as an array of 3 tasks plus the collect job (afterok); the
#      tables must again equal the reference byte for byte.
# The suite is the quick convergence suite's 1D cases (1,260 runs, about a
# minute on 2 cores); MPMTB_CLUSTER_WHOLE_SUITE=1 (scripts/suite.sh) adds the 2D
# manufactured solution, 180 more runs that take 10 times as long.
# Without the packages or root, or when Slurm is not up within a minute, it
# exits 77 (ctest: skipped) with the reason. MPMTB_CLUSTER_ONE_SHARD=1 also
# times 1 shard under each (for the README's figures).
set -euo pipefail
mpmtb=$1 src=$2 work=$3
skip() {
  echo "SKIP: $*"
  exit 77
}
rm -rf "$work" && mkdir -p "$work"
work=$(cd "$work" && pwd)
for c in parallel slurmctld slurmd munged sbatch squeue scontrol sinfo; do
  command -v "$c" >/dev/null ||
    skip "$c is not installed (apt-get install slurmctld slurmd munge parallel)"
done
[ "$(id -u)" -eq 0 ] || skip "slurmd must start as root to run jobs"
suite=(--quick)
if [ "${MPMTB_CLUSTER_WHOLE_SUITE:-0}" != 1 ]; then
  suite+=(--case bar --case bar_vcm --case mms_bar_small --case mms_bar_large)
fi
now() { date +%s.%N; }
since() { awk -v a="$1" -v b="$(now)" 'BEGIN { printf "%.1f", b - a }'; }
report=()

# The tables of two suite folders, file for file and byte for byte.
same_tables() {  # reference other label
  local a=$1/convergence b=$2/convergence
  [ "$(cd "$a" && ls ./*.csv)" = "$(cd "$b" && ls ./*.csv)" ] ||
    { echo "$3: other table files than the local run's"; exit 1; }
  for t in "$a"/*.csv; do
    cmp "$t" "$b/$(basename "$t")" || { echo "$3: $(basename "$t") differs"; exit 1; }
  done
  echo "$3: $(cd "$a" && ls ./*.csv | wc -l) tables identical to the local run's"
}

t=$(now)
"$mpmtb" suite convergence "${suite[@]}" --jobs "$(nproc)" --quiet --out "$work/local"
report+=("local, $(nproc) runs at once: $(since "$t") s")
runs=$(find "$work/local/convergence/runs" -name done.json | wc -l)

# GNU parallel on 3 local slots (and on 1, timed only).
parallel_suite() {  # shards folder jobs-per-shard
  local t
  t=$(now)
  bash "$src/scripts/parallel-suite.sh" convergence "$1" --mpmtb "$mpmtb" --out "$work/$2" \
    --jobs-per-shard "$3" -- "${suite[@]}" >"$work/$2.log" 2>&1 ||
    { echo "parallel-suite.sh failed:"; cat "$work/$2.log"; exit 1; }
  report+=("GNU parallel, $1 shard(s) x $3 runs at once: $(since "$t") s")
  same_tables "$work/local" "$work/$2" "GNU parallel, $1 shard(s)"
}
parallel_suite 3 parallel3 1
[ "${MPMTB_CLUSTER_ONE_SHARD:-0}" = 1 ] && parallel_suite 1 parallel1 "$(nproc)"

# ---------------------------------------------------------- single-node Slurm --
daemons=$work/slurm
mkdir -p "$daemons"/{state,spool,log,munge}
chmod 700 "$daemons/munge"
pids=()
stop_daemons() {
  local f p running=()
  # Only this test's jobs live on this private cluster (SLURM_CONF is ours):
  # cancel them and give their steps a moment to end before slurmd goes.
  if [ -s "$daemons/slurmctld.pid" ]; then
    scancel --user="$(id -un)" 2>/dev/null || true
    for _ in $(seq 1 10); do
      [ -z "$(squeue -h 2>/dev/null)" ] && break
      sleep 1
    done
  fi
  for f in "${pids[@]}"; do
    [ -s "$f" ] && p=$(cat "$f") && kill "$p" 2>/dev/null && running+=("$p") || true
  done
  # slurmd waits for steps that a failed test left behind: not for ever.
  for _ in $(seq 1 10); do
    local alive=0
    for p in "${running[@]}"; do kill -0 "$p" 2>/dev/null && alive=1; done
    [ "$alive" -eq 0 ] && return 0
    sleep 1
  done
  for p in "${running[@]}"; do kill -9 "$p" 2>/dev/null || true; done
}
trap stop_daemons EXIT
dd if=/dev/urandom of="$daemons/munge/munge.key" bs=1024 count=1 status=none
chmod 400 "$daemons/munge/munge.key"
socket=$daemons/munge/munge.socket
# munged refuses folders that others may write to, such as /tmp above WORKDIR;
# --force lets it run there (the key is readable only by root all the same).
munged --force --key-file="$daemons/munge/munge.key" --socket="$socket" \
  --pid-file="$daemons/munge/munged.pid" --log-file="$daemons/log/munged.log" \
  --seed-file="$daemons/munge/seed" >"$daemons/log/munged.out" 2>&1 ||
  skip "munged did not start: $(tail -n 3 "$daemons/log/munged.out" "$daemons/log/munged.log" 2>/dev/null)"
pids+=("$daemons/munge/munged.pid")
host=$(hostname -s)
port=$((20000 + $$ % 20000))
export SLURM_CONF=$daemons/slurm.conf
cat >"$SLURM_CONF" <<EOF
ClusterName=mpmtbtest
SlurmctldHost=$host(127.0.0.1)
SlurmctldPort=$port
SlurmdPort=$((port + 1))
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
AuthInfo=socket=$socket
CredType=cred/munge
StateSaveLocation=$daemons/state
SlurmdSpoolDir=$daemons/spool
SlurmctldPidFile=$daemons/slurmctld.pid
SlurmdPidFile=$daemons/slurmd.pid
SlurmctldLogFile=$daemons/log/slurmctld.log
SlurmdLogFile=$daemons/log/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/none
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
SchedulerType=sched/backfill
MpiDefault=none
ReturnToService=2
MinJobAge=600
KillWait=10
NodeName=$host NodeAddr=127.0.0.1 CPUs=$(nproc) State=UNKNOWN
PartitionName=test Nodes=$host Default=YES MaxTime=INFINITE State=UP
EOF
# The jobs inherit the daemons' priority: nice, like every build and suite here.
nice -n 15 slurmctld -c >"$daemons/log/slurmctld.out" 2>&1 ||
  skip "slurmctld did not start: $(tail -n 5 "$daemons/log/slurmctld.out" "$daemons/log/slurmctld.log" 2>/dev/null)"
pids+=("$daemons/slurmctld.pid")
nice -n 15 slurmd -N "$host" >"$daemons/log/slurmd.out" 2>&1 ||
  skip "slurmd did not start: $(tail -n 5 "$daemons/log/slurmd.out" "$daemons/log/slurmd.log" 2>/dev/null)"
pids+=("$daemons/slurmd.pid")
t=$(now)
state=""
for _ in $(seq 1 60); do
  state=$(sinfo -h -N -o %T 2>/dev/null | head -n 1 || true)
  [ "$state" = idle ] && break
  sleep 1
done
[ "$state" = idle ] || skip "Slurm not up within a minute (node state '$state'): \
$(tail -n 5 "$daemons/log/slurmctld.log" "$daemons/log/slurmd.log" 2>/dev/null)"
echo "Slurm up in $(since "$t") s: node $host, $(nproc) CPUs"

# A job's state while it is known to slurmctld (MinJobAge keeps it 10 minutes).
job_state() { scontrol show job "$1" -o 2>/dev/null | grep -o 'JobState=[A-Z_]*' | sort -u | cut -d= -f2; }
slurm_suite() {  # shards folder cpus-per-task
  local t ids array collect s
  t=$(now)
  ids=$(bash "$src/scripts/slurm/submit.sh" convergence "$1" --out "$work/$2" --mpmtb "$mpmtb" \
    --cpus "$3" --no-figures -- "${suite[@]}")
  array=$(sed -n 's/.*array=\([0-9]*\).*/\1/p' <<<"$ids")
  collect=$(sed -n 's/.*collect=\([0-9]*\).*/\1/p' <<<"$ids")
  echo "submitted $1 shard(s): $ids"
  for _ in $(seq 1 1800); do
    s=$(job_state "$collect")
    case "$s" in COMPLETED | FAILED | CANCELLED | TIMEOUT | NODE_FAIL | OUT_OF_MEMORY) break ;; esac
    sleep 1
  done
  [ "$s" = COMPLETED ] || {
    echo "collect job $collect: '$s'; array $array: $(job_state "$array" | tr '\n' ' ')"
    tail -n 20 "$work/$2"/slurm/*.log "$daemons/log/slurmd.log"
    exit 1
  }
  report+=("Slurm, $1 shard(s) x $3 CPUs each, submit to collected: $(since "$t") s;" \
    "tasks ran $(scontrol show job "$array" -o | grep -o 'RunTime=[0-9:-]*' | cut -d= -f2 |
      tr '\n' ' ')")
  same_tables "$work/local" "$work/$2" "Slurm, $1 shard(s)"
}
slurm_suite 3 slurm3 1
[ "${MPMTB_CLUSTER_ONE_SHARD:-0}" = 1 ] && slurm_suite 1 slurm1 "$(nproc)"

echo "cluster: the quick convergence suite, ${suite[*]} ($runs runs):"
printf '  %s\n' "${report[@]}"
