#!/usr/bin/env python3
"""Simplify meshes with the fast-simplification package and measure the
result with `mts distance`, so its error sits beside mts and meshoptimizer.

Needs `pip install fast-simplification numpy` and a built `mts`
(`cargo build --release`). For each mesh and ratio it prints one JSON line:
mesh, ratio, input_triangles, triangles, ms (fast-simplification's own time,
median of --repeat runs), hausdorff and rms (relative to the input's
bounding-box diagonal, measured by `mts distance` exactly as `mts simplify`
measures itself).

    python3 crates/mts-cli/peers/fast_simplification.py ../shared/models/bunny.ply
    python3 crates/mts-cli/peers/fast_simplification.py --ratios 0.1,0.01 MESH...
"""

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time


def read_obj(path):
    """Vertices and triangles of a simple OBJ (as written by `mts convert`)."""
    vertices, faces = [], []
    with open(path, encoding="utf-8") as f:
        for line in f:
            if line.startswith("v "):
                vertices.append([float(x) for x in line.split()[1:4]])
            elif line.startswith("f "):
                faces.append([int(x.split("/")[0]) - 1 for x in line.split()[1:4]])
    return vertices, faces


def write_obj(path, vertices, faces):
    with open(path, "w", encoding="utf-8") as f:
        for v in vertices:
            f.write("v %r %r %r\n" % (float(v[0]), float(v[1]), float(v[2])))
        for t in faces:
            f.write("f %d %d %d\n" % (t[0] + 1, t[1] + 1, t[2] + 1))


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("meshes", nargs="+", help="OBJ or PLY files")
    parser.add_argument("--ratios", default="0.1,0.01")
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--mts", default="target/release/mts", help="path to the mts binary")
    args = parser.parse_args()
    # This file shares the package's name: import the package, not itself.
    here = os.path.dirname(os.path.abspath(__file__))
    sys.path[:] = [p for p in sys.path if os.path.abspath(p or ".") != here]
    try:
        import fast_simplification
        import numpy as np
    except ImportError as e:
        sys.exit("needs `pip install fast-simplification numpy`: %s" % e)
    if not os.path.exists(args.mts):
        sys.exit("no mts binary at %s: run `cargo build --release` first" % args.mts)

    with tempfile.TemporaryDirectory() as tmp:
        for mesh in args.meshes:
            # The same cleaned mesh mts works on (degenerate and unreferenced
            # vertices dropped), so the inputs match exactly.
            clean = os.path.join(tmp, "input.obj")
            subprocess.run([args.mts, "convert", mesh, "-o", clean], check=True)
            vertices, faces = read_obj(clean)
            points = np.asarray(vertices, dtype=np.float32)
            tris = np.asarray(faces, dtype=np.int64)
            for ratio in (float(r) for r in args.ratios.split(",")):
                times = []
                for _ in range(max(1, args.repeat)):
                    start = time.perf_counter()
                    out_points, out_faces = fast_simplification.simplify(
                        points, tris, target_reduction=1.0 - ratio
                    )
                    times.append((time.perf_counter() - start) * 1e3)
                result = os.path.join(tmp, "result.obj")
                write_obj(result, out_points, out_faces)
                measured = subprocess.run(
                    [args.mts, "distance", clean, result, "--json"],
                    check=True,
                    capture_output=True,
                    text=True,
                )
                d = json.loads(measured.stdout)
                print(
                    json.dumps(
                        {
                            "mesh": mesh,
                            "ratio": ratio,
                            "input_triangles": len(faces),
                            "triangles": int(len(out_faces)),
                            "ms": statistics.median(times),
                            "hausdorff": d["hausdorff"],
                            "rms": d["rms"],
                        }
                    ),
                    flush=True,
                )


if __name__ == "__main__":
    main()
