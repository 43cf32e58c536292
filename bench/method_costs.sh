#!/usr/bin/env bash
# What each method gives and costs, side by side (docs/results.md, "What each method costs"):
# for every method and the default fusion, bench/storage.sh's eval through the embedded services
# into a fresh data folder (first tier, eval wall time, bytes a model), one after the other.
#   bench/method_costs.sh MANIFEST [METHOD ...]   (default: dld rld ld bfdsift lsf lfd and the fusion)
# Needs a Release build in ./build. Extraction per model is bench/extract_ab.sh's
# (bench/results/speed_extract_fused.txt), not measured here.
set -euo pipefail
cd "$(dirname "$0")/.."
MANIFEST=${1:?usage: bench/method_costs.sh MANIFEST [METHOD ...]}
shift
METHODS=("$@")
[ ${#METHODS[@]} -gt 0 ] || METHODS=(dld rld ld bfdsift lsf lfd bfdsift+rld+lsf+lfd)
echo "# bench/method_costs.sh $MANIFEST: $(date -u '+%F %H:%M UTC'), $(nproc) cores: $(lscpu | sed -n 's/^Model name: *//p')"
printf '%-22s %8s %10s %14s %16s\n' method "FT %" "eval s" "index B/model" "coord. B/model"
for m in "${METHODS[@]}"; do
  report=$(timeout 1800 bench/storage.sh "$MANIFEST" "$m")
  ft=$(sed -n 's/^R-precision (query excluded = first tier): \([0-9.]*\) % micro.*/\1/p' <<<"$report")
  wall=$(sed -n 's/^# eval: wall \([0-9.]*\) s.*/\1/p' <<<"$report")
  models=$(sed -n 's/^models \([0-9]*\)$/\1/p' <<<"$report")
  index=$(sed -n 's/^index *\([0-9,]*\) bytes on disk/\1/p' <<<"$report" | tr -d ,)
  coord=$(sed -n 's/^coordinator *\([0-9,]*\) bytes on disk/\1/p' <<<"$report" | tr -d ,)
  mesh=$(sed -n 's/.*holds: meshes \([0-9,]*\),.*/\1/p' <<<"$report" | tr -d ,)
  printf '%-22s %8s %10s %14d %16d\n' "$m" "$ft" "$wall" $((index / models)) $(((coord - mesh) / models))
done
