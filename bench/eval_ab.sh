#!/usr/bin/env bash
# The whole in-process evaluation (extract, codebooks, encode, rank) of one
# labelled set by two builds of the CLI, alternated run by run in one session
# (this machine is shared: compare the two columns of one run, not runs of
# different days), with each run's first tier and its stages' seconds from
# metrics.json.
#
#   bench/eval_ab.sh BASE_MESHSEEK NEW_MESHSEEK [MANIFEST] [ROUNDS] [-- EVAL FLAGS]
#
# BASE_MESHSEEK: e.g. landed main's build/cli/meshseek, copied aside.
# Defaults: McGill articulated (~/.cache/meshseek-data; research data, bench
# only), 2 rounds, each build's default method. Prints a line per run and the
# medians per build.
set -euo pipefail
BASE=$1
NEW=$2
MANIFEST=${3:-$HOME/.cache/meshseek-data/msb_articulated/manifest.csv}
ROUNDS=${4:-2}
shift $(( $# < 4 ? $# : 4 ))
[ "${1:-}" = "--" ] && shift
WORK=$(mktemp -d)
trap 'rm -rf "$WORK"' EXIT
echo "machine: $(lscpu | sed -n 's/^Model name: *//p'), $(nproc) cores; $(date -u '+%Y-%m-%d %H:%M UTC'); load $(cut -d' ' -f1-3 /proc/loadavg)"
echo "set: $MANIFEST; $ROUNDS rounds, base and new alternated; flags: ${*:-none}"
for r in $(seq "$ROUNDS"); do
  for build in base new; do
    binary=$BASE; [ "$build" = new ] && binary=$NEW
    out="$WORK/$build-$r"
    start=$(date +%s.%N)
    timeout 1800 "$binary" eval --server in-process --progress=false --format json \
      --manifest "$MANIFEST" --out "$out" "$@" >/dev/null 2>"$WORK/err" ||
      { cat "$WORK/err" >&2; exit 1; }
    wall=$(echo "$(date +%s.%N) - $start" | bc -l)
    python3 - "$out/metrics.json" "$build" "$r" "$wall" <<'PY'
import json, sys
m = json.load(open(sys.argv[1])); t = m["timings_seconds"]
per = " ".join("%s=%.1f+%.1f+%.1f" % (k, v["extract"], v["codebook"], v["encode"])
               for k, v in t.items() if isinstance(v, dict))
print("%-4s round %s: wall %6.1f s  FT %.2f  extract %.1f codebook %.1f encode %.1f rank %.1f  (%s)"
      % (sys.argv[2], sys.argv[3], float(sys.argv[4]), m["micro"]["FT"], t["extract"],
         t["codebook"], t["encode"], t["rank"], per))
PY
  done
done | tee "$WORK/runs"
for build in base new; do
  grep "^$build " "$WORK/runs" | sed 's/.*wall *\([0-9.]*\) s.*/\1/' | sort -n |
    awk -v b="$build" '{a[NR]=$1} END{printf "%s median wall %.1f s\n", b, (NR%2)?a[(NR+1)/2]:(a[NR/2]+a[NR/2+1])/2}'
done
