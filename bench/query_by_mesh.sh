#!/usr/bin/env bash
# A query by mesh end to end through the services, and its stages apart
# (issue "What the best configuration costs", item 3): `meshseek serve` on a
# fresh data folder, MANIFEST ingested and built with METHOD (default: the
# default fusion), then QUERIES of its models queried as files with
# `meshseek query --top_k 10 --format json`, one after the other. Prints each
# query's wall time (process start to ranked list out) and the coordinator's
# stages (QueryResponse.timings), then their medians. With PICTURES (a folder
# of PNG or JPEG files, e.g. bench/picture_benchmark --write_pictures), the
# queries are QUERIES of those pictures (`meshseek query --image`) instead;
# METHOD must then hold lfd.
#   bench/query_by_mesh.sh MANIFEST [METHOD] [QUERIES] [PICTURES]
# Needs a Release build in ./build.
set -euo pipefail
cd "$(dirname "$0")/.."
MANIFEST=${1:?usage: bench/query_by_mesh.sh MANIFEST [METHOD] [QUERIES]}
METHOD=${2:-}
QUERIES=${3:-10}
PICTURES=${4:-}
BIN=$PWD/build/cli/meshseek
DATA=$(mktemp -d /tmp/meshseek-query-bench.XXXXXX)
PORT=$(python3 -c 'import socket; s=socket.socket(); s.bind(("127.0.0.1",0)); print(s.getsockname()[1])')
trap 'kill "$SERVER" 2>/dev/null; wait "$SERVER" 2>/dev/null; rm -rf "$DATA"' EXIT
"$BIN" serve --data_dir "$DATA" --port "$PORT" > "$DATA/serve.log" 2>&1 &
SERVER=$!
for _ in $(seq 100); do grep -q "serving on" "$DATA/serve.log" && break; sleep 0.2; done
CLIENT=("$BIN" --server "127.0.0.1:$PORT" --progress=false)
echo "# bench/query_by_mesh.sh $MANIFEST ${METHOD:-(default method)} $QUERIES: $(date -u '+%F %H:%M UTC'), $(nproc) cores: $(lscpu | sed -n 's/^Model name: *//p')"
start=$(date +%s.%N)
timeout 1800 "${CLIENT[@]}" ingest --collection bench --manifest "$MANIFEST" ${METHOD:+--method "$METHOD"} 2>&1 | tail -1
echo "ingest: $(python3 -c "print(f'{$(date +%s.%N) - $start:.1f}')") s"
start=$(date +%s.%N)
timeout 1800 "${CLIENT[@]}" build --collection bench 2>&1 | tail -1
echo "build: $(python3 -c "print(f'{$(date +%s.%N) - $start:.1f}')") s"
# The first QUERIES models of the manifest, as files (paths relative to it),
# or the first QUERIES pictures.
dir=$(dirname "$MANIFEST")
if [ -n "$PICTURES" ]; then
  find "$PICTURES" -maxdepth 1 -type f \( -name '*.png' -o -name '*.jpg' \) | sort | head -n "$QUERIES" |
    while read -r file; do echo "$(basename "$file"),-,--image=$file"; done
else
  tail -n +2 "$MANIFEST" | head -n "$QUERIES"
fi | while IFS=, read -r id label path; do
  file=$path; [[ $file = /* || $file = --image=* ]] || file=$dir/$path
  t0=$(date +%s.%N)
  json=$("${CLIENT[@]}" query --collection bench --top_k 10 --format json "$file")
  t1=$(date +%s.%N)
  python3 - "$id" "$t0" "$t1" "$json" <<'PY'
import json, sys
model, t0, t1, answer = sys.argv[1], float(sys.argv[2]), float(sys.argv[3]), json.loads(sys.argv[4])
t = answer["timings"]
members = " ".join(f'{m["method"]}={1e3*m["extract_seconds"]:.0f}+{1e3*m["encode_seconds"]:.0f}'
                   for m in t["methods"])
top = answer["results"][0]["model_id"] if answer["results"] else "-"
print(f'query {model}: wall {1e3*(t1-t0):.0f} ms; mesh {1e3*t["mesh_seconds"]:.0f}, '
      f'signatures {1e3*t["signatures_seconds"]:.0f} ({members}), search {1e3*t["search_seconds"]:.0f} ms; top {top}')
PY
done | tee "$DATA/queries.txt"
python3 - "$DATA/queries.txt" <<'PY'
import re, statistics, sys
rows = open(sys.argv[1]).read().splitlines()
def med(pattern):
    values = [float(re.search(pattern, r).group(1)) for r in rows]
    return statistics.median(values) if values else float("nan")
stages = {name: med(name + r" (\d+)") for name in ("wall", "mesh", "signatures", "search")}
print(f"median of {len(rows)}: wall {stages['wall']:.0f} ms, mesh {stages['mesh']:.0f}, "
      f"signatures {stages['signatures']:.0f}, search {stages['search']:.0f} ms")
for method in re.findall(r"(\w+)=\d+\+\d+", rows[0] if rows else ""):
    extract, encode = med(method + r"=(\d+)"), med(method + r"=\d+\+(\d+)")
    print(f"  {method}: extract {extract:.0f} ms, encode {encode:.0f} ms (medians)")
PY
