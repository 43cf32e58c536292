#!/usr/bin/env bash
# Builds meshseek-base:bookworm, a minimal Debian 12 image made with
# debootstrap from Debian's package archive, for machines that cannot pull
# from a container registry. The Dockerfile takes it with
#   --build-arg BASE=meshseek-base:bookworm
# Idempotent: does nothing when the image exists. Needs root (debootstrap).
set -euo pipefail
IMAGE=${1:-meshseek-base:bookworm}
MIRROR=${DEBIAN_MIRROR:-http://deb.debian.org/debian}
if docker image inspect "$IMAGE" >/dev/null 2>&1; then
  echo "make-base-image: $IMAGE exists"
  exit 0
fi
command -v debootstrap >/dev/null || { apt-get update -qq && apt-get install -y -qq debootstrap; }
ROOT=$(mktemp -d)
trap 'rm -rf "$ROOT"' EXIT
debootstrap --variant=minbase bookworm "$ROOT" "$MIRROR"
# The same archives as the official debian:12 image: updates and security too.
cat > "$ROOT/etc/apt/sources.list" <<SOURCES
deb $MIRROR bookworm main
deb $MIRROR bookworm-updates main
deb ${MIRROR%/debian}/debian-security bookworm-security main
SOURCES
chroot "$ROOT" apt-get clean
rm -rf "$ROOT"/var/lib/apt/lists/*
tar -C "$ROOT" -c . | docker import --change 'CMD ["/bin/bash"]' - "$IMAGE"
echo "make-base-image: built $IMAGE"
