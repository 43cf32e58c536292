#!/usr/bin/env bash
# Builds meshseek and runs the whole test suite (unit, integration, end to end),
# every GoogleTest case as its own CTest test, then prints the slowest tests
# against their timeouts (scripts/test_times.py).
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD_DIR=${MESHSEEK_BUILD_DIR:-build}
./scripts/build.sh
rc=0
ctest --test-dir "$BUILD_DIR" --output-on-failure -j"$(nproc)" \
  --output-junit "$PWD/$BUILD_DIR/junit.xml" || rc=$?
python3 scripts/test_times.py "$BUILD_DIR" "$BUILD_DIR/junit.xml" || true
exit "$rc"
