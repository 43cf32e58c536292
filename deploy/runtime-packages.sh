#!/usr/bin/env bash
# Prints the Debian packages of every shared library the given binaries load
# directly (apt installs what those need in turn), one a line. The image's
# runtime stage installs exactly these, whether the binaries were compiled in
# the build stage (deploy/Dockerfile) or on this machine
# (deploy/image-from-build.sh).
#   deploy/runtime-packages.sh BINARY...
# No pipefail: `dpkg -S | head -1` may end dpkg early by SIGPIPE, which is no error.
set -eu
for b in "$@"; do readelf -d "$b"; done \
  | sed -n 's/.*Shared library: \[\(.*\)\]/\1/p' | sort -u \
  | while read -r lib; do dpkg -S "*/$lib" | head -1 | cut -d: -f1; done \
  | sort -u
