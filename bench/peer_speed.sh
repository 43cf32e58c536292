#!/usr/bin/env bash
# Wall time of the whole McGill eval, meshseek's DLD-SIFT (embedded services,
# fresh data folder) against the off-the-shelf peer (Open3D FPFH + k-means +
# symmetric KL, ../shared/peers/fpfh_bof, its README's Debian packages:
# python3-open3d python3-numpy python3-scipy python3-sklearn), run
# alternately in one session so that both see the same machine; prints each
# run and the ratio of the medians. Research data and the peer live outside
# the repository: this script is a benchmark, never a test.
#
#   bench/peer_speed.sh [DATA_DIR] [ROUNDS]   (defaults: ~/.cache/meshseek-data, 2)
set -euo pipefail
cd "$(dirname "$0")/.."
DATA=${1:-$HOME/.cache/meshseek-data}
ROUNDS=${2:-2}
MANIFEST=$DATA/msb_articulated/manifest.csv
WORK=$(mktemp -d)
trap 'rm -rf "$WORK"' EXIT
# The peer finds the evaluator at ../../shared/tools from its own folder: run
# a copy from a layout where that resolves.
mkdir -p "$WORK/root/peers"
cp -r ../shared/peers/fpfh_bof "$WORK/root/peers/"
ln -s "$(cd ../shared && pwd)" "$WORK/root/shared"
PEER=$WORK/root/peers/fpfh_bof/run.py
seconds() { local s; s=$(date +%s.%N); "$@" >"$WORK/log" 2>&1 || { cat "$WORK/log"; return 1; }; echo "$(date +%s.%N) - $s" | bc; }
echo "machine: $(lscpu | sed -n 's/^Model name: *//p'), $(nproc) cores; $(date -u '+%F %H:%M UTC')"
echo "meshseek: build/cli/meshseek eval --progress=false --manifest $MANIFEST --method dld --out <dir> --data_dir <fresh>"
echo "peer: PEER_OUT=<fresh> /usr/bin/python3 ../shared/peers/fpfh_bof/run.py full --set msb --manifest $MANIFEST --no-cache"
ours=() theirs=()
for r in $(seq "$ROUNDS"); do
  rm -rf "$WORK/data" "$WORK/out" "$WORK/peer"
  t=$(seconds build/cli/meshseek eval --progress=false --manifest "$MANIFEST" --method dld \
        --out "$WORK/out" --data_dir "$WORK/data")
  ours+=("$t")
  echo "round $r meshseek dld: $t s ($(grep -m1 'micro' "$WORK/log" | awk '{print "FT " $3}'))"
  t=$(PEER_OUT="$WORK/peer" seconds /usr/bin/python3 "$PEER" full --set msb --manifest "$MANIFEST" --no-cache)
  theirs+=("$t")
  echo "round $r peer fpfh_bof: $t s"
done
median() { printf '%s\n' "$@" | sort -n | awk '{a[NR]=$1} END{print (NR%2)?a[(NR+1)/2]:(a[NR/2]+a[NR/2+1])/2}'; }
m=$(median "${ours[@]}") p=$(median "${theirs[@]}")
printf 'median: meshseek %.1f s, peer %.1f s, ratio %.2f\n' "$m" "$p" "$(echo "$m / $p" | bc -l)"
