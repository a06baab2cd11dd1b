#!/bin/bash
# Regenerates the README's simplification table: `mts simplify --json` at
# 10% and 1% on every model in ../shared/models (meshoptimizer side by side,
# compared at the same triangle count).
set -euo pipefail
cd "$(dirname "$0")/.."
cargo build --release --quiet
echo "| mesh | ratio | triangles (mts / meshopt) | Hausdorff (mts / meshopt) | ratio | RMS (mts / meshopt) | ms whole sequence (mts) / to target (meshopt) |"
echo "|---|---|---|---|---|---|---|"
for m in ../shared/models/*.ply ../shared/models/*.obj; do
  for r in 0.1 0.01; do
    ./target/release/mts simplify "$m" --ratio "$r" --json | python3 -c '
import json, sys
v = json.load(sys.stdin); p = v["meshopt"]
h = v["hausdorff"] / p["hausdorff"] if p["hausdorff"] > 0 else (1.0 if v["hausdorff"] == 0 else float("inf"))
print("| %s | %s | %d / %d | %.5f / %.5f | %.2f | %.5f / %.5f | %.0f / %.0f |" % (
    v["mesh"].split("/")[-1], sys.argv[1], v["triangles"], p["triangles"],
    v["hausdorff"], p["hausdorff"], h, v["rms"], p["rms"], v["ms"], p["ms"]))' "$r"
  done
done
