#!/usr/bin/env bash
# The main job on the embedded default: builds meshseek, writes the built-in
# synthetic benchmark and evaluates DLD-SIFT retrieval on it with
# `meshseek eval`, printing the metrics table. Outputs go to ./out/.
set -euo pipefail
cd "$(dirname "$0")/.."
./scripts/build.sh
BIN=${MESHSEEK_BUILD_DIR:-build}/cli/meshseek
"$BIN" synth --out out/synthetic
# Through the embedded stack: every service on loopback ports, state in out/meshseek-data.
"$BIN" eval --manifest out/synthetic/manifest.csv --method dld --out out/synthetic-eval \
  --data_dir out/meshseek-data
