#!/usr/bin/env bash
# Two builds' fused query by mesh end to end through the services, alternated
# on one machine (issue "What the best configuration costs", item 3): NEW's
# `meshseek serve` ingests and builds MANIFEST with the default fusion once;
# then, ROUNDS times, BASE's server and NEW's server in turn serve that data
# folder and answer the first QUERIES models of the manifest as files
# (`meshseek query --top_k 10 --format json`, the same build's CLI). Prints
# each round's median wall time (CLI start to ranked list out) and the
# coordinator's signatures stage, then the medians over all rounds and their
# ratio. BASE and NEW are meshseek binaries whose stores read each other's.
# BASE_COLLECTION_FLAGS, when set, compares collection parameters instead of
# code: NEW also ingests and builds a second collection made with those flags
# (e.g. "--rld.rld_samples=15000"), and BASE's turns query that one.
#   [BASE_COLLECTION_FLAGS=...] bench/query_ab.sh BASE NEW MANIFEST [QUERIES] [ROUNDS]
set -euo pipefail
BASE=${1:?usage: bench/query_ab.sh BASE NEW MANIFEST [QUERIES] [ROUNDS]}
NEW=${2:?usage}
MANIFEST=${3:?usage}
QUERIES=${4:-10}
ROUNDS=${5:-3}
DATA=$(mktemp -d /tmp/meshseek-query-ab.XXXXXX)
SERVER=
stop() { [ -n "$SERVER" ] && kill "$SERVER" 2>/dev/null && wait "$SERVER" 2>/dev/null; SERVER=; }
trap 'stop; rm -rf "$DATA"' EXIT
serve() {  # binary -> port
  local port
  port=$(python3 -c 'import socket; s=socket.socket(); s.bind(("127.0.0.1",0)); print(s.getsockname()[1])')
  : > "$DATA/serve.log"
  "$1" serve --data_dir "$DATA/store" --port "$port" >> "$DATA/serve.log" 2>&1 &
  SERVER=$!
  for _ in $(seq 150); do grep -q "serving on" "$DATA/serve.log" && break; sleep 0.2; done
  echo "$port"
}
echo "# bench/query_ab.sh $BASE $NEW $MANIFEST $QUERIES $ROUNDS: $(date -u '+%F %H:%M UTC'), $(nproc) cores: $(lscpu | sed -n 's/^Model name: *//p')"
port=$(serve "$NEW")
timeout 1800 "$NEW" --server "127.0.0.1:$port" --progress=false ingest --collection bench --manifest "$MANIFEST" | tail -1
timeout 1800 "$NEW" --server "127.0.0.1:$port" --progress=false build --collection bench | tail -1
BASE_COLLECTION=bench
if [ -n "${BASE_COLLECTION_FLAGS:-}" ]; then
  BASE_COLLECTION=bench_base
  # shellcheck disable=SC2086  # the flags are words
  timeout 1800 "$NEW" --server "127.0.0.1:$port" --progress=false ingest --collection bench_base \
    --manifest "$MANIFEST" $BASE_COLLECTION_FLAGS | tail -1
  timeout 1800 "$NEW" --server "127.0.0.1:$port" --progress=false build --collection bench_base | tail -1
fi
stop
dir=$(dirname "$MANIFEST")
mapfile -t files < <(tail -n +2 "$MANIFEST" | head -n "$QUERIES" | while IFS=, read -r _ _ path; do
  [[ $path = /* ]] && echo "$path" || echo "$dir/$path"; done)
for round in $(seq "$ROUNDS"); do
  for variant in base new; do
    bin=$BASE collection=$BASE_COLLECTION
    [ "$variant" = new ] && bin=$NEW collection=bench
    port=$(serve "$bin")
    "$bin" --server "127.0.0.1:$port" --progress=false query --collection "$collection" --top_k 10 \
      --format json "${files[0]}" > /dev/null  # warm: the codebooks and index load
    for file in "${files[@]}"; do
      t0=$(date +%s.%N)
      json=$("$bin" --server "127.0.0.1:$port" --progress=false query --collection "$collection" \
        --top_k 10 --format json "$file")
      t1=$(date +%s.%N)
      python3 -c 'import json, sys
t0, t1, answer, variant = sys.argv[1:]
signatures = json.loads(answer)["timings"]["signatures_seconds"]
print(variant, f"{1e3 * (float(t1) - float(t0)):.1f}", f"{1e3 * signatures:.1f}")' \
        "$t0" "$t1" "$json" "$variant"
    done | tee -a "$DATA/times.txt" | python3 -c '
import statistics, sys
rows = [l.split() for l in sys.stdin]
print(f"round '"$round"' {rows[0][0]}: median wall {statistics.median(float(r[1]) for r in rows):.0f} ms, "
      f"signatures {statistics.median(float(r[2]) for r in rows):.0f} ms")'
    stop
  done
done
python3 - "$DATA/times.txt" <<'PY'
import statistics, sys
rows = [l.split() for l in open(sys.argv[1])]
med = {v: [statistics.median(float(r[k]) for r in rows if r[0] == v) for k in (1, 2)]
       for v in ("base", "new")}
print(f"all rounds: base wall {med['base'][0]:.0f} ms (signatures {med['base'][1]:.0f}), "
      f"new wall {med['new'][0]:.0f} ms (signatures {med['new'][1]:.0f}); "
      f"ratio {med['new'][0] / med['base'][0]:.2f} (signatures {med['new'][1] / med['base'][1]:.2f})")
PY
