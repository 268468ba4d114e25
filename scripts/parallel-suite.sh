#!/usr/bin/env bash
# Runs an mpmtb suite as N shards under GNU parallel (Debian's `parallel`),
# for groups without a scheduler, then writes the tables once:
#
#   scripts/parallel-suite.sh SUITE N [--sshloginfile FILE] [--out DIR]
#                             [--mpmtb PATH] [--jobs-per-shard J] [-- SUITE_OPTION ...]
#
# Without --sshloginfile the N shards share this machine (N at once). With it,
# GNU parallel spreads them over the hosts of FILE (one `[slots/]host` a line,
# `:` for this machine) by ssh; DIR (default results/suites) and the program
# (default build/cases/mpmtb) must then be on a filesystem every host sees at
# the same path. Each shard runs J runs at once (default 1). SUITE_OPTIONs go to
# every shard and to the collect step (--full, --case NAME, ...). A shard that
# fails or is killed leaves its finished runs; running this again redoes only
# the rest. Exit status: that of the collect step, or 1 when a shard failed.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
usage() {
  echo "usage: parallel-suite.sh SUITE N [--sshloginfile FILE] [--out DIR] [--mpmtb PATH]" \
    "[--jobs-per-shard J] [-- SUITE_OPTION ...]" >&2
  exit 2
}
[ $# -ge 2 ] || usage
suite=$1 shards=$2
shift 2
source "$root/scripts/slurm/shard-args.sh"
check_suite_and_shards parallel-suite.sh "$suite" "$shards"
out=results/suites mpmtb=$root/build/cases/mpmtb jobs=1 hosts=()
while [ $# -gt 0 ]; do
  case "$1" in
  --sshloginfile) hosts=(--sshloginfile "$2"); shift 2 ;;
  --out) out=$2; shift 2 ;;
  --mpmtb) mpmtb=$2; shift 2 ;;
  --jobs-per-shard) jobs=$2; shift 2 ;;
  --) shift; break ;;
  *) echo "parallel-suite.sh: unknown option '$1'" >&2; usage ;;
  esac
done
command -v parallel >/dev/null ||
  { echo "parallel-suite.sh: GNU parallel is not installed (apt-get install parallel)" >&2; exit 2; }
[ -x "$mpmtb" ] ||
  { echo "parallel-suite.sh: --mpmtb '$mpmtb': not an executable (build first)" >&2; exit 2; }
mkdir -p "$out"
# Absolute paths: a remote shard starts in its home folder.
out=$(cd "$out" && pwd) mpmtb=$(cd "$(dirname "$mpmtb")" && pwd)/$(basename "$mpmtb")
# One job slot per shard on this machine; with hosts, the slots of the file.
slots=(-j "$shards")
[ ${#hosts[@]} -eq 0 ] || slots=()
# --line-buffer keeps the shards' lines whole; --tag names the shard on each.
status=0
seq 1 "$shards" | parallel "${slots[@]}" "${hosts[@]}" --line-buffer --tag \
  "$(printf '%q ' "$mpmtb" suite "$suite" "$@")" --shard '{}'/"$shards" --jobs "$jobs" --quiet \
  --out "$(printf '%q' "$out")" || status=$?
if [ "$status" -ne 0 ]; then
  echo "parallel-suite.sh: $status shard(s) failed; run again to resume them" >&2
  exit 1
fi
exec "$mpmtb" suite "$suite" "$@" --collect --out "$out"
