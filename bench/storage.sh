#!/usr/bin/env bash
# Bytes stored per model by the services: `meshseek eval` of a collection
# through the embedded services into a fresh data folder, then each state
# file's size and, in the coordinator's database, what its tables hold.
#   bench/storage.sh MANIFEST [METHOD]   (default method: bfdsift+rld+lsf+lfd)
# Prints a report; bench/results/storage.txt keeps the measured ones.
# Needs a Release build in ./build and python3 (for SQLite's figures).
set -euo pipefail
cd "$(dirname "$0")/.."
MANIFEST=${1:?usage: bench/storage.sh MANIFEST [METHOD]}
METHOD=${2:-bfdsift+rld+lsf+lfd}
WORK=$(mktemp -d)
trap 'rm -rf "$WORK"' EXIT
echo "# bench/storage.sh $MANIFEST $METHOD: $(date -u '+%F %H:%M UTC'), $(nproc) cores: $(lscpu | sed -n 's/^Model name: *//p')"
echo "# build/cli/meshseek eval --manifest $MANIFEST --method $METHOD --data_dir <fresh> --out <dir>"
/usr/bin/time -f "# eval: wall %e s, peak RSS %M KiB" \
  build/cli/meshseek eval --progress=false --manifest "$MANIFEST" --method "$METHOD" \
  --data_dir "$WORK/data" --out "$WORK/eval" 2>&1 | grep -E "^# eval|first tier|micro|time " || true
# Let SQLite fold its write-ahead logs into the files before they are measured.
python3 - "$WORK/data" <<'EOF'
import os, sqlite3, sys
data = sys.argv[1]
def size(path):
    return sum(os.path.getsize(os.path.join(d, f)) for d, _, fs in os.walk(path) for f in fs)
for service in ("coordinator", "index", "codebook"):
    for d, _, fs in os.walk(os.path.join(data, service)):
        for f in fs:
            if f.endswith(".db"):
                con = sqlite3.connect(os.path.join(d, f))
                con.execute("PRAGMA wal_checkpoint(TRUNCATE)")
                con.close()
db = sqlite3.connect(os.path.join(data, "coordinator", "coordinator.db"))
models = db.execute("SELECT COUNT(DISTINCT model_id) FROM models").fetchone()[0]
mesh = db.execute("SELECT COALESCE(SUM(length(mesh)), 0) FROM models").fetchone()[0]
features = db.execute("SELECT COALESCE(SUM(length(features)), 0) FROM models").fetchone()[0]
thumbs = db.execute("SELECT COALESCE(SUM(length(png)), 0) FROM thumbnails").fetchone()[0]
ranking = db.execute("SELECT COALESCE(SUM(length(state)), 0) FROM rankings").fetchone()[0]
files = {s: size(os.path.join(data, s)) for s in ("coordinator", "index", "codebook")}
total = sum(files.values())
print(f"models {models}")
for s, b in files.items():
    print(f"{s:12s} {b:>14,d} bytes on disk")
print(f"{'total':12s} {total:>14,d} bytes on disk")
print(f"coordinator.db holds: meshes {mesh:,d}, features {features:,d}, thumbnails {thumbs:,d}, ranking state {ranking:,d}")
per_model = files["coordinator"] + files["index"] - mesh
print(f"per model beyond its mesh (coordinator + index): {per_model / models:,.0f} bytes "
      f"(its mesh: {mesh / models:,.0f}); the collection's codebooks: {files['codebook']:,d} in all")
EOF
