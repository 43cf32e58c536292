#!/usr/bin/env bash
# Per-model extraction time of two builds of extract_benchmark, alternated
# method by method in one session (this machine is shared: compare the two
# columns of one run, not runs of different days), with each build's features
# fingerprint, so that a change meant to keep features bit-identical is
# checked on the same meshes.
#
#   bench/extract_ab.sh BASE_BINARY NEW_BINARY [MODELS_DIR] [MAX_MODELS] [METHODS] [ROUNDS]
#
# BASE_BINARY: e.g. an older commit's build/bench/extract_benchmark, copied
# aside. Defaults: McGill articulated (~/.cache/meshseek-data; research data,
# bench only), the first 50 models, the default fusion's four methods, 2
# rounds. Prints one line per method and build: the median of the rounds'
# median CPU ms per model, and the fingerprint.
set -euo pipefail
BASE=$1
NEW=$2
MODELS=${3:-$HOME/.cache/meshseek-data/msb_articulated/models}
MAX=${4:-50}
METHODS=${5:-bfdsift rld lsf lfd}
ROUNDS=${6:-2}
ERR=$(mktemp)
trap 'rm -f "$ERR"' EXIT
run() {  # binary method -> "cpu_median_ms fingerprint"
  "$1" --models_dir="$MODELS" --max_models="$MAX" --benchmark_filter="^BM_Extract/$2/" \
    --benchmark_format=json 2>"$ERR" |
    python3 -c 'import json,sys; b=json.load(sys.stdin)["benchmarks"][0]; print("%.1f" % b["median_cpu_ms_per_model"])'
  sed -n 's/.*features fingerprint //p' "$ERR"
}
median() { printf '%s\n' "$@" | sort -n | awk '{a[NR]=$1} END{print (NR%2)?a[(NR+1)/2]:(a[NR/2]+a[NR/2+1])/2}'; }
echo "machine: $(lscpu | sed -n 's/^Model name: *//p'), $(nproc) cores; $(date -u '+%Y-%m-%d %H:%M UTC'); load $(cut -d' ' -f1-3 /proc/loadavg)"
echo "models: $MODELS (first $MAX); $ROUNDS rounds, base and new alternated per method"
for m in $METHODS; do
  base_ms=() new_ms=()
  for r in $(seq "$ROUNDS"); do
    mapfile -t out < <(run "$BASE" "$m")
    b=${out[0]} bf=${out[1]:-none}
    mapfile -t out < <(run "$NEW" "$m")
    n=${out[0]} nf=${out[1]:-none}
    base_ms+=("$b") new_ms+=("$n")
  done
  bm=$(median "${base_ms[@]}") nm=$(median "${new_ms[@]}")
  printf '%-8s base %7.1f ms  new %7.1f ms  ratio %.2f  fingerprints %s %s %s\n' "$m" "$bm" "$nm" \
    "$(echo "$nm / $bm" | bc -l)" "$bf" "$nf" "$([ "$bf" = "$nf" ] && echo same || echo DIFFER)"
done
