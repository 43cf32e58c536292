#!/usr/bin/env bash
# Speed and memory of the shipped defaults on this machine:
#   1. per-model extraction time of every method on one core (median and p90
#      over the first 50 McGill articulated models, ~13k vertices each), and
#      RLD-SIFT's time against N_RLD;
#   2. the whole `meshseek eval` of McGill articulated on all cores, through
#      the embedded services with a fresh data folder: wall time and peak
#      memory.
# Results go to bench/results/speed_*.{json,txt}.
#
#   bench/speed.sh [DATA_DIR]    (default: ~/.cache/meshseek-data)
set -euo pipefail
cd "$(dirname "$0")/.."
DATA=${1:-$HOME/.cache/meshseek-data}
OUT=bench/results
mkdir -p "$OUT"
./scripts/build.sh >/dev/null
{
  echo "machine: $(lscpu | sed -n 's/^Model name: *//p'), $(nproc) cores, $(free -g | awk '/Mem:/{print $2}') GiB"
  echo "date: $(date -u +%Y-%m-%d)"
  echo "command: build/bench/extract_benchmark --models_dir=$DATA/msb_articulated/models --max_models=50"
} > "$OUT/speed_extract.txt"
build/bench/extract_benchmark --models_dir="$DATA/msb_articulated/models" --max_models=50 \
  --benchmark_out="$OUT/speed_extract.json" --benchmark_out_format=json >/dev/null
"${PYTHON:-/usr/bin/python3}" - "$OUT/speed_extract.json" >> "$OUT/speed_extract.txt" <<'PY'
import json, sys
for b in json.load(open(sys.argv[1]))['benchmarks']:
    print('%-28s median %6.1f ms/model (CPU %6.1f)  p90 %6.1f ms  %5.0f features/model  (%d models, %.0f vertices on average)'
          % (b['name'].split('/iterations')[0], b['median_ms_per_model'], b['median_cpu_ms_per_model'],
             b['p90_ms_per_model'], b['features_per_model'], b['models'], b['mean_vertices']))
PY
cat "$OUT/speed_extract.txt"
{
  echo "machine: $(lscpu | sed -n 's/^Model name: *//p'), $(nproc) cores"
  echo "command: build/cli/meshseek eval --manifest $DATA/msb_articulated/manifest.csv --method dld --out out/msb --data_dir <fresh>"
  rm -rf out/speed-data
  /usr/bin/time -f "wall %e s, user %U s, peak RSS %M KiB" \
    build/cli/meshseek eval --manifest "$DATA/msb_articulated/manifest.csv" --method dld --out out/msb \
    --data_dir out/speed-data --progress=false 2>&1 | grep -v "^I "
} | tee "$OUT/speed_eval_msb.txt"
