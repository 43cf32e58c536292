#!/usr/bin/env bash
# Codebooks at large vocabularies (issue 9, part 3): training and encoding
# time, exact against approximate assignment, and the libraries compared.
# Writes bench/results/codebook.txt (machine, date, each command and its output).
#
#   bench/codebook.sh [BUILD_DIR] [DATA_DIR]   (defaults: build, ~/.cache/meshseek-data)
#
# Takes about 30 minutes on the 2-core development machine. Times are given as
# wall and CPU seconds: on a shared machine CPU seconds / threads is the better
# estimate of the wall time on idle cores.
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD=${1:-build}
DATA=${2:-$HOME/.cache/meshseek-data}
BIN="$BUILD/bench/codebook_benchmark"
OUT=bench/results/codebook.txt
TMP=$(mktemp -d)
trap 'rm -rf "$TMP"' EXIT
# Faiss's OpenMP threads must not spin while idle (it would inflate CPU time).
export OMP_WAIT_POLICY=passive

run() {
  echo
  echo "\$ $*" | sed "s|$TMP|TMP|g"
  "$@" 2>&1 | grep -v '^I ' | sed "s|$TMP|TMP|g"
}
{
  echo "machine: $(lscpu | sed -n 's/^Model name: *//p'), $(nproc) cores, $(free -g | awk '/Mem:/{print $2}') GiB"
  echo "date: $(date -u '+%Y-%m-%d %H:%M UTC')"
  echo "load average at start: $(cut -d' ' -f1-3 /proc/loadavg)"
  echo
  echo "== V = 2,000 (today's default), 200,000 SIFT-like descriptors (100 per word, as the pipeline)"
  run "$BIN" --experiment=train --points=200000 --vocabulary=2000 --assignment=exact
  run "$BIN" --experiment=train --points=200000 --vocabulary=2000 --assignment=approximate \
    --seeding=random
  run "$BIN" --experiment=train --points=200000 --vocabulary=2000 --assignment=approximate \
    --seeding=kmeanspp
  echo
  echo "== Where exact gets too slow: V = 10,000, 500,000 descriptors, 3 iterations"
  run "$BIN" --experiment=train --points=500000 --vocabulary=10000 --iterations=3 \
    --assignment=exact --agreement_sample=20000
  run "$BIN" --experiment=train --points=500000 --vocabulary=10000 --iterations=3 \
    --assignment=approximate --agreement_sample=20000
  echo
  echo "== Target: V = 20,000 on 1,000,000 descriptors (automatic choice: approximate)"
  run "$BIN" --experiment=train --points=1000000 --vocabulary=20000 \
    --codebook_out="$TMP/v20000.mscb"
  echo
  echo "== Target: 1,000 models of 2,000-3,000 descriptors encoded against it"
  run "$BIN" --experiment=encode --codebook_in="$TMP/v20000.mscb" --models=1000 --exact_models=40
  echo
  echo "== Probes, and the libraries (Faiss 1.7.3 on OpenBLAS 0.3.21), on the V = 20,000 codebook"
  run "$BIN" --experiment=libraries --codebook_in="$TMP/v20000.mscb" --agreement_sample=20000 \
    --probes_list=4,8,16
  if [ -f "$DATA/msb_articulated/manifest.csv" ]; then
    echo
    echo "== McGill articulated (DLD-SIFT, pipeline defaults), V = 2,000: exact against approximate"
    run "$BIN" --experiment=collection --manifest="$DATA/msb_articulated/manifest.csv" \
      --vocabulary=2000 --probes_list=8
  fi
} | tee "$OUT"
