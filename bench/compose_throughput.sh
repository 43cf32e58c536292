#!/usr/bin/env bash
# Ingest throughput of the compose deployment with 1, 2 and 3 extract replicas
# (one extraction slot each) on this Docker host; optionally the same on a
# single-node Docker Swarm (--swarm). Uses the image meshseek:test that
# tests/deploy_test.sh builds, and the CLI in ./build.
#   bench/compose_throughput.sh [MANIFEST] [--swarm]
# (COMPOSE_REPLICAS="" skips the compose runs.)
# Appends to bench/results/deploy.txt.
set -euo pipefail
cd "$(dirname "$0")/.."
MANIFEST=${1:-$HOME/.cache/meshseek-data/msb_articulated/manifest.csv}
BIN=build/cli/meshseek
PROBE=build/services/meshseek-probe
export MESHSEEK_IMAGE=meshseek:test MESHSEEK_PORT=50552
COMPOSE="docker-compose -p meshseek-bench -f deploy/docker-compose.yml"
RESULT=bench/results/deploy.txt
n=$(($(wc -l < "$MANIFEST") - 1))
wait_serving() {
  for _ in $(seq 300); do $PROBE --addr "localhost:$MESHSEEK_PORT" >/dev/null 2>&1 && return 0; sleep 0.2; done
  echo "coordinator not serving" >&2; return 1
}
ingest() {  # collection -> seconds
  /usr/bin/time -f %e $BIN ingest --progress=false --server "localhost:$MESHSEEK_PORT" \
    --collection "$1" --manifest "$MANIFEST" 2>&1 >/dev/null | tail -1
}
echo "# bench/compose_throughput.sh $(date -u +%F), $(nproc) cores: $(lscpu | sed -n 's/^Model name: *//p'); $MANIFEST ($n models), DLD-SIFT defaults" >> "$RESULT"
for r in ${COMPOSE_REPLICAS-1 2 3}; do
  $COMPOSE down -v >/dev/null 2>&1 || true
  MESHSEEK_MAX_IN_FLIGHT=$r $COMPOSE up -d --scale extract=$r >/dev/null 2>&1
  wait_serving
  sleep 3  # let every replica pass its first health check
  t=$(ingest "tp$r")
  echo "compose, $r extract replica(s) x 1 slot: $t s, $(python3 -c "print(round($n/$t, 2))") models/s" | tee -a "$RESULT"
done
$COMPOSE down -v >/dev/null 2>&1 || true
if [ "${2:-}" = "--swarm" ]; then
  docker swarm init --advertise-addr 127.0.0.1 >/dev/null 2>&1 || true
  for r in 1 2 3; do
    MESHSEEK_MAX_IN_FLIGHT=$r docker stack deploy -c deploy/docker-compose.yml meshseek-bench >/dev/null
    docker service scale -d meshseek-bench_extract=$r >/dev/null
    wait_serving
    for _ in $(seq 60); do
      [ "$(docker service ls --filter name=meshseek-bench_extract --format '{{.Replicas}}')" = "$r/$r" ] && break; sleep 1
    done
    sleep 5
    t=$(ingest "swarm$r")
    echo "swarm, $r extract replica(s) x 1 slot: $t s, $(python3 -c "print(round($n/$t, 2))") models/s" | tee -a "$RESULT"
    docker stack rm meshseek-bench >/dev/null; sleep 10
  done
  docker volume ls -q | grep '^meshseek-bench_' | xargs -r docker volume rm >/dev/null 2>&1 || true
fi
