#!/usr/bin/env bash
# Hashes what the CLI writes (JSON with timings removed, and the files it
# writes) over every model in ../shared/models and a few generated meshes, so
# that a change that must not alter outputs can be checked bit for bit:
#   scripts/output-hashes.sh target/release/mts > before.txt
#   ... change, rebuild ...
#   scripts/output-hashes.sh target/release/mts > after.txt; diff before.txt after.txt
# One line per (input, command): the sha256 of its output; a last line hashes
# them all. Meshes are read positions only (`--positions-only`, the flag of
# the commands since properties became the default); a binary from before
# that needs POSITIONS_ONLY= (empty) to compare with.
set -uo pipefail
mts=${1:-target/release/mts}
read -r -a pos <<< "${POSITIONS_ONLY---positions-only}"
models=${MODELS:-$(dirname "$0")/../../shared/models}
work=$(mktemp -d)
export WORK=$work
trap 'rm -rf "$work"' EXIT
# Timings differ from run to run: drop keys that hold them.
strip_times() {
  python3 -c '
import json, os, re, sys
t = re.compile(r"(^|_)(ms|us|s|ns)($|_)|time|elapsed|per_second|fps|seconds")
def f(v):
    if isinstance(v, dict):
        return {k: f(x) for k, x in v.items() if not t.search(k)}
    if isinstance(v, list):
        return [f(x) for x in v]
    return v
text = sys.stdin.read().replace(os.environ["WORK"], "WORK")
try:
    print(json.dumps(f(json.loads(text)), sort_keys=True))
except Exception as e:
    print("not json:", e)
'
}
run() { # name, then the command
  local name=$1; shift
  local out
  out=$("$@" 2>&1 | strip_times | sha256sum | cut -c1-16)
  echo "$name $out"
}
file_hash() { if [ -f "$2" ]; then echo "$1 $(sha256sum < "$2" | cut -c1-16)"; else echo "$1 missing"; fi; }
inputs=()
for m in "$models"/*.obj "$models"/*.ply; do [ -f "$m" ] && inputs+=("$m"); done
gens=(icosphere:20k torus:5k grid:2k)
for src in "${inputs[@]}" "${gens[@]}"; do
  if [ -f "$src" ]; then arg=("$src"); n=$(basename "$src"); else arg=(--generated "$src"); n=$src; fi
  run "$n strips" "$mts" strips "${arg[@]}" "${pos[@]}" --json --repeat 1
  run "$n simplify" "$mts" simplify "${arg[@]}" "${pos[@]}" --ratio 0.1 --samples 2000 --json -o "$work/s.obj"
  file_hash "$n simplify.obj" "$work/s.obj"
  run "$n build" "$mts" build "${arg[@]}" "${pos[@]}" -o "$work/m.mts" --json
  file_hash "$n build.mts" "$work/m.mts"
  run "$n extract" "$mts" extract "$work/m.mts" --ratio 0.1 --repeat 1 --json -o "$work/e.obj"
  file_hash "$n extract.obj" "$work/e.obj"
  run "$n verify" "$mts" verify "$work/m.mts" --lods 40 --json
  run "$n encode" "$mts" encode "${arg[@]}" "${pos[@]}" -o "$work/c.stream" --json
  file_hash "$n encode.stream" "$work/c.stream"
  rm -f "$work"/*
done | tee "$work/../hashes.$$"
echo "all $(sha256sum < "$work/../hashes.$$" | cut -c1-16)"
rm -f "$work/../hashes.$$"
