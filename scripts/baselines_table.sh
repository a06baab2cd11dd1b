#!/bin/bash
# Regenerates the README's per-model baseline table: `mts compare --json` on
# every model in ../shared/models, each method's file bytes against the raw
# mesh (12 bytes per vertex + 6 per triangle) and the multilevel mesh's
# memory ratio (its structure is its file). Requests kept few: the build
# dominates.
set -euo pipefail
cd "$(dirname "$0")/.."
cargo build --release --quiet
echo "| mesh | raw bytes | mts | pm | multilevel (memory) | cluster | discrete |"
echo "|---|---|---|---|---|---|---|"
for m in ../shared/models/*.ply ../shared/models/*.obj; do
  ./target/release/mts compare "$m" --requests 10 --json | python3 -c '
import json, sys
v = json.load(sys.stdin)
r = {x["method"]: x["file_ratio_to_raw_u16"] for x in v["methods"]}
print("| %s | %d | %.3f | %.3f | %.3f | %.3f | %.3f |" % (v["mesh"]["input"].split("/")[-1],
    v["mesh"]["raw_bytes_u16"], r["mts"], r["pm"], r["multilevel"], r["cluster"], r["discrete"]))'
done
