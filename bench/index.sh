#!/usr/bin/env bash
# The index service through gRPC at growing collection sizes (issue 9):
# add rate, resident memory, Search p50/p95/p99 for top-10 exact and with
# candidates (with recall@10 against exact), throughput with 4 clients and
# restart time, on synthetic histograms shaped like real ones
# (bench/synthetic_histograms.h), V = 2,000 and V = 20,000.
#   bench/index.sh [SIZES_2000] [SIZES_20000]
#     (defaults "1000,10000,100000,500000,1000000" and "1000,10000,100000")
# Writes bench/results/index.txt. Needs a Release build in ./build; the
# 1,000,000-model run takes about 15 minutes and 9 GB.
set -euo pipefail
cd "$(dirname "$0")/.."
SIZES_2000=${1:-1000,10000,100000,500000,1000000}
SIZES_20000=${2:-1000,10000,100000}
RESULT=bench/results/index.txt
run() {
  echo
  echo "\$ $*"
  "$@" 2>&1 | grep -v "^I "
}
{
  echo "# bench/index.sh $(date -u '+%F %H:%M UTC'), $(nproc) cores: $(lscpu | sed -n 's/^Model name: *//p'), $(free -g | awk '/Mem:/{print $2}') GiB"
  echo "# server: build/services/meshseek-index (all cores), one client for latency, 4 for adds and throughput"
  run build/bench/index_benchmark --sizes="$SIZES_2000" --vocabulary=2000 --queries=200
  run build/bench/index_benchmark --sizes="$SIZES_20000" --vocabulary=20000 --queries=200
} | tee "$RESULT"
