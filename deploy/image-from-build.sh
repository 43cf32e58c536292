#!/usr/bin/env bash
# Builds the meshseek image from binaries already compiled on this Debian 12
# machine (scripts/build.sh), in about a minute instead of compiling
# everything again inside Docker: the runtime stage of deploy/Dockerfile, the
# same recipe line for line, fed from a context holding only the stripped
# binaries and the list of packages they load. What CI's deploy test runs
# (tests/deploy_test.sh); deploy/Dockerfile stays the way to build from source.
#   deploy/image-from-build.sh TAG [BASE]     (BASE default meshseek-base:bookworm)
set -euo pipefail
cd "$(dirname "$0")/.."
TAG=${1:?usage: deploy/image-from-build.sh TAG [BASE]}
BASE=${2:-meshseek-base:bookworm}
BUILD_DIR=${MESHSEEK_BUILD_DIR:-build}
CONTEXT=$(mktemp -d)
trap 'rm -rf "$CONTEXT"' EXIT
mkdir -p "$CONTEXT/out/bin"
for b in services/meshseek-resample services/meshseek-extract services/meshseek-codebook \
         services/meshseek-index services/meshseek-coordinator services/meshseek-probe cli/meshseek; do
  [ -x "$BUILD_DIR/$b" ] || { echo "image-from-build: $BUILD_DIR/$b is not built (scripts/build.sh)" >&2; exit 1; }
  strip -o "$CONTEXT/out/bin/$(basename "$b")" "$BUILD_DIR/$b"
done
deploy/runtime-packages.sh "$CONTEXT"/out/bin/* > "$CONTEXT/out/runtime-packages"
{
  echo 'ARG BASE=debian:12'
  sed -n '/^FROM \${BASE} AS runtime/,$p' deploy/Dockerfile | sed 's#COPY --from=build /out/#COPY out/#'
} > "$CONTEXT/Dockerfile"
grep -q '^COPY out/bin/' "$CONTEXT/Dockerfile" && ! grep -q -- '--from=' "$CONTEXT/Dockerfile" \
  || { echo "image-from-build: deploy/Dockerfile's runtime stage no longer has the COPY lines this reads" >&2; exit 1; }
docker build -q --build-arg BASE="$BASE" -t "$TAG" "$CONTEXT" >/dev/null
echo "image-from-build: built $TAG from $BUILD_DIR on $BASE"
