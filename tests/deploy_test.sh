#!/usr/bin/env bash
# End-to-end test of the compose deployment on this Docker host, run by CI
# (.ci/run) after the test suite, in about 2 minutes (74 s with the base image
# already built, debootstrap about 45 s more):
#   1. builds the base image (no registry: deploy/make-base-image.sh) and the
#      meshseek image from the binaries of ./build (deploy/image-from-build.sh:
#      deploy/Dockerfile's runtime stage, no second compile; --from-source
#      builds deploy/Dockerfile whole instead, about 25 minutes);
#   2. brings the compose stack up with one extract replica and runs
#      `meshseek eval` on the synthetic benchmark through the published
#      coordinator, scaling extract to 3 during the ingest and killing one
#      extract container hard in the middle;
#   3. checks every model is indexed exactly once and the distance matrix and
#      metrics equal an embedded run's;
#   4. checks that every service's metrics endpoint (container:9464) counted
#      the eval's calls, and that the query page (the web service) lists the
#      collection, ranks an uploaded model first and serves its thumbnail;
#   5. brings the stack down and up again and checks the index is still there.
# Reads only machine-readable output (status --format json, the web API's
# JSON, metrics.json, the matrices). Needs a Release build in ./build
# (scripts/build.sh), Docker and docker-compose, and root for debootstrap.
#   tests/deploy_test.sh [--keep] [--from-source]
set -euo pipefail
cd "$(dirname "$0")/.."
ROOT=$PWD
BIN=$ROOT/build/cli/meshseek
PROBE=$ROOT/build/services/meshseek-probe
COMPOSE="docker-compose -p meshseek-test -f deploy/docker-compose.yml"
export MESHSEEK_IMAGE=meshseek:test
export MESHSEEK_PORT=${MESHSEEK_PORT:-50551}
export MESHSEEK_WEB_PORT=${MESHSEEK_WEB_PORT:-50580}
T=$(mktemp -d)
cleanup() {
  if [ "${1:-}" != "--keep" ]; then $COMPOSE down -v --remove-orphans >/dev/null 2>&1 || true; fi
  rm -rf "$T"
}
trap 'cleanup "${KEEP:-}"' EXIT
FROM_SOURCE=
for arg in "$@"; do
  case $arg in
    --keep) KEEP=--keep ;;
    --from-source) FROM_SOURCE=1 ;;
    *) echo "usage: tests/deploy_test.sh [--keep] [--from-source]" >&2; exit 2 ;;
  esac
done
step() { echo "deploy_test: $*"; }
fail() { echo "deploy_test: FAILED: $*" >&2; exit 1; }

for tool in docker-compose curl; do
  command -v "$tool" >/dev/null || { apt-get update -qq && apt-get install -y -qq "$tool"; }
done

step "image"
START=$SECONDS
deploy/make-base-image.sh
if [ -n "$FROM_SOURCE" ]; then
  docker build -q -f deploy/Dockerfile --build-arg BASE=meshseek-base:bookworm -t "$MESHSEEK_IMAGE" . >/dev/null
else
  deploy/image-from-build.sh "$MESHSEEK_IMAGE"
fi
docker image ls "$MESHSEEK_IMAGE" --format 'deploy_test: image {{.Repository}}:{{.Tag}} {{.Size}}'
[ "$(docker run --rm "$MESHSEEK_IMAGE" id -un)" = meshseek ] || fail "image does not run as meshseek"

step "reference: the synthetic benchmark through the embedded stack"
"$BIN" synth --out "$T/syn" >/dev/null
"$BIN" eval --method dld --progress=false --manifest "$T/syn/manifest.csv" --out "$T/embedded" \
  --data_dir "$T/embedded-data" 2>/dev/null | grep -E "micro|macro"

wait_serving() {
  for _ in $(seq 150); do "$PROBE" --addr "localhost:$MESHSEEK_PORT" >/dev/null 2>&1 && return 0; sleep 0.2; done
  fail "coordinator not serving on port $MESHSEEK_PORT"
}

# Calls a compose service's containers served so far: the sum of
# meshseek_rpc_calls_total over each container's own metrics endpoint (not
# published: read at the container's address on the compose network).
calls_served() {
  local total=0 c ip n
  for c in $($COMPOSE ps -q "$1" 2>/dev/null); do
    ip=$(docker inspect -f '{{range .NetworkSettings.Networks}}{{.IPAddress}}{{end}}' "$c")
    n=$(curl -sf --max-time 5 "http://$ip:9464/metrics" \
        | awk '/^meshseek_rpc_calls_total/ { s += $2 } END { printf "%d", s }')
    total=$((total + ${n:-0}))
  done
  echo "$total"
}
SERVICES="coordinator resample extract codebook index-0 index-1"

# The synthetic collection's model counts, from `meshseek status --format json`.
collection_counts() {
  "$BIN" status --format json --server "localhost:$MESHSEEK_PORT" --collection synthetic \
    | python3 -c 'import json, sys
c = json.load(sys.stdin)["collection"]
print(" ".join(f"{k}={int(c[k])}" for k in ("models", "pending", "extracted", "failed", "indexed")))'
}
ALL_INDEXED="models=72 pending=0 extracted=72 failed=0 indexed=72"

