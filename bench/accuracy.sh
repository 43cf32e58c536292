#!/usr/bin/env bash
# Accuracy of the shipped defaults on the development sets: `meshseek eval`
# of every method on McGill articulated and PSB train through the embedded
# services (fresh data folder each), each matrix cross-checked with the
# independent evaluator ../shared/tools/psb_eval.py.
#   bench/accuracy.sh [DATA_DIR] [METHODS]   (defaults: ~/.cache/meshseek-data, "dld rld ld bfdsift lsf lfd bfdsift+rld+lsf+lfd")
# Writes bench/results/accuracy.txt. Needs a Release build in ./build.
set -euo pipefail
cd "$(dirname "$0")/.."
DATA=${1:-$HOME/.cache/meshseek-data}
METHODS=${2:-dld rld ld bfdsift lsf lfd bfdsift+rld+lsf+lfd}
OUT=$(mktemp -d)
trap 'rm -rf "$OUT"' EXIT
RESULT=bench/results/accuracy.txt
{
  echo "# bench/accuracy.sh $(date -u '+%F %H:%M UTC'), $(nproc) cores: $(lscpu | sed -n 's/^Model name: *//p')"
  echo "# build/cli/meshseek eval --manifest $DATA/<set>/manifest.csv --method <m> --out <dir> --data_dir <fresh>"
  echo "# cross-check: python3 ../shared/tools/psb_eval.py <manifest> <dir>/distances.bin"
} > "$RESULT"
for set in msb_articulated psb_train; do
  manifest=$DATA/$set/manifest.csv
  for m in $METHODS; do
    dir=$OUT/$set-$m
    {
      echo
      echo "== $set, $m"
      /usr/bin/time -f "wall %e s, user %U s, peak RSS %M KiB" \
        build/cli/meshseek eval --progress=false --manifest "$manifest" --method "$m" \
        --out "$dir" --data_dir "$OUT/data-$set-$m" 2>&1 | grep -v "^I " | grep -E "micro|macro|NN|time|wall"
      python3 ../shared/tools/psb_eval.py "$manifest" "$dir/distances.bin" 2>&1 | sed 's/^/psb_eval: /' | head -4
    } | tee -a "$RESULT"
    rm -rf "$OUT/data-$set-$m"
  done
done
