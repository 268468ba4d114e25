#!/usr/bin/env bash
# Submits an mpmtb suite to Slurm as a job array of N shards plus a collect job
# that starts once every shard has succeeded (--dependency=afterok) and writes
# the tables (and the figures, where matplotlib is installed):
#
#   scripts/slurm/submit.sh SUITE N [--out DIR] [--mpmtb PATH] [--cpus C]
#                           [--sbatch 'ARGS'] [--no-figures] [-- SUITE_OPTION ...]
#
# DIR (default results/suites) and the program (default build/cases/mpmtb)
# must be on a filesystem that every compute node sees at the same path.
# SUITE_OPTIONs go to every shard and to the collect step alike (--full,
# --case NAME, --transfer NAME, ...). --sbatch passes options to both sbatch
# calls (--partition, --time, --account). Prints the two job ids:
# `array=ID collect=ID`. Running it again after a failed or timed-out shard
# resumes: finished runs are skipped, only the missing ones run.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
usage() {
  echo "usage: submit.sh SUITE N [--out DIR] [--mpmtb PATH] [--cpus C] [--sbatch 'ARGS']" \
    "[--no-figures] [-- SUITE_OPTION ...]" >&2
  exit 2
}
[ $# -ge 2 ] || usage
suite=$1 shards=$2
shift 2
source "$here/shard-args.sh"
check_suite_and_shards submit.sh "$suite" "$shards"
out=results/suites mpmtb=$root/build/cases/mpmtb cpus=1 sbatch_args="" figures=1
while [ $# -gt 0 ]; do
  case "$1" in
  --out) out=$2; shift 2 ;;
  --mpmtb) mpmtb=$2; shift 2 ;;
  --cpus) cpus=$2; shift 2 ;;
  --sbatch) sbatch_args=$2; shift 2 ;;
  --no-figures) figures=0; shift ;;
  --) shift; break ;;
  *) echo "submit.sh: unknown option '$1'" >&2; usage ;;
  esac
done
[ -x "$mpmtb" ] || { echo "submit.sh: --mpmtb '$mpmtb': not an executable (build first)" >&2; exit 2; }
mkdir -p "$out/slurm"
out=$(cd "$out" && pwd) mpmtb=$(cd "$(dirname "$mpmtb")" && pwd)/$(basename "$mpmtb")
# Bad suite options are refused here rather than in N failed tasks: the collect
# step runs nothing, exits 2 on bad input and 4 when it only lists runs to do.
set +e
"$mpmtb" suite "$suite" "$@" --collect --quiet --out "$out" 2>"$out/slurm/check.log"
status=$?
set -e
if [ "$status" -eq 2 ]; then cat "$out/slurm/check.log" >&2; exit 2; fi
read -r -a extra <<<"$sbatch_args"
array=$(sbatch --parsable "${extra[@]}" --array="1-$shards" --cpus-per-task="$cpus" \
  --job-name="mpmtb-$suite" --output="$out/slurm/shard-%a.log" \
  "$here/suite.sbatch" "$mpmtb" "$suite" "$shards" "$out" "$@")
array=${array%%;*}  # "id;cluster" on multi-cluster setups
q() { printf '%q ' "$@"; }
collect="$(q "$mpmtb" suite "$suite" "$@" --collect --quiet --out "$out")"
if [ "$figures" -eq 1 ]; then
  # The figures of analysis/suite_plots.py, where matplotlib is installed.
  collect+="&& { /usr/bin/python3 -c 'import matplotlib' 2>/dev/null || exit 0; "
  collect+="/usr/bin/python3 -c 'import sys; sys.path.insert(0, sys.argv[1]); import suite_plots; "
  collect+="suite_plots.plot_all_suites(sys.argv[2])' $(q "$root/analysis" "$out"); }"
fi
done_id=$(sbatch --parsable "${extra[@]}" --dependency="afterok:$array" --kill-on-invalid-dep=yes \
  --job-name="mpmtb-$suite-collect" --output="$out/slurm/collect.log" --wrap="$collect")
echo "array=$array collect=${done_id%%;*}"
