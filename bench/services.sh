#!/usr/bin/env bash
# Cost of the services path against the in-process pipeline, and ingest
# throughput with 1 and 2 extract worker processes.
#   bench/services.sh [MANIFEST]   (default: McGill articulated, unpacked by ../shared/data/unpack.sh)
# Writes bench/results/services.txt. Needs a Release build in ./build.
set -euo pipefail
cd "$(dirname "$0")/.."
MANIFEST=${1:-$HOME/.cache/meshseek-data/msb_articulated/manifest.csv}
B=build
OUT=$(mktemp -d)
trap 'kill $(jobs -p) 2>/dev/null || true; rm -rf "$OUT"' EXIT
RESULT=bench/results/services.txt
{
  echo "# bench/services.sh $(date -u +%F), $(nproc) cores: $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2)"
  echo "# manifest: $MANIFEST ($(($(wc -l < "$MANIFEST") - 1)) models), method dld, shipped defaults"
} > "$RESULT"

seconds() { /usr/bin/time -f %e "$@" 2>&1 >/dev/null | tail -1; }

t_in=$(seconds $B/cli/meshseek eval --progress=false --server in-process --manifest "$MANIFEST" --out "$OUT/in")
t_svc=$(seconds $B/cli/meshseek eval --progress=false --data_dir "$OUT/data" --manifest "$MANIFEST" --out "$OUT/svc")
same=$(cmp -s "$OUT/in/distances.bin" "$OUT/svc/distances.bin" && echo identical || echo DIFFERENT)
echo "eval in-process:           $t_in s" >> "$RESULT"
echo "eval through the services: $t_svc s (embedded stack, fresh data folder; ratio $(python3 -c "print(round($t_svc/$t_in, 3))")); distance matrices $same" >> "$RESULT"

# Ingest throughput: real server processes on loopback, N extract workers
# of one extraction slot each.
free_port() { python3 -c 'import socket; s=socket.socket(); s.bind(("127.0.0.1",0)); print(s.getsockname()[1])'; }
wait_port() { for _ in $(seq 100); do $B/services/meshseek-probe --addr "127.0.0.1:$1" >/dev/null 2>&1 && return 0; sleep 0.1; done; return 1; }
for workers in 1 2; do
  D="$OUT/w$workers"; mkdir -p "$D"
  pr=$(free_port); pc=$(free_port); pi=$(free_port); pk=$(free_port)
  $B/services/meshseek-resample --port $pr >/dev/null 2>&1 &
  $B/services/meshseek-codebook --port $pc --data_dir "$D/codebook" >/dev/null 2>&1 &
  $B/services/meshseek-index --port $pi --data_dir "$D/index" >/dev/null 2>&1 &
  targets=""
  for w in $(seq $workers); do
    pe=$(free_port)
    $B/services/meshseek-extract --port $pe --workers 1 >/dev/null 2>&1 &
    wait_port $pe
    targets="${targets:+$targets,}127.0.0.1:$pe"
  done
  $B/services/meshseek-coordinator --port $pk --data_dir "$D/coordinator" --resample 127.0.0.1:$pr \
    --extract "ipv4:$targets" --codebook 127.0.0.1:$pc --index 127.0.0.1:$pi --max_in_flight $workers >/dev/null 2>&1 &
  wait_port $pr; wait_port $pc; wait_port $pi; wait_port $pk
  t=$(seconds $B/cli/meshseek ingest --progress=false --server 127.0.0.1:$pk --collection bench --manifest "$MANIFEST")
  n=$(($(wc -l < "$MANIFEST") - 1))
  echo "ingest with $workers extract worker(s) x 1 slot: $t s, $(python3 -c "print(round($n/$t, 2))") models/s" >> "$RESULT"
  kill $(jobs -p) 2>/dev/null || true; wait 2>/dev/null || true
done
cat "$RESULT"
