#!/usr/bin/env python3
"""The glTF tables of issue 35, for every mesh in ../shared/models.

Table 1, size and read time: each model as `mts convert` writes it plain,
--quantize and --compress, beside gltfpack's -c and -cc output of the
plain file (gltfpack's default quantization bits), and -cc -kv (gltfpack
drops texture coordinates no material samples unless -kv; mts keeps every
attribute), with the median time `examples/gltf_read` takes to read each
from bytes in memory.

Table 2, what gltfpack's outputs (default, -c, -cc, -si 0.1) give when
mts reads and builds them: the triangle count gltfpack reports, the count
mts reads, and whether `mts build` succeeds.

    cargo build --release -p mts-cli
    cargo build --release -p mts --features gltf --example gltf_read
    npm install -g gltfpack
    python3 scripts/gltf-table.py [--models DIR] [--out DIR] [--no-build]

Prints two Markdown tables; the files are left in --out (default
target/gltf-table).
"""
import argparse
import json
import os
import re
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
MTS = os.path.join(ROOT, "target/release/mts")
READ = os.path.join(ROOT, "target/release/examples/gltf_read")


def run(cmd, timeout=600):
    p = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout)
    return p.returncode, p.stdout, p.stderr


def gltfpack(src, dst, flags):
    rc, out, err = run(["gltfpack", "-i", src, "-o", dst, "-v"] + flags)
    m = re.search(r"output: \d+ mesh primitives \((\d+) triangles", out + err)
    return rc, int(m.group(1)) if m else None


def read(files):
    rc, out, err = run([READ, "--runs", "11"] + files)
    if rc != 0:
        sys.exit(f"gltf_read failed: {err}")
    return {json.loads(line)["file"]: json.loads(line) for line in out.splitlines()}


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--models", default=os.path.join(ROOT, "../shared/models"))
    ap.add_argument("--out", default=os.path.join(ROOT, "target/gltf-table"))
    ap.add_argument("--no-build", action="store_true")
    args = ap.parse_args()
    os.makedirs(args.out, exist_ok=True)
    models = sorted(f for f in os.listdir(args.models) if f.endswith((".obj", ".ply")))
    sizes, builds = [], []
    for model in models:
        stem = os.path.splitext(model)[0]
        src = os.path.join(args.models, model)
        out = lambda tag: os.path.join(args.out, f"{stem}.{tag}.glb")
        for tag, flags in [("plain", []), ("quantized", ["--quantize"]), ("compressed", ["--compress"])]:
            rc, _, err = run([MTS, "convert", src, "-o", out(tag)] + flags)
            if rc != 0:
                sys.exit(f"mts convert {model} {flags}: {err}")
        packed = {}
        for tag, flags in [("gp-default", []), ("gp-c", ["-c"]), ("gp-cc", ["-cc"]),
                           ("gp-cc-kv", ["-cc", "-kv"]), ("gp-si0.1", ["-si", "0.1"])]:
            rc, tris = gltfpack(out("plain"), out(tag), flags)
            packed[tag] = (rc, tris)
        tags = ["plain", "quantized", "compressed", "gp-c", "gp-cc", "gp-cc-kv"]
        r = read([out(t) for t in tags])
        row = {t: r[out(t)] for t in tags}
        sizes.append((stem, row))
        for tag, (rc, tris) in packed.items():
            got = read([out(tag)])[out(tag)] if rc == 0 else None
            built = None
            if got and not args.no_build:
                brc, bout, berr = run([MTS, "build", out(tag), "-o", out(tag) + ".mts", "--json"])
                built = json.loads(bout)["triangles"] if brc == 0 else "error: " + berr.strip().splitlines()[-1]
            if tag != "gp-cc-kv":
                builds.append((stem, tag, tris, got["triangles"] if got else None, built))
        print(f"{stem}: done", file=sys.stderr)

    print("| model | triangles | plain | quantized | compressed (mts) | gltfpack -c | gltfpack -cc | -cc -kv | mts / -cc | mts / -cc -kv | read ms: plain, quantized, compressed, -cc |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    ratios, kept = [], []
    for stem, row in sizes:
        ratio = row["compressed"]["bytes"] / row["gp-cc"]["bytes"]
        ratio_kv = row["compressed"]["bytes"] / row["gp-cc-kv"]["bytes"]
        ratios.append(ratio)
        kept.append(ratio_kv)
        ms = ", ".join(f"{row[t]['read_ms']:.2f}" for t in ["plain", "quantized", "compressed", "gp-cc"])
        print(f"| {stem} | {row['plain']['triangles']:,} | {row['plain']['bytes']:,} | {row['quantized']['bytes']:,} | "
              f"{row['compressed']['bytes']:,} | {row['gp-c']['bytes']:,} | {row['gp-cc']['bytes']:,} | "
              f"{row['gp-cc-kv']['bytes']:,} | {ratio:.3f} | {ratio_kv:.3f} | {ms} |")
    for name, r in [("-cc", ratios), ("-cc -kv (every attribute kept, as mts does)", kept)]:
        r.sort()
        print(f"\nmts --compress / gltfpack {name}: median {r[len(r) // 2]:.3f}, worst {r[-1]:.3f}")
    print()
    print("| model | gltfpack output | gltfpack's triangles | mts reads | mts build |")
    print("|---|---|---|---|---|")
    for stem, tag, tris, got, built in builds:
        ok = "" if tris == got else " **differs**"
        print(f"| {stem} | {tag} | {tris:,} | {got if got is None else format(got, ',')}{ok} | {built} |")


if __name__ == "__main__":
    main()
