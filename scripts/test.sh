#!/usr/bin/env bash
# Builds meshseek and runs the whole test suite (unit, integration, end to end).
set -euo pipefail
cd "$(dirname "$0")/.."
./scripts/build.sh
ctest --test-dir "${MESHSEEK_BUILD_DIR:-build}" --output-on-failure -j"$(nproc)"
