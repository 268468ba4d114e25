# Sourced by scripts/slurm/submit.sh and scripts/parallel-suite.sh: the checks of
# their two positional arguments, one place for the list of suites.
# check_suite_and_shards PROGRAM SUITE N: exits 2 with a message naming the
# argument and the allowed values when SUITE or N is not valid.
check_suite_and_shards() {
  local prog=$1 suite=$2 shards=$3
  case "$suite" in convergence | stability | speed-accuracy | all) ;; *)
    echo "$prog: SUITE '$suite': allowed convergence, stability, speed-accuracy, all" >&2
    exit 2
    ;;
  esac
  [[ "$shards" =~ ^[1-9][0-9]*$ ]] || { echo "$prog: N '$shards': a whole number >= 1" >&2; exit 2; }
}
