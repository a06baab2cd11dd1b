#!/usr/bin/env bash
# The streamed .mts file on every shared model (docs/experiments/compressed-file.md):
# the file against the raw mesh, the share of it that opens and draws 10% of the
# triangles, and the time to open that prefix and to load the whole file.
#   scripts/prefix-table.sh [target/release/mts] > table.tsv
set -uo pipefail
mts=${1:-target/release/mts}
models=${MODELS:-$(dirname "$0")/../../shared/models}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
printf 'model\ttriangles\tfile_bytes\tfile_over_raw\tprefix_share_10\tprefix_triangles\topen_prefix_ms\tload_whole_ms\n'
for f in "$models"/*.ply "$models"/*.obj; do
  [ -f "$f" ] || continue
  n=$(basename "$f")
  "$mts" build "$f" -o "$work/m.mts" --json > "$work/b.json" 2>/dev/null || { echo "$n: build failed" >&2; continue; }
  end=$(python3 -c "import json,sys; d=json.load(open(sys.argv[1])); c=[x for x in d['prefixes'] if x['triangles']<=round(d['triangles']*0.1)]; print(c[-1]['bytes'] if c else d['bytes'])" "$work/b.json")
  "$mts" extract "$work/m.mts" --bytes "$end" --ratio 0.1 --json --repeat 1 > "$work/p.json" 2>/dev/null
  "$mts" extract "$work/m.mts" --ratio 0.1 --json --repeat 1 > "$work/w.json" 2>/dev/null
  python3 - "$n" "$work" <<'PY'
import json, sys
w = sys.argv[2]
d, e, x = (json.load(open("%s/%s.json" % (w, k))) for k in "bpw")
print("%s\t%d\t%d\t%.3f\t%.2f%%\t%d\t%.1f\t%.1f" % (sys.argv[1], d["triangles"], d["bytes"], d["bytes"] / d["raw_bytes"],
      100 * e["bytes_used"] / d["bytes"], e["triangles"], e["load_ms"], x["load_ms"]))
PY
done
