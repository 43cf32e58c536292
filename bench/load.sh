#!/usr/bin/env bash
# The load generator against the embedded stack: 64 concurrent Query clients
# (and 4 Ingest clients) for 60 s on the synthetic benchmark, 0 errors wanted.
#   bench/load.sh [load_benchmark flags, e.g. --query_clients 128 --duration 120s]
# Writes bench/results/load.txt. Needs a Release build in ./build
# (cmake --build build --target load_benchmark).
set -euo pipefail
cd "$(dirname "$0")/.."
RESULT=bench/results/load.txt
ARGS=(--query_clients 64 --ingest_clients 4 --duration 60s --models_per_class 8 --progress=false "$@")
{
  echo "# bench/load.sh $(date -u '+%F %H:%M') UTC, $(nproc) cores:$(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2), $(free -g | awk '/Mem:/ {print $2}') GiB"
  echo "# load: $(uptime | sed 's/.*load average/load average/') before the run (the machine may be shared)"
  echo "# command: build/services/load_benchmark ${ARGS[*]}"
  echo "# embedded stack, shipped defaults (method dld; server threads 16, queue 256 per service)"
} > "$RESULT"
build/services/load_benchmark "${ARGS[@]}" 2>/dev/null | tee -a "$RESULT"
