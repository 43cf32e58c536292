#!/usr/bin/env bash
# The DLD-SIFT scale sweep (the paper's Fig. 6) on the development sets, with
# every other parameter at its shipped default: R-precision against E on
# McGill articulated and PSB train, written to bench/results/e_sweep.csv and
# plotted to bench/results/e_sweep.png.
#
#   bench/e_sweep.sh [DATA_DIR]    (default: ~/.cache/meshseek-data, from ../shared/data/unpack.sh)
#
# About 40 minutes on 2 cores. The plot needs python3-matplotlib (Debian), run by
# /usr/bin/python3 unless PYTHON says otherwise.
set -euo pipefail
cd "$(dirname "$0")/.."
DATA=${1:-$HOME/.cache/meshseek-data}
SCALES=${SCALES:-0.1,0.15,0.2,0.25,0.3,0.4,0.5}
./scripts/build.sh >/dev/null
OUT=bench/results
mkdir -p "$OUT"
CSV=$OUT/e_sweep.csv
rm -f "$CSV"
for set in msb_articulated psb_train; do
  build/bench/sweep --manifest "$DATA/$set/manifest.csv" --scales "$SCALES" --progress=false \
    --tag "$set" --csv "$CSV"
done
"${PYTHON:-/usr/bin/python3}" bench/plot_e_sweep.py "$OUT/e_sweep.png" "$CSV" \
  --series "msb_articulated=McGill articulated (255)" --series "psb_train=PSB train (904)" \
  --reference "paper DLD-SIFT, MSB: 74.5=74.5"
echo "wrote $CSV and $OUT/e_sweep.png"
