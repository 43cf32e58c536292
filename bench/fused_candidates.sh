#!/usr/bin/env bash
# Recall of fused candidates on a labelled set: an in-process eval of the
# default fusion (which writes each method's matrix beside the fused one),
# then bench/fused_candidates on those matrices (see its header).
#   bench/fused_candidates.sh MANIFEST [CANDIDATES]   (default 10,25,50,100,200)
# Keeps the eval in $OUT (default: a temporary folder, removed).
# Needs a Release build in ./build; bench/results/fused_candidates.txt keeps the measured ones.
set -euo pipefail
cd "$(dirname "$0")/.."
MANIFEST=${1:?usage: bench/fused_candidates.sh MANIFEST [CANDIDATES]}
CANDIDATES=${2:-10,25,50,100,200}
METHOD=bfdsift+rld+lsf+lfd
if [ -z "${OUT:-}" ]; then
  OUT=$(mktemp -d)
  trap 'rm -rf "$OUT"' EXIT
fi
echo "# bench/fused_candidates.sh $MANIFEST $CANDIDATES: $(date -u '+%F %H:%M UTC'), $(nproc) cores: $(lscpu | sed -n 's/^Model name: *//p')"
mkdir -p "$OUT"
if [ ! -f "$OUT/eval/distances.lfd.bin" ]; then
  echo "# build/cli/meshseek eval --manifest $MANIFEST --method $METHOD --server in-process --out \$OUT/eval"
  build/cli/meshseek eval --progress=false --manifest "$MANIFEST" --method "$METHOD" \
    --server in-process --out "$OUT/eval" > "$OUT/eval.log" 2>&1 || { cat "$OUT/eval.log"; exit 1; }
  grep -E "first tier|micro" "$OUT/eval.log" || true
fi
echo "# build/bench/fused_candidates --manifest $MANIFEST --eval \$OUT/eval --method $METHOD --candidates $CANDIDATES"
build/bench/fused_candidates --manifest "$MANIFEST" --eval "$OUT/eval" --method "$METHOD" \
  --candidates "$CANDIDATES"
