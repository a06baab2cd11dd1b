#!/usr/bin/env bash
# Prints the README's strip table: `mts strips --json` on every model in
# ../shared/models and on generated meshes, as Markdown.
set -euo pipefail
cd "$(dirname "$0")/.."
cargo build --release -q
bin=target/release/mts
row() {
  "$bin" strips "$@" --json --repeat "${REPEAT:-5}" | python3 -c '
import json, sys
d = json.load(sys.stdin); m = d["meshopt"]
name = d["mesh"].split("/")[-1]
cols = [name, str(d["triangles"]),
        "%d / %d" % (d["strips"], m["strips"]),
        "%d / %d" % (d["swaps"], m["swaps"]),
        "**%.4f** / %.4f" % (d["indices_per_triangle"], m["indices_per_triangle"]),
        "%.3f / %.3f" % (d["acmr"], m["acmr"]),
        "%.1f / %.1f" % (d["ms"], m["ms"])]
print("| " + " | ".join(cols) + " |")'
}
echo "| mesh | triangles | strips (mts / meshopt) | swaps | indices per triangle | ACMR | ms |"
echo "|---|---|---|---|---|---|---|"
for f in ../shared/models/*.obj ../shared/models/*.ply; do [ -e "$f" ] && row "$f"; done
for g in icosphere:100k icosphere:300k icosphere:1M torus:1M; do row --generated "$g"; done
