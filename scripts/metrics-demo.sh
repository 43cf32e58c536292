#!/usr/bin/env bash
# Shows the Prometheus metrics of the embedded stack moving: starts
# `meshseek serve --metrics_port`, scrapes /metrics, evaluates the synthetic
# benchmark through the served coordinator (ingest, build, all-pairs ranking),
# scrapes again and prints the key lines before and after, and their diff.
# Needs a build in ./build (scripts/build.sh) and curl. State goes to a
# temporary folder, removed at the end.
#   scripts/metrics-demo.sh            # ports 50051 (gRPC) and 9464 (metrics)
#   PORT=50061 METRICS_PORT=9474 scripts/metrics-demo.sh
set -euo pipefail
cd "$(dirname "$0")/.."
BIN=build/cli/meshseek
PORT=${PORT:-50051}
METRICS_PORT=${METRICS_PORT:-9464}
URL=http://127.0.0.1:$METRICS_PORT/metrics
T=$(mktemp -d)
SERVE=""
cleanup() {
  if [ -n "$SERVE" ]; then kill "$SERVE" 2>/dev/null || true; wait "$SERVE" 2>/dev/null || true; fi
  rm -rf "$T"
}
trap cleanup EXIT

"$BIN" serve --port "$PORT" --metrics_port "$METRICS_PORT" --data_dir "$T/data" >"$T/serve.log" 2>&1 &
SERVE=$!
for _ in $(seq 100); do curl -sf "$URL" >/dev/null && break; sleep 0.1; done
curl -sf "$URL" >/dev/null || { cat "$T/serve.log"; echo "metrics-demo: no metrics on $URL" >&2; exit 1; }

# The lines worth watching: calls by method and code, calls timed, and the
# coordinator's and index's gauges (health checks left out).
key() { grep -E '^meshseek_(rpc_calls_total|rpc_duration_seconds_count|coordinator_models|index_models)' | grep -v grpc.health || true; }

curl -sf "$URL" | key >"$T/before"
"$BIN" synth --out "$T/syn" >/dev/null
echo "\$ meshseek eval --server 127.0.0.1:$PORT --manifest syn/manifest.csv --method dld"
"$BIN" eval --progress=false --server "127.0.0.1:$PORT" --manifest "$T/syn/manifest.csv" \
  --method dld --out "$T/eval" | grep -E "micro|macro" || true
curl -sf "$URL" | key >"$T/after"

echo "== $URL before ($(wc -l <"$T/before") key lines)"
cat "$T/before"
echo "== after"
cat "$T/after"
echo "== diff"
diff "$T/before" "$T/after" || true
