#!/usr/bin/env bash
# One command for a machine with a GPU (issue 24): builds release, then runs
# `mts bench render` on the bunny with the vertex-work measurements (the
# adapter's vertex-shader invocations, clipper and fragment counts and GPU
# time per method at 100/50/10/1%, beside the cache models) and the scene of
# 10,000 instances of the 8 scene models of `mts bench`, and writes one JSON
# file:
#   scripts/gpu-bench.sh [OUT]          (default target/gpu-bench.json)
# MODELS overrides the models folder (default ../shared/models). The adapter
# is wgpu's default; WGPU_ADAPTER_NAME / WGPU_BACKEND choose another.
# Budget: under 5 minutes after the build on a GPU.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
out=${1:-$root/target/gpu-bench.json}
models=${MODELS:-$root/../shared/models}
cd "$root"
cargo build --release --quiet
start=$(date +%s)
others=()
for m in armadillo.obj spot.obj cow.obj teapot.obj fandisk.obj homer.obj rocker_arm.obj; do
  [ -f "$models/$m" ] && others+=("$models/$m")
done
mkdir -p "$(dirname "$out")"
target/release/mts bench render "$models/bunny.ply" --scene 10000 \
  ${others:+--scene-with "${others[@]}"} --json > "$out.tmp"
mv "$out.tmp" "$out"
echo "wrote $out in $(( $(date +%s) - start )) s (after the build)" >&2