step "compose up with 1 extract replica"
$COMPOSE down -v --remove-orphans >/dev/null 2>&1 || true
$COMPOSE up -d --scale extract=1 > "$T/compose.log" 2>&1 || { cat "$T/compose.log"; fail "compose up"; }
wait_serving

declare -A before
for s in $SERVICES; do before[$s]=$(calls_served "$s"); done

step "eval through the published coordinator; scale extract 1 -> 3 and kill one mid-ingest"
"$BIN" eval --method dld --progress=false --server "localhost:$MESHSEEK_PORT" --collection synthetic \
  --manifest "$T/syn/manifest.csv" --out "$T/cluster" > "$T/cluster.log" 2>&1 &
EVAL=$!
sleep 3
$COMPOSE up -d --no-recreate --scale extract=3 > "$T/compose.log" 2>&1 || { cat "$T/compose.log"; fail "scale to 3"; }
sleep 4
# awk, not head: under pipefail, head's early exit may end compose by SIGPIPE (exit 141).
victim=$($COMPOSE ps -q extract 2>/dev/null | awk 'NR == 1')
docker kill --signal KILL "$victim" >/dev/null
step "killed extract container ${victim:0:12}"
wait "$EVAL" || { cat "$T/cluster.log"; fail "eval through the cluster failed"; }
grep -E "micro|macro" "$T/cluster.log"
retried=$($COMPOSE logs coordinator 2>/dev/null | grep -c "will be retried" || true)
step "coordinator log: $retried model extraction(s) retried after the kill (gRPC's own retries are not logged)"

step "checks"
cmp "$T/embedded/distances.bin" "$T/cluster/distances.bin" || fail "distance matrices differ"
python3 - "$T/embedded/metrics.json" "$T/cluster/metrics.json" <<'PY' || fail "metrics differ"
import json, sys
a, b = (json.load(open(p)) for p in sys.argv[1:])
keys = ["queries", "classes", "micro", "macro", "per_class", "local_features"]
sys.exit(0 if all(a[k] == b[k] for k in keys) else 1)
PY
counts=$(collection_counts)
step "status: $counts"
[ "$counts" = "$ALL_INDEXED" ] \
  || fail "not every model indexed once: $counts"
[ "$($COMPOSE ps -q extract 2>/dev/null | wc -l)" -eq 3 ] || fail "expected 3 extract containers"

step "metrics: calls each service counted during the eval (its own endpoint, :9464/metrics)"
for s in $SERVICES; do
  after=$(calls_served "$s")
  step "  $s: ${before[$s]} -> $after"
  # DLD-SIFT, the eval's method, needs no resampling.
  [ "$s" = resample ] || [ "$after" -gt "${before[$s]}" ] || fail "$s counted no calls"
done
ip=$(docker inspect -f '{{range .NetworkSettings.Networks}}{{.IPAddress}}{{end}}' \
  "$($COMPOSE ps -q coordinator 2>/dev/null)")
curl -sf "http://$ip:9464/metrics" | grep '^meshseek_coordinator_models{collection="synthetic"' \
  | sed 's/^/deploy_test:   /'

step "the query page (web service, port $MESHSEEK_WEB_PORT)"
web=http://localhost:$MESHSEEK_WEB_PORT
for _ in $(seq 50); do curl -sf "$web/" >/dev/null && break; sleep 0.2; done
curl -sf "$web/" -o "$T/page.html" && grep -q 'id="results"' "$T/page.html" \
  || fail "no query page at $web/"
curl -sf "$web/api/collections" | python3 -c 'import json, sys
sys.exit(0 if any(c["name"] == "synthetic" for c in json.load(sys.stdin)["collections"]) else 1)' \
  || fail "web lists no collection 'synthetic'"
query=$(awk -F, 'NR == 2 { print $3 }' "$T/syn/manifest.csv")
query_id=$(awk -F, 'NR == 2 { print $1 }' "$T/syn/manifest.csv")
answer=$(curl -sf -F collection=synthetic -F top_k=3 -F "mesh=@$T/syn/$query" "$web/api/query") \
  || fail "web query failed"
echo "$answer" | python3 -c 'import json, sys
sys.exit(0 if json.load(sys.stdin)["results"][0]["model_id"] == sys.argv[1] else 1)' "$query_id" \
  || fail "web: $query_id not first: $answer"
curl -sf "$web/api/thumbnail?collection=synthetic&model_id=$query_id" -o "$T/thumb.png" \
  && [ "$(head -c 4 "$T/thumb.png" | tail -c 3)" = PNG ] || fail "web: no thumbnail"
step "  uploaded $query: first result $query_id, thumbnail served"

step "down and up again: the index is still there"
$COMPOSE down > "$T/compose.log" 2>&1 || { cat "$T/compose.log"; fail "compose down"; }
$COMPOSE up -d > "$T/compose.log" 2>&1 || { cat "$T/compose.log"; fail "compose up again"; }
wait_serving
[ "$(collection_counts)" = "$ALL_INDEXED" ] \
  || fail "index lost after down/up: $(collection_counts)"
"$BIN" eval --progress=false --server "localhost:$MESHSEEK_PORT" --collection synthetic \
  --manifest "$T/syn/manifest.csv" --out "$T/again" >/dev/null 2>&1 || fail "eval after restart"
cmp "$T/embedded/distances.bin" "$T/again/distances.bin" || fail "matrix changed after restart"
step "PASSED in $((SECONDS - START)) s"
