#!/usr/bin/env bash
# The Python client end to end (ctest python/example_test):
#   python/example_test.sh MESHSEEK_CLI GENERATED_DIR [PYTHON]
# writes a small synthetic benchmark (`meshseek synth`), starts `meshseek serve`
# on a free port (--port 0: it prints the port it got) with a temporary data
# folder, runs python/example.py against it with PYTHONPATH=GENERATED_DIR and
# checks that the nearest model to the query, by its mesh and then by its
# thumbnail as a picture (the collection is dld+lfd), is the query itself or
# of its class. The server is stopped with SIGTERM and the folder removed whatever
# happens. Exits 77 (ctest: skipped) only when PYTHON has no grpc or protobuf.
set -euo pipefail
CLI=$1
GENERATED=$2
PY=${3:-/usr/bin/python3}
HERE=$(cd "$(dirname "$0")" && pwd)
if ! "$PY" -c 'import grpc, google.protobuf' 2>/dev/null; then
  echo "example_test: SKIPPED: $PY lacks grpc/protobuf (apt-get install python3-grpcio python3-protobuf)"
  exit 77
fi

T=$(mktemp -d)
SERVER=
cleanup() {
  if [ -n "$SERVER" ] && kill -0 "$SERVER" 2>/dev/null; then
    kill -TERM "$SERVER" 2>/dev/null || true
    for _ in $(seq 50); do kill -0 "$SERVER" 2>/dev/null || break; sleep 0.1; done
    kill -KILL "$SERVER" 2>/dev/null || true
  fi
  rm -rf "$T"
}
trap cleanup EXIT
fail() {
  echo "example_test: FAILED: $*" >&2
  [ -f "$T/server.log" ] && sed 's/^/  server: /' "$T/server.log" >&2
  exit 1
}

# 9 classes x 3 models; small DLD-SIFT parameters keep the run to seconds.
"$CLI" synth --out "$T/syn" --models_per_class 3 >/dev/null || fail "meshseek synth"
"$CLI" serve --port 0 --data_dir "$T/data" >"$T/server.log" 2>&1 &
SERVER=$!
ADDR=
for _ in $(seq 300); do
  ADDR=$(sed -n 's/^meshseek serving on \([^ ]*\) .*/\1/p' "$T/server.log")
  [ -n "$ADDR" ] && break
  kill -0 "$SERVER" 2>/dev/null || fail "meshseek serve exited"
  sleep 0.1
done
[ -n "$ADDR" ] || fail "meshseek serve did not print its address in 30 s"

# The query: the manifest's 5th model (id,class,path).
IFS=, read -r QID QCLASS QPATH < <(sed -n 6p "$T/syn/manifest.csv")
PYTHONPATH=$GENERATED timeout 90 "$PY" "$HERE/example.py" --server "$ADDR" --folder "$T/syn" \
  --collection example-test --query "$T/syn/$QPATH" --top_k 5 --method dld+lfd \
  --param points=256 --param vocabulary=32 | tee "$T/example.log" || fail "example.py"
# Two rankings: the mesh's, then its thumbnail's as a picture.
FIRSTS=$(awk '$1 == "1" { print $2, $3 }' "$T/example.log")
[ "$(wc -l <<<"$FIRSTS")" = 2 ] || fail "example.py printed $(wc -l <<<"$FIRSTS") rank-1 lines, not 2"
while read -r ID LABEL; do
  [ "$ID" = "$QID" ] || [ "$LABEL" = "$QCLASS" ] ||
    fail "nearest to model $QID ($QCLASS) is model $ID ($LABEL)"
done <<<"$FIRSTS"

kill -TERM "$SERVER"
wait "$SERVER" || fail "meshseek serve exited with status $? after SIGTERM"
SERVER=
echo "example_test: OK (nearest to model $QID of class $QCLASS by mesh, then by picture: $(tr '\n' ';' <<<"$FIRSTS"))"
