#!/usr/bin/env bash
# The default fusion's whole eval through the embedded services against
# --server in-process, alternated in one session (issue: within 15 %), on one
# development set; prints each run's wall time and phases, the ratio of the
# medians, and whether every run's distance matrix is the same. Research data
# lives outside the repository: a benchmark, never a test.
#
#   bench/services_ratio.sh [SET] [ROUNDS] [DATA_DIR]
#   (defaults: msb_articulated, 2, ~/.cache/meshseek-data)
set -euo pipefail
cd "$(dirname "$0")/.."
SET=${1:-msb_articulated}
ROUNDS=${2:-2}
DATA=${3:-$HOME/.cache/meshseek-data}
MANIFEST=$DATA/$SET/manifest.csv
METHOD=bfdsift+rld+lsf+lfd
WORK=$(mktemp -d)
trap 'rm -rf "$WORK"' EXIT
echo "machine: $(lscpu | sed -n 's/^Model name: *//p'), $(nproc) cores; $(date -u '+%F %H:%M UTC')"
echo "build/cli/meshseek eval --progress=false [--server in-process] --manifest $MANIFEST --method $METHOD --out <dir> --data_dir <fresh>"
run() {  # run NAME ROUND [--server in-process]
  local name=$1 round=$2 s t
  shift 2
  rm -rf "$WORK/data"
  s=$(date +%s.%N)
  build/cli/meshseek eval --progress=false "$@" --manifest "$MANIFEST" --method "$METHOD" \
    --out "$WORK/$name-$round" --data_dir "$WORK/data" >"$WORK/log" 2>"$WORK/err" ||
    { cat "$WORK/log" "$WORK/err"; return 1; }
  t=$(echo "$(date +%s.%N) - $s" | bc)
  echo "round $round $name: $t s; $(grep -m1 'micro' "$WORK/log" | awk '{print "FT " $3}'); $(grep -o 'time .*' "$WORK/log")" >&2
  grep 'features loaded' "$WORK/err" | sed 's/.*build-[0-9]*: /  /' >&2 || true
  echo "$t"
}
services=() in_process=()
for r in $(seq "$ROUNDS"); do
  services+=("$(run services "$r")")
  in_process+=("$(run in-process "$r" --server in-process)")
done
median() { printf '%s\n' "$@" | sort -n | awk '{a[NR]=$1} END{print (NR%2)?a[(NR+1)/2]:(a[NR/2]+a[NR/2+1])/2}'; }
s=$(median "${services[@]}") p=$(median "${in_process[@]}")
echo "median: services $s s, in process $p s, ratio $(echo "scale=3; $s / $p" | bc)"
first=$(ls -d "$WORK"/*-1 | head -1)
same=yes
for d in "$WORK"/*-*; do cmp -s "$first/distances.bin" "$d/distances.bin" || same=no; done
echo "every distance matrix the same: $same"
