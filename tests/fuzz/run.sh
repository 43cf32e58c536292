#!/usr/bin/env bash
# Runs the fuzz harnesses over their seed corpora, JOBS at a time (default:
# the number of cores; each harness is one single-threaded process), and
# prints one line per harness as it ends: executions, final corpus (files and
# bytes), seconds.
#
#   tests/fuzz/run.sh BUILD_DIR [libFuzzer flags...]
#   tests/fuzz/run.sh build-fuzz -max_total_time=20        # CI's short run
#   tests/fuzz/run.sh build-fuzz -runs=10000000            # the long local run
#   FUZZERS="mesh_off manifest" tests/fuzz/run.sh build-fuzz -runs=100000
#
# Seeds (tests/fuzz/corpus/<harness>/, committed) are read only; what a run
# discovers goes to BUILD_DIR/fuzz-corpus/<harness>/, so that later runs start
# from it, and a crash, leak, timeout or memory overrun stops the run with the
# input in BUILD_DIR/fuzz-artifacts/ and a non-zero exit. The flags always
# include the issue's limits (-rss_limit_mb=2048 -timeout=5).
set -euo pipefail
cd "$(dirname "$0")/../.."
BUILD_DIR=${1:?usage: tests/fuzz/run.sh BUILD_DIR [libFuzzer flags...]}
shift
ALL="mesh_off mesh_obj mesh_ply mesh_stl mesh_detect manifest class_file
     convert_mesh convert_features convert_graph convert_histogram convert_params picture"
FUZZERS=${FUZZERS:-$ALL}
JOBS=${JOBS:-$(nproc)}
mkdir -p "$BUILD_DIR/fuzz-logs" "$BUILD_DIR/fuzz-artifacts"

# One harness; its exit code also goes to fuzz-logs/<harness>.rc.
fuzz() {
  local h=$1
  shift
  local work="$BUILD_DIR/fuzz-corpus/$h" log="$BUILD_DIR/fuzz-logs/$h.log"
  local start rc=0 seconds runs files bytes
  mkdir -p "$work"
  start=$(date +%s.%N)
  # -max_len: the seeds are a few hundred bytes; 4 KB leaves room for every
  # header and body structure while keeping executions fast.
  "$BUILD_DIR/tests/fuzz/fuzz_$h" -rss_limit_mb=2048 -timeout=5 -max_len=4096 \
      -print_final_stats=1 -artifact_prefix="$BUILD_DIR/fuzz-artifacts/$h-" "$@" \
      "$work" "tests/fuzz/corpus/$h" >"$log" 2>&1 || rc=$?
  seconds=$(awk -v a="$start" -v b="$(date +%s.%N)" 'BEGIN {print b - a}')
  runs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -1)
  files=$(find "$work" -type f | wc -l)
  bytes=$(find "$work" -type f -printf '%s\n' | awk '{s += $1} END {print s + 0}')
  printf '%-18s %12s execs  corpus %6d files %9d bytes  %8.1f s  rc %d\n' \
      "$h" "${runs:-?}" "$files" "$bytes" "$seconds" "$rc"
  if [ "$rc" -ne 0 ]; then
    grep -E 'ERROR|SUMMARY|Test unit written' "$log" | head -5 || true
  fi
  echo "$rc" >"$BUILD_DIR/fuzz-logs/$h.rc"
}

for h in $FUZZERS; do
  rm -f "$BUILD_DIR/fuzz-logs/$h.rc"
  while [ "$(jobs -rp | wc -l)" -ge "$JOBS" ]; do wait -n || true; done
  fuzz "$h" "$@" &
done
wait
failed=0
for h in $FUZZERS; do
  [ "$(cat "$BUILD_DIR/fuzz-logs/$h.rc" 2>/dev/null)" = 0 ] || failed=1
done
exit $failed
