#!/usr/bin/env python3
"""Hostile-input harness for the `mts` command line (issue 19).

Feeds the CLI inputs built to break it and classifies every run. Python 3
standard library only; everything it reads is generated in a temporary
directory, starting from seeds that `mts` itself writes.

Commands
--------
CI slice (fixed seed 19, 600 inputs, about 1,700 runs, timeout 10 s; no
heavy extreme mesh, no argument that is slow even when handled right, one
render run; well under 2 minutes on 2 cores with a sound binary)::

    python3 scripts/hostile.py --mts target/release/mts --quick

Full run (default: seed 1, 2,700 inputs, about 7,600 runs, --jobs 2; under
2 minutes on 2 cores with a sound binary, each hang adds up to --timeout)::

    python3 scripts/hostile.py --mts target/release/mts --json hostile.json --keep hostile-cases

Other options: --seed N, --count N (inputs), --timeout S (20), --mem-gb G (4),
--families obj,ply,mts,stream,args,extreme, --jobs N (2), --list-limit N.
The same seed, count and --families give the same inputs whatever --jobs
says (each input is drawn from its own generator, seeded by seed and index).

Families
--------
obj      hand-written OBJ seeds (triangles, quads, v/vt/vn corners, relative
         indices, groups) with mutations: truncation at a random point,
         random byte flips, face/vt/vn indices out of range, 0 or huge
         indices, NaN/inf/1e39/words as coordinates, junk statements, no
         faces at all, tokens swapped, the file repeated.
ply      hand-written PLY seeds: ascii, binary_little_endian and
         binary_big_endian, float/double/short coordinates, uchar/int/uint
         list counts, extra properties and elements to skip, a `tristrips`
         element. Mutations: truncation, byte flips, element counts raised
         (to 2^32-1 and 10^18 too) or lowered, unknown types, float list
         counts, a last face with list count 255, indices out of range,
         NaN/inf coordinates, bad `format` lines, no `end_header`.
mts      .mts models written by `mts build` (torus, optimal-placement
         icosphere, single-band grid, a hand-written cube). Mutations:
         truncation, byte flips (the header's FNV-1a/64 catches them all),
         byte flips in the body with the checksum resealed, and structured
         edits, resealed, that the loader must refuse: META counts +-1 or
         huge, band slack NaN/-1/-inf, flags 2..255, infinite swap penalty,
         NaN/inf positions, strip indices out of range, short runs, steps
         naming absent vertices / contracting a vertex onto itself / reusing
         a removed vertex / NaN or decreasing errors, bad tags, section
         lengths, trailing bytes, version and section count.
stream   cluster-tree packet streams written by `mts encode`, decoded whole
         (`mts decode F`) and by prefix (`mts decode F --bytes N`).
         Mutations: truncation, byte flips, body flips with the FNV-1a/32
         resealed, structured edits resealed (header counts +-1, 2^32-1,
         roots > vertices, base > triangles, a NaN root coordinate, a
         trailing byte), a bad magic.
args     absurd arguments: huge, negative, zero, NaN, inf and empty values
         for --repeat, --samples, --lods, --requests, --scene, --frames,
         --size, --ratio, --triangles, --band-slack, --bytes,
         --swap-penalty, --pair-distance, --boundary-weight, --min-patch,
         --lod; generated sizes such as icosphere:1e9, grid:1073741824,
         torus:0, torus:NaN, cube:10.
extreme  valid but extreme meshes, and files that are not meshes at all:
         coordinates of 1e20, 3e38 and denormals, 1e-25 edges, one polygon
         of 100k corners, a million coincident `f 1 2 3`, a non-manifold
         fan of 2,000 triangles on one edge, degenerate and collinear
         triangles, duplicated vertices (with --weld too), `l` and `p`
         statements, vt/vn out of range, CR-only line endings, UTF-16
         text, binary garbage, zero-filled files, /dev/zero, /dev/null, a
         directory, an empty file, a 10 MB comment line, 100k `o`
         statements.

Checksums (read from src/model/format.rs and src/baselines/cluster/stream.rs):
.mts: header "MTSMODEL" | version u32 | section count u32 | file length u64
| FNV-1a/64 (offset basis 0xcbf29ce484222325, prime 0x100000001b3) of every
byte after the 32-byte header (version 3: its four-lane word form,
checksum::fnv1a64_words), stored at bytes 24..32. Stream: "MTSCT\\0\\0\\x01"
| vertices, triangles, roots, base triangles (u32 LE each) | FNV-1a/32
(0x811c9dc5, 0x01000193) of the body after the 28-byte header at bytes
24..28. Resealing rewrites the length (.mts) and the checksum. Note that
`mts decode --bytes N` with N below the file length decodes a prefix and
does not check the checksum (it covers the whole body); N at or past the
end decodes the whole file strictly, checksum included.

Classification of a run
-----------------------
hang              the time limit (--timeout) was reached; the whole process
                  group is killed.
oom               "memory allocation of", "capacity overflow", "out of
                  memory", "Cannot allocate memory" in stderr, or killed by
                  SIGKILL (the address-space cap, RLIMIT_AS = --mem-gb).
panic             "panicked at" / "has overflowed its stack" in stderr, or
                  death by any other signal (SIGABRT, SIGSEGV, ...).
garbage accepted  exit 0 on an input the CLI must refuse (truncated .mts,
                  unresealed flips, out-of-range indices, NaN arguments...).
ok                exit 0 on a valid or possibly valid input.
unnamed error     non-zero exit, no panic, but stderr does not name the
                  input file under test (only checked for file inputs).
clean error       non-zero exit, no panic, the input file named.
For file errors (clean or unnamed) the harness also records whether the
message names a place: "line N", "byte N", "offset N", "column N", or an
element and index ("vertex 3", "face 12", "step 4", "strip index 7", ...).

Runs use a copy of the binary taken at the start (its sha1 is reported),
have stdin on /dev/null, stdout discarded, RUST_BACKTRACE=0, their own
process group and working directory. Exit status: 0 when no run is a panic,
hang, oom or garbage accepted; 1 otherwise; 2 when the harness cannot run
(binary missing, seeds cannot be made).
"""

import argparse
import collections
import hashlib
import json
import math
import os
import random
import re
import resource
import shutil
import signal
import struct
import subprocess
import sys
import tempfile
import threading
import time
from concurrent.futures import ThreadPoolExecutor

FAMILIES = ["obj", "ply", "mts", "stream", "args", "extreme"]
# Share of the inputs per family.
WEIGHTS = {"obj": 26, "ply": 25, "mts": 19, "stream": 15, "extreme": 9, "args": 6}
DEFAULT_COUNT = 2700
QUICK_COUNT = 600
QUICK_SEED = 19
QUICK_TIMEOUT = 10

GARBAGE, VALID, UNKNOWN = "garbage", "valid", "unknown"
CLASSES = ["clean error", "ok", "panic", "hang", "oom", "garbage accepted", "unnamed error"]
FAILING = ("panic", "hang", "oom", "garbage accepted")

PLACE_RE = re.compile(
    r"\b(line|byte|offset|column|col|position|pos|vertex|face|triangle|"
    r"tristrips|element|index|step|run|packet|root|strip index|statement|"
    r"section \w+)\s+#?\d+",
    re.IGNORECASE,
)

# --------------------------------------------------------------------------
# Checksums and binary helpers


def fnv1a64(data):
    h = 0xCBF29CE484222325
    for b in data:
        h ^= b
        h = (h * 0x100000001B3) & 0xFFFFFFFFFFFFFFFF
    return h


def fnv1a64_words(data):
    """.mts version 3: FNV-1a's step over little-endian 64-bit words in four
    lanes (word i to lane i mod 4), lanes folded with the same step, the
    tail bytes after them with FNV-1a (checksum::fnv1a64_words)."""
    m = 0xFFFFFFFFFFFFFFFF
    p = 0x100000001B3
    lanes = [0xCBF29CE484222325, 0x84222325CBF29CE4, 0x9CE484222325CBF2, 0x2325CBF29CE48422]
    n = len(data) // 32 * 32
    words = struct.unpack_from("<%dQ" % (n // 8), data, 0) if n else ()
    for i, w in enumerate(words):
        lanes[i & 3] = ((lanes[i & 3] ^ w) * p) & m
    h = lanes[0]
    for lane in lanes[1:]:
        h = ((h ^ lane) * p) & m
    for b in data[n:]:
        h = ((h ^ b) * p) & m
    return h


def fnv1a32(data):
    h = 0x811C9DC5
    for b in data:
        h ^= b
        h = (h * 0x01000193) & 0xFFFFFFFF
    return h


MTS_HEADER = 32
STREAM_HEADER = 28


def seal_mts(data):
    """Rewrites the .mts header's length and checksum (as format::seal)."""
    b = bytearray(data)
    if len(b) < MTS_HEADER:
        return bytes(b)
    b[16:24] = struct.pack("<Q", len(b))
    version = struct.unpack_from("<I", b, 8)[0]
    body = bytes(b[MTS_HEADER:])
    b[24:32] = struct.pack("<Q", fnv1a64(body) if version < 3 else fnv1a64_words(body))
    return bytes(b)


def seal_stream(data):
    b = bytearray(data)
    if len(b) < STREAM_HEADER:
        return bytes(b)
    b[24:28] = struct.pack("<I", fnv1a32(b[STREAM_HEADER:]))
    return bytes(b)


def put_varint(out, v):
    v &= (1 << 64) - 1
    while v >= 0x80:
        out.append((v & 0x7F) | 0x80)
        v >>= 7
    out.append(v)


def get_varint(buf, pos):
    v, shift = 0, 0
    while True:
        b = buf[pos]
        pos += 1
        v |= (b & 0x7F) << shift
        shift += 7
        if not b & 0x80:
            return v, pos


def zigzag(v):
    return ((v << 1) ^ (v >> 63)) & ((1 << 64) - 1)


def unzigzag(v):
    return (v >> 1) ^ -(v & 1)


class MtsFile:
    """An .mts file taken apart (layout of src/model/format.rs)."""

    def __init__(self, data):
        self.version = struct.unpack_from("<I", data, 8)[0]
        pos = MTS_HEADER
        sec = {}
        for tag in ("META", "POSI", "STRP", "STEP"):
            n = struct.unpack_from("<Q", data, pos + 4)[0]
            sec[tag] = bytes(data[pos + 12 : pos + 12 + n])
            pos += 12 + n
        m = sec["META"]
        p = 0
        self.counts = []
        for _ in range(5):
            v, p = get_varint(m, p)
            self.counts.append(v)
        self.band_slack = struct.unpack_from("<d", m, p)[0]
        p += 8
        self.patches = m[p]
        p += 1
        self.min_patch, p = get_varint(m, p)
        self.swap = list(struct.unpack_from("<ff", m, p))
        p += 8
        self.join_ends, self.optimal = m[p], m[p + 1]
        self.posi = list(struct.unpack("<%df" % (len(sec["POSI"]) // 4), sec["POSI"]))
        s = sec["STRP"]
        p = 0
        self.runs = []
        for _ in range(self.counts[2]):
            v, p = get_varint(s, p)
            self.runs.append(v)
        self.indices = []
        prev = 0
        for _ in range(self.counts[3]):
            v, p = get_varint(s, p)
            prev += unzigzag(v)
            self.indices.append(prev)
        st = sec["STEP"]
        p = 0
        self.steps = []
        for _ in range(self.counts[4]):
            r, p = get_varint(st, p)
            k, p = get_varint(st, p)
            e = struct.unpack_from("<f", st, p)[0]
            p += 4
            self.steps.append([r, k, e])
        self.tags = [b"META", b"POSI", b"STRP", b"STEP"]
        self.len_delta = [0, 0, 0, 0]
        self.extra = [b"", b"", b"", b""]
        self.trailing = b""
        self.section_count = 4

    def to_bytes(self, raw_f32=None):
        meta = bytearray()
        for c in self.counts:
            put_varint(meta, c)
        meta += struct.pack("<d", self.band_slack)
        meta.append(self.patches & 0xFF)
        put_varint(meta, self.min_patch)
        meta += struct.pack("<ff", *self.swap)
        meta.append(self.join_ends & 0xFF)
        meta.append(self.optimal & 0xFF)
        posi = struct.pack("<%df" % len(self.posi), *self.posi)
        strp = bytearray()
        for r in self.runs:
            put_varint(strp, r)
        prev = 0
        for v in self.indices:
            put_varint(strp, zigzag(v - prev))
            prev = v
        step = bytearray()
        for r, k, e in self.steps:
            put_varint(step, r)
            put_varint(step, k)
            step += struct.pack("<f", e)
        body = bytearray()
        for i, payload in enumerate([bytes(meta), posi, bytes(strp), bytes(step)]):
            payload = payload + self.extra[i]
            body += self.tags[i]
            body += struct.pack("<Q", max(0, len(payload) + self.len_delta[i]) & ((1 << 64) - 1))
            body += payload
        body += self.trailing
        head = b"MTSMODEL" + struct.pack("<II", self.version, self.section_count)
        head += struct.pack("<QQ", 0, 0)
        return seal_mts(head + bytes(body))


# --------------------------------------------------------------------------
# Seed meshes (positions, polygons)


def torus_mesh(nu, nv, r1=1.0, r2=0.35):
    pos = []
    for i in range(nu):
        a = 2 * math.pi * i / nu
        for j in range(nv):
            b = 2 * math.pi * j / nv
            pos.append(((r1 + r2 * math.cos(b)) * math.cos(a), (r1 + r2 * math.cos(b)) * math.sin(a), r2 * math.sin(b)))
    tris = []
    for i in range(nu):
        for j in range(nv):
            a, b = i * nv + j, ((i + 1) % nu) * nv + j
            c, d = ((i + 1) % nu) * nv + (j + 1) % nv, i * nv + (j + 1) % nv
            tris.append((a, b, c))
            tris.append((a, c, d))
    return pos, tris


def grid_mesh(n, m, quads=False):
    pos = [(x / n, y / m, 0.1 * math.sin(x + y)) for y in range(m + 1) for x in range(n + 1)]
    faces = []
    for y in range(m):
        for x in range(n):
            a = y * (n + 1) + x
            b, c, d = a + 1, a + n + 2, a + n + 1
            if quads:
                faces.append((a, b, c, d))
            else:
                faces.append((a, b, c))
                faces.append((a, c, d))
    return pos, faces


def cube_mesh():
    pos = [(x, y, z) for x in (0.0, 1.0) for y in (0.0, 1.0) for z in (0.0, 1.0)]
    quads = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
    return pos, quads


def icosahedron():
    t = (1 + 5 ** 0.5) / 2
    pos = [(-1, t, 0), (1, t, 0), (-1, -t, 0), (1, -t, 0), (0, -1, t), (0, 1, t),
           (0, -1, -t), (0, 1, -t), (t, 0, -1), (t, 0, 1), (-t, 0, -1), (-t, 0, 1)]
    faces = [(0, 11, 5), (0, 5, 1), (0, 1, 7), (0, 7, 10), (0, 10, 11), (1, 5, 9), (5, 11, 4),
             (11, 10, 2), (10, 7, 6), (7, 1, 8), (3, 9, 4), (3, 4, 2), (3, 2, 6), (3, 6, 8),
             (3, 8, 9), (4, 9, 5), (2, 4, 11), (6, 2, 10), (8, 6, 7), (9, 8, 1)]
    return [tuple(float(c) for c in p) for p in pos], faces


def fmt(x):
    return repr(float(x)) if isinstance(x, float) else str(x)


def obj_text(pos, faces, style="plain", extra_head=""):
    """OBJ text; style: plain, slashes (v/vt/vn), relative (negative
    indices), groups (o/g/usemtl/s statements)."""
    out = [extra_head] if extra_head else []
    out.append("# mts hostile seed\n")
    if style == "groups":
        out.append("mtllib missing.mtl\no first\ng part\nusemtl none\ns 1\n")
    for p in pos:
        out.append("v %s %s %s\n" % tuple(fmt(c) for c in p))
    if style == "slashes":
        for i in range(len(pos)):
            out.append("vt %s %s\n" % (fmt(i / len(pos)), fmt(0.5)))
        for p in pos:
            out.append("vn 0.0 0.0 1.0\n")
    half = len(faces) // 2
    for k, f in enumerate(faces):
        if style == "groups" and k == half:
            out.append("o second\ng other\ns off\n")
        if style == "slashes":
            out.append("f " + " ".join("%d/%d/%d" % (i + 1, i + 1, i + 1) for i in f) + "\n")
        elif style == "relative":
            out.append("f " + " ".join(str(i - len(pos)) for i in f) + "\n")
        else:
            out.append("f " + " ".join(str(i + 1) for i in f) + "\n")
    return "".join(out).encode()


SCALAR = {"char": "b", "uchar": "B", "short": "h", "ushort": "H", "int": "i",
          "uint": "I", "float": "f", "double": "d"}


def ply_bytes(pos, faces, enc="ascii", coord="float", count="uchar", index="int",
              extras=False, strips=None, element_counts=None, header_edit=None,
              last_count=None):
    """A PLY file. `strips`: list of index lists written as a `tristrips`
    element (-1 restarts) instead of faces. `element_counts` overrides the
    declared counts; `header_edit(lines)` rewrites header lines;
    `last_count` replaces the list count of the last face."""
    nv = len(pos)
    fe = "tristrips" if strips is not None else "face"
    items = strips if strips is not None else faces
    counts = dict(vertex=nv, face=len(items), extra=2)
    if element_counts:
        counts.update(element_counts)
    head = ["ply", "format %s 1.0" % enc, "comment hostile seed", "obj_info generated"]
    head.append("element vertex %s" % counts["vertex"])
    head += ["property %s x" % coord, "property %s y" % coord, "property %s z" % coord]
    if extras:
        head += ["property float nx", "property float ny", "property float nz",
                 "property uchar red", "property uchar green", "property uchar blue"]
    head.append("element %s %s" % (fe, counts["face"]))
    if extras and strips is None:
        head.append("property list uchar float texcoord")
    head.append("property list %s %s vertex_indices" % (count, index))
    if extras:
        head.append("property uchar flags")
        head += ["element extra %s" % counts["extra"], "property list ushort short junk", "property double w"]
    head.append("end_header")
    if header_edit:
        head = header_edit(head)
    text = ("\n".join(head) + "\n").encode()
    if enc == "ascii":
        out = [text]
        for p in pos:
            line = " ".join(fmt(c) if coord in ("float", "double") else str(int(c)) for c in p)
            if extras:
                line += " 0 0 1 200 100 50"
            out.append((line + "\n").encode())
        for k, f in enumerate(items):
            n = len(f) if (last_count is None or k != len(items) - 1) else last_count
            line = "%d %s" % (n, " ".join(str(i) for i in f))
            if extras and strips is None:
                line = "2 0.5 0.25 " + line
            if extras:
                line += " 7"
            out.append((line + "\n").encode())
        if extras:
            out.append(b"3 1 2 3 0.5\n0 1.5\n")
        return b"".join(out)
    e = "<" if enc == "binary_little_endian" else ">"
    out = bytearray(text)
    for p in pos:
        c = SCALAR[coord]
        vals = [float(x) if c in "fd" else int(x) for x in p]
        out += struct.pack(e + c * 3, *vals)
        if extras:
            out += struct.pack(e + "fffBBB", 0, 0, 1, 200, 100, 50)
    for k, f in enumerate(items):
        n = len(f) if (last_count is None or k != len(items) - 1) else last_count
        if extras and strips is None:
            out += struct.pack(e + "Bff", 2, 0.5, 0.25)
        out += struct.pack(e + SCALAR[count], n)
        out += struct.pack(e + SCALAR[index] * len(f), *f)
        if extras:
            out += struct.pack(e + "B", 7)
    if extras:
        out += struct.pack(e + "H3hd", 3, 1, 2, 3, 0.5)
        out += struct.pack(e + "Hd", 0, 1.5)
    return bytes(out)


INT_RANGE = {"char": (-128, 127), "uchar": (0, 255), "short": (-32768, 32767), "ushort": (0, 65535),
             "int": (-2 ** 31, 2 ** 31 - 1), "uint": (0, 2 ** 32 - 1)}
TYPE_ALIASES = {"int8": "char", "uint8": "uchar", "int16": "short", "uint16": "ushort", "int32": "int",
                "uint32": "uint", "float32": "float", "float64": "double"}
ASCII_INT = re.compile(rb"^[+-]?[0-9]+$")
ASCII_FLOAT = re.compile(rb"^[+-]?([0-9]+\.?[0-9]*|\.[0-9]+)([eE][+-]?[0-9]+)?$")


class Unsure(Exception):
    pass


def ply_verdict(data):
    """A strict reference reading of a PLY file, to tell whether a mutated
    file must be refused: "invalid" when any reader must fail (the data
    ends inside a declared element, a negative list length, a coordinate
    that is not a finite f32, a vertex index outside the declared
    vertices), "valid" when it reads through, "unsure" when the header or a
    token is beyond what this reference decides (unknown lines, odd number
    syntax, values outside their type)."""
    try:
        return _ply_verdict(data)
    except Unsure:
        return "unsure"
    except Exception:  # noqa: BLE001 - anything unexpected: no verdict
        return "unsure"


def _ply_verdict(data):
    end = data.find(b"end_header")
    if end < 0 or end > 64 * 1024:
        raise Unsure
    nl = data.find(b"\n", end)
    if nl < 0:
        raise Unsure
    lines = data[:nl].split(b"\n")
    if lines[0].strip() != b"ply":
        raise Unsure
    enc, elements = None, []
    for line in lines[1:]:
        w = line.split()
        if not w or w[0] in (b"comment", b"obj_info"):
            continue
        if w[0] == b"format" and len(w) == 3:
            enc = w[1].decode()
        elif w[0] == b"element" and len(w) == 3 and ASCII_INT.match(w[2]) and int(w[2]) >= 0:
            elements.append((w[1].decode(), int(w[2]), []))
        elif w[0] == b"property" and len(w) == 5 and w[1] == b"list" and elements:
            c, i = (TYPE_ALIASES.get(x.decode(), x.decode()) for x in (w[2], w[3]))
            if c not in INT_RANGE or i not in SCALAR:
                raise Unsure
            elements[-1][2].append((w[4].decode(), c, i))
        elif w[0] == b"property" and len(w) == 3 and elements:
            t = TYPE_ALIASES.get(w[1].decode(), w[1].decode())
            if t not in SCALAR:
                raise Unsure
            elements[-1][2].append((w[2].decode(), t, None))
        elif w == [b"end_header"]:
            break
        else:
            raise Unsure
    if enc not in ("ascii", "binary_little_endian", "binary_big_endian"):
        raise Unsure
    body = data[nl + 1 :]
    nv = next((n for name, n, _ in elements if name == "vertex"), 0)
    if enc == "ascii":
        tokens = iter(body.split())

        def read(t):
            tok = next(tokens, None)
            if tok is None:
                raise EOFError
            if t in INT_RANGE:
                if not ASCII_INT.match(tok):
                    raise Unsure
                v = int(tok)
                lo, hi = INT_RANGE[t]
                if not lo <= v <= hi:
                    raise Unsure
                return v
            if not ASCII_FLOAT.match(tok):
                raise Unsure
            return float(tok)
    else:
        e = "<" if enc == "binary_little_endian" else ">"
        pos = [0]

        def read(t):
            f = e + SCALAR[t]
            n = struct.calcsize(f)
            if pos[0] + n > len(body):
                raise EOFError
            v = struct.unpack_from(f, body, pos[0])[0]
            pos[0] += n
            return v
    try:
        for name, count, props in elements:
            if not props:
                continue
            names = [p[0] for p in props]
            if name == "vertex" and not all(a in names for a in "xyz"):
                raise Unsure
            index_prop = None
            if name in ("face", "tristrips"):
                lists = [p for p in props if p[2] is not None and p[0] in ("vertex_indices", "vertex_index")]
                if not lists or lists[0][2] not in INT_RANGE:
                    raise Unsure
                index_prop = lists[0][0]
            for _ in range(count):
                for pname, t, item in props:
                    if item is None:
                        v = read(t)
                        if name == "vertex" and pname in "xyz" and len(pname) == 1:
                            if v != v:
                                return "invalid"
                            try:
                                struct.pack("<f", v)
                            except OverflowError:
                                return "invalid"
                            if math.isinf(v):
                                return "invalid"
                        continue
                    n = read(t)
                    if n < 0:
                        return "invalid"
                    for _ in range(n):
                        v = read(item)
                        if pname == index_prop and not (0 <= v < nv or (name == "tristrips" and v == -1)):
                            return "invalid"
    except EOFError:
        return "invalid"
    return "valid"


def grid_strips(n, m):
    strips = []
    for y in range(m):
        s = []
        for x in range(n + 1):
            s += [y * (n + 1) + x, (y + 1) * (n + 1) + x]
        strips.append(s)
    joined = []
    for s in strips:
        joined += s + [-1]
    return [joined[:-1]]


# OBJ and PLY seeds: name -> (pos, faces, writer kwargs)
def obj_seeds():
    tp, tf = torus_mesh(12, 8)
    gp, gq = grid_mesh(6, 5, quads=True)
    ip, i_f = icosahedron()
    cp, cq = cube_mesh()
    return [
        ("torus", tp, tf, "plain"),
        ("torus_vt_vn", tp, tf, "slashes"),
        ("grid_quads_relative", gp, gq, "relative"),
        ("icosahedron_groups", ip, i_f, "groups"),
        ("cube_quads", cp, cq, "plain"),
    ]


def ply_seeds():
    tp, tf = torus_mesh(10, 8)
    gp, gf = grid_mesh(5, 4)
    ip, i_f = icosahedron()
    sp, _ = grid_mesh(6, 3)
    cp, cq = cube_mesh()
    cpi = [tuple(int(c * 100) for c in p) for p in cp]
    return [
        ("torus_ascii", tp, tf, dict(enc="ascii")),
        ("torus_le", tp, tf, dict(enc="binary_little_endian")),
        ("torus_be", tp, tf, dict(enc="binary_big_endian")),
        ("grid_le_double_uint", gp, gf, dict(enc="binary_little_endian", coord="double", count="uint", index="uint")),
        ("ico_be_extras", ip, i_f, dict(enc="binary_big_endian", extras=True)),
        ("ico_ascii_extras", ip, i_f, dict(enc="ascii", extras=True)),
        ("strips_le", sp, None, dict(enc="binary_little_endian", strips=grid_strips(6, 3))),
        ("cube_short_quads", cpi, cq, dict(enc="binary_little_endian", coord="short", count="uchar", index="int")),
    ]


# --------------------------------------------------------------------------
# Generic mutations


def truncate(rng, data):
    if len(data) <= 1:
        return b""
    r = rng.random()
    if r < 0.3:
        cut = rng.randrange(0, min(len(data), 64))
    elif r < 0.5:
        cut = len(data) - 1 - rng.randrange(0, min(len(data) - 1, 16))
    else:
        cut = rng.randrange(0, len(data))
    return data[:cut]


def flip(rng, data, start=0, count=None):
    b = bytearray(data)
    if len(b) <= start:
        return bytes(b), []
    n = count or rng.choice([1, 1, 1, 2, 3, 8])
    where = []
    for _ in range(n):
        i = rng.randrange(start, len(b))
        b[i] ^= rng.randrange(1, 256)
        where.append(i)
    return bytes(b), where


# --------------------------------------------------------------------------
# Cases


class Case:
    def __init__(self, family, kind, ext=None, data=None, path=None):
        self.family = family
        self.kind = kind
        self.ext = ext
        self.data = data
        self.path = path  # a fixed path (/dev/zero) instead of data
        self.runs = []  # (argv with "{in}"/"{out}"/"{seed:*}", expect, names_target)

    def run(self, argv, expect, target=True):
        self.runs.append((argv, expect, target))


MESH_EXTRA_CMDS = [
    ["simplify", "{in}", "--ratio", "0.5", "--samples", "500"],
    ["distance", "{seed:obj}", "{in}", "--samples", "500"],
    ["encode", "{in}", "-o", "{out}.stream"],
    ["verify", "{in}", "--lods", "4"],
    ["extract", "{in}", "--ratio", "0.5", "--repeat", "1"],
    ["compare", "{in}", "--requests", "5"],
    ["convert", "{in}", "-o", "{out}.obj"],
    ["simplify", "{in}", "--triangles", "10", "--samples", "500", "--optimal", "--no-meshopt"],
    ["extract", "{in}", "--lod", "3", "--repeat", "1", "--method", "pm"],
    ["extract", "{in}", "--ratio", "0.3", "--repeat", "1", "--method", "cluster"],
    ["build", "{in}", "--weld", "--optimal", "-o", "{out}.mts"],
    ["distance", "{in}", "{in}", "--samples", "300", "--json"],
]


def mesh_runs(case, rng, expect, render_ok=False):
    case.run(["strips", "{in}", "--repeat", "1"], expect)
    case.run(["build", "{in}", "-o", "{out}.mts"], expect)
    case.run(rng.choice(MESH_EXTRA_CMDS), expect)
    if render_ok:
        case.run(["render", "{in}", "--size", "32x32", "-o", "{out}.png"], expect)


def gen_obj(rng, seeds):
    name, pos, faces, style = rng.choice(obj_seeds())
    data = obj_text(pos, faces, style)
    text = data.decode()
    lines = text.splitlines(keepends=True)
    nv = len(pos)
    kinds = ["truncate", "flip", "face_range", "face_zero", "face_huge", "face_word",
             "coord_nonfinite", "coord_word", "junk_lines", "no_faces", "swap_tokens",
             "repeat_file", "short_face", "vt_range", "vn_range", "clean"]
    kind = rng.choice(kinds)
    expect = UNKNOWN
    face_lines = [i for i, l in enumerate(lines) if l.startswith("f ")]
    v_lines = [i for i, l in enumerate(lines) if l.startswith("v ")]

    def edit_face(fn):
        i = rng.choice(face_lines)
        toks = lines[i].split()
        j = rng.randrange(1, len(toks))
        toks[j] = fn(toks[j])
        lines[i] = " ".join(toks) + "\n"

    def set_part(tok, part, value):
        parts = tok.split("/")
        if part < len(parts):
            parts[part] = value
        else:
            parts[0] = value
        return "/".join(parts)

    if kind == "truncate":
        data = truncate(rng, data)
    elif kind == "flip":
        data, _ = flip(rng, data)
    elif kind == "face_range":
        v = rng.choice([nv + 1, nv + 2, nv + 1000, 2 ** 31, 2 ** 32 + 1, -(nv + 1), -(2 ** 31)])
        edit_face(lambda t: set_part(t, 0, str(v)))
        data, expect = "".join(lines).encode(), GARBAGE
    elif kind == "face_zero":
        edit_face(lambda t: set_part(t, 0, "0"))
        data, expect = "".join(lines).encode(), GARBAGE
    elif kind == "face_huge":
        edit_face(lambda t: set_part(t, 0, rng.choice(["99999999999999999999", "18446744073709551617", "-99999999999999999999"])))
        data, expect = "".join(lines).encode(), GARBAGE
    elif kind == "face_word":
        edit_face(lambda t: set_part(t, 0, rng.choice(["x", "1.5", "one", "1e3", "0x10", "--1"])))
        data, expect = "".join(lines).encode(), GARBAGE
    elif kind == "coord_nonfinite":
        i = rng.choice(v_lines)
        toks = lines[i].split()
        toks[rng.randrange(1, 4)] = rng.choice(["nan", "NaN", "inf", "-inf", "1e39", "-3.5e38e", "infinity"])
        lines[i] = " ".join(toks) + "\n"
        data, expect = "".join(lines).encode(), GARBAGE
    elif kind == "coord_word":
        i = rng.choice(v_lines)
        toks = lines[i].split()
        toks[rng.randrange(1, 4)] = rng.choice(["abc", "1,5", "--", "0x1p3", ""])
        lines[i] = " ".join(toks) + "\n"
        data, expect = "".join(lines).encode(), GARBAGE
    elif kind == "junk_lines":
        junk = ["vp 0.5 0.5\n", "cstype bspline\n", "mtllib ../../../etc/passwd\n", "usemtl\n",
                "#" + "x" * 5000 + "\n", "\n\n\n", "s 1\n", "g\n", "o\n", "l 1 2\n", "p 1\n",
                "\t  \n", "v\n", "deg 3\n", "call x.obj\n", "\x00\n"]
        for _ in range(rng.randint(1, 6)):
            lines.insert(rng.randrange(len(lines) + 1), rng.choice(junk))
        data = "".join(lines).encode()
    elif kind == "no_faces":
        data = "".join(l for l in lines if not l.startswith("f ")).encode()
        expect = GARBAGE
    elif kind == "swap_tokens":
        toks = text.split(" ")
        for _ in range(rng.randint(1, 4)):
            a, b = rng.randrange(len(toks)), rng.randrange(len(toks))
            toks[a], toks[b] = toks[b], toks[a]
        data = " ".join(toks).encode()
    elif kind == "repeat_file":
        data = data * rng.randint(2, 5)
    elif kind == "short_face":
        i = rng.choice(face_lines)
        toks = lines[i].split()
        lines[i] = " ".join(toks[: rng.choice([1, 2, 3])]) + "\n"
        data = "".join(lines).encode()
    elif kind in ("vt_range", "vn_range"):
        pos2, faces2 = pos, faces
        lines = obj_text(pos2, faces2, "slashes").decode().splitlines(keepends=True)
        face_lines = [i for i, l in enumerate(lines) if l.startswith("f ")]
        part = 1 if kind == "vt_range" else 2
        v = rng.choice([len(pos2) + 1, len(pos2) + 50, 2 ** 31, -(len(pos2) + 1)])
        edit_face(lambda t: set_part(t, part, str(v)))
        data, expect = "".join(lines).encode(), GARBAGE
    else:
        expect = VALID
    case = Case("obj", "%s/%s" % (kind, name), ".obj", data)
    mesh_runs(case, rng, expect)
    return case


def gen_ply(rng, seeds):
    name, pos, faces, kw = rng.choice(ply_seeds())
    kw = dict(kw)
    enc = kw.get("enc")
    binary = enc != "ascii"
    items = kw.get("strips") or faces
    kinds = ["truncate", "truncate", "flip", "flip", "count_up", "count_huge", "count_down",
             "bad_type", "float_count", "last_count", "index_range", "coord_nonfinite",
             "bad_format", "no_end_header", "clean", "header_junk", "face_count_up"]
    kind = rng.choice(kinds)
    expect = UNKNOWN
    full = ply_bytes(pos, faces, **kw)
    data = full
    if kind == "truncate":
        data = truncate(rng, full)
        head = full.index(b"end_header") + len(b"end_header\n")
        if len(data) < head or (binary and len(data) < len(full)) or len(data.split()) < len(full.split()):
            expect = GARBAGE
    elif kind == "flip":
        data, _ = flip(rng, full)
    elif kind in ("count_up", "face_count_up"):
        key = "vertex" if kind == "count_up" else "face"
        base = len(pos) if key == "vertex" else len(items)
        data = ply_bytes(pos, faces, element_counts={key: base + rng.choice([1, 2, 100])}, **kw)
    elif kind == "count_huge":
        key = rng.choice(["vertex", "face"])
        v = rng.choice([4294967295, 4294967296, 10 ** 18, 18446744073709551615, 18446744073709551616, -1, "1e9", "0x10"])
        data = ply_bytes(pos, faces, element_counts={key: v}, **kw)
        expect = GARBAGE
    elif kind == "count_down":
        key = rng.choice(["vertex", "face"])
        base = len(pos) if key == "vertex" else len(items)
        data = ply_bytes(pos, faces, element_counts={key: max(0, base - rng.choice([1, 2, base]))}, **kw)
    elif kind == "bad_type":
        def edit(h):
            i = next(k for k, l in enumerate(h) if l.startswith("property"))
            h[i] = h[i].replace(h[i].split()[1], rng.choice(["float128", "int64", "half", "string", "list"]), 1)
            return h
        data = ply_bytes(pos, faces, header_edit=edit, **kw)
        expect = GARBAGE
    elif kind == "float_count":
        def edit(h):
            return [l.replace("property list %s" % kw.get("count", "uchar"), "property list float") if "vertex_indices" in l else l for l in h]
        data = ply_bytes(pos, faces, header_edit=edit, **kw)
        expect = GARBAGE
    elif kind == "last_count":
        big = 255 if kw.get("count", "uchar") == "uchar" else rng.choice([255, 2 ** 31 - 1, 2 ** 32 - 1])
        if kw.get("count") == "int":
            big = rng.choice([255, 2 ** 31 - 1, -5])
        data = ply_bytes(pos, faces, last_count=big, **kw)
    elif kind == "index_range":
        items2 = [list(f) for f in items]
        k = rng.randrange(len(items2))
        j = rng.randrange(len(items2[k]))
        signed = kw.get("index", "int") in ("int", "short", "char")
        choices = [len(pos), len(pos) + 7, 65535]
        choices += [-2, -(2 ** 31)] if signed else [2 ** 32 - 1]
        items2[k][j] = rng.choice(choices)
        if kw.get("strips") is not None:
            kw["strips"] = items2
            data = ply_bytes(pos, None, **kw)
        else:
            data = ply_bytes(pos, items2, **kw)
        expect = GARBAGE
    elif kind == "coord_nonfinite":
        if kw.get("coord", "float") not in ("float", "double"):
            kw["coord"] = "float"
        pos2 = [list(p) for p in pos]
        pos2[rng.randrange(len(pos2))][rng.randrange(3)] = rng.choice([float("nan"), float("inf"), -float("inf")])
        data = ply_bytes(pos2, faces, **kw)
        expect = GARBAGE
    elif kind == "bad_format":
        bad = rng.choice(["format binary_middle_endian 1.0", "format ascii", "format", "format ascii 1.0 extra", "format utf8 1.0"])
        data = ply_bytes(pos, faces, header_edit=lambda h: [bad if l.startswith("format") else l for l in h], **kw)
        expect = GARBAGE
    elif kind == "no_end_header":
        data = ply_bytes(pos, faces, header_edit=lambda h: [l for l in h if l != "end_header"], **kw)
        expect = GARBAGE
    elif kind == "header_junk":
        junk = rng.choice(["property float x", "element vertex 3", "comment " + "y" * 70000, "elephant 3", "property list uchar", "ply"])
        def edit(h):
            h.insert(rng.randrange(1, len(h)), junk)
            return h
        data = ply_bytes(pos, faces, header_edit=edit, **kw)
        expect = GARBAGE if junk.startswith(("elephant", "property list uchar", "comment y", "ply")) else UNKNOWN
    else:
        expect = VALID
    if kind in ("flip", "count_up", "face_count_up", "count_down", "last_count"):
        # Whether these must be refused depends on where the bytes fall: the
        # reference reading decides (a raised vertex count can realign onto
        # the faces as one empty face, a valid file).
        expect = GARBAGE if ply_verdict(data) == "invalid" else UNKNOWN
    case = Case("ply", "%s/%s" % (kind, name), ".ply", data)
    mesh_runs(case, rng, expect)
    return case


MTS_CMDS = [
    ["extract", "{in}", "--ratio", "0.5", "--repeat", "1"],
    ["extract", "{in}", "--lod", "1000000", "--repeat", "1", "-o", "{out}.obj"],
    ["extract", "{in}", "--triangles", "1", "--repeat", "1", "--method", "multilevel"],
    ["extract", "{in}", "--ratio", "0.25", "--repeat", "1", "--method", "discrete"],
    ["extract", "{in}", "--lod", "2", "--repeat", "1", "--method", "pm"],
    ["extract", "{in}", "--ratio", "0.1", "--repeat", "1", "--method", "cluster", "--json"],
    ["verify", "{in}", "--lods", "all", "--json"],
]


def gen_mts(rng, seeds, render_ok):
    name = rng.choice(sorted(seeds.mts))
    full = seeds.mts[name]
    kinds = ["truncate", "truncate", "flip", "flip", "reseal_flip", "reseal_flip", "reseal_flip",
             "meta_count", "meta_count_huge", "band_slack", "flag", "swap_inf", "pos_nonfinite",
             "strip_range", "strip_other", "short_run", "step_range", "step_self", "step_reuse",
             "step_error", "step_drop", "tag", "section_len", "trailing", "section_extra",
             "version", "section_count", "no_strips", "pos_extreme", "clean"]
    ready = struct.unpack_from("<I", full, 8)[0] >= 3
    if ready:
        # The harness rebuilds only the recipe's sections: byte-level
        # mutations for the ready file.
        kinds = ["truncate", "flip", "reseal_flip", "reseal_flip", "reseal_flip", "clean"]
    kind = rng.choice(kinds)
    expect = GARBAGE
    m = MtsFile(full)
    nv = m.counts[0]
    data = None
    if kind == "truncate":
        data = truncate(rng, full)
    elif kind == "flip":
        data, _ = flip(rng, full)
    elif kind == "reseal_flip":
        data, _ = flip(rng, full, start=MTS_HEADER + 12)
        data = seal_mts(data)
        expect = UNKNOWN
    elif kind == "meta_count":
        i = rng.randrange(5)
        m.counts[i] = max(0, m.counts[i] + rng.choice([-1, 1, 2]))
        if m.counts[i] == MtsFile(full).counts[i]:
            m.counts[i] += 1
    elif kind == "meta_count_huge":
        m.counts[rng.randrange(5)] = rng.choice([2 ** 32, 2 ** 40, 2 ** 63, 2 ** 64 - 1, 0x3FFFFFFF])
    elif kind == "band_slack":
        m.band_slack = rng.choice([float("nan"), -1.0, -float("inf"), 0.0, 0.001, -0.0])
    elif kind == "flag":
        which = rng.choice(["patches", "join_ends", "optimal"])
        setattr(m, which, rng.randrange(2, 256))
    elif kind == "swap_inf":
        m.swap[rng.randrange(2)] = rng.choice([float("inf"), -float("inf")])
    elif kind == "pos_nonfinite":
        m.posi[rng.randrange(len(m.posi))] = rng.choice([float("nan"), float("inf"), -float("inf")])
    elif kind == "pos_extreme":
        for _ in range(rng.randint(1, 5)):
            m.posi[rng.randrange(len(m.posi))] = rng.choice([3.0e38, -3.0e38, 1e-45, 0.0, -0.0, 1e20])
        expect = UNKNOWN
    elif kind == "strip_range":
        m.indices[rng.randrange(len(m.indices))] = rng.choice([nv, nv + 1, nv + 1000, -1, -(2 ** 40), 2 ** 32])
    elif kind == "strip_other":
        for _ in range(rng.randint(1, 3)):
            m.indices[rng.randrange(len(m.indices))] = rng.randrange(nv)
        expect = UNKNOWN
    elif kind == "short_run":
        k = rng.randrange(len(m.runs))
        cut = m.runs[k] - rng.choice([1, 2]) if m.runs[k] > 3 else 1
        cut = min(cut, 2)
        start = sum(m.runs[:k])
        del m.indices[start + cut : start + m.runs[k]]
        m.runs[k] = cut
        m.counts[3] = len(m.indices)
    elif kind == "step_range" and m.steps:
        s = rng.choice(m.steps)
        s[rng.randrange(2)] = rng.choice([len(m.posi) // 3, len(m.posi) // 3 + 5, 2 ** 32, 2 ** 63])
    elif kind == "step_self" and m.steps:
        s = rng.choice(m.steps)
        s[0] = s[1]
    elif kind == "step_reuse" and len(m.steps) > 1:
        i = rng.randrange(len(m.steps) - 1)
        j = rng.randrange(i + 1, len(m.steps))
        m.steps[j][0] = m.steps[i][0]
        if m.steps[j][1] == m.steps[j][0]:
            m.steps[j][1] = m.steps[i][1]
    elif kind == "step_error" and m.steps:
        i = rng.randrange(len(m.steps))
        if i > 0 and m.steps[i - 1][2] > 0 and rng.random() < 0.5:
            m.steps[i][2] = -1.0
        else:
            m.steps[i][2] = rng.choice([float("nan"), float("inf"), -float("inf"), -1.0])
    elif kind == "step_drop" and m.steps:
        del m.steps[rng.randrange(1, len(m.steps) + 1) :]
        m.counts[4] = len(m.steps)
        if m.optimal:
            # appended vertices must match the steps: keep them matched
            extra = m.counts[1] - len(m.steps)
            m.counts[1] = len(m.steps)
            if extra > 0:
                del m.posi[len(m.posi) - 3 * extra :]
        expect = UNKNOWN
    elif kind == "tag":
        i = rng.randrange(4)
        m.tags[i] = rng.choice([b"XXXX", b"meta", b"STEP", b"\x00\x00\x00\x00"]) if i != 3 else b"META"
    elif kind == "section_len":
        m.len_delta[rng.randrange(4)] = rng.choice([-1, 1, 7, 2 ** 40, 2 ** 63, -(2 ** 10)])
    elif kind == "trailing":
        m.trailing = bytes(rng.randrange(256) for _ in range(rng.randint(1, 16)))
    elif kind == "section_extra":
        m.extra[rng.randrange(4)] = bytes(rng.randrange(256) for _ in range(rng.randint(1, 8)))
    elif kind == "version":
        m.version = rng.choice([0, 2, 255, 2 ** 32 - 1])
    elif kind == "section_count":
        m.section_count = rng.choice([0, 3, 5, 2 ** 32 - 1])
    elif kind == "no_strips":
        m.runs, m.indices = [], []
        m.counts[2] = m.counts[3] = 0
    else:
        kind = "clean"
        expect = VALID
        if ready:
            data = full
    if data is None:
        data = m.to_bytes()
    case = Case("mts", "%s/%s" % (kind, name[:-4]), ".mts", data)
    case.run(["info", "{in}", "--json"] if rng.random() < 0.3 else ["info", "{in}"], expect)
    case.run(["verify", "{in}", "--lods", "4"], expect)
    extra = list(rng.choice(MTS_CMDS))
    if MtsFile(full).optimal and extra[-1] in ("pm", "multilevel"):
        # The progressive and multilevel baselines refuse optimal placement
        # (an argument error, not the file's).
        extra[-1] = "mts"
    case.run(extra, expect)
    if render_ok:
        case.run(["render", "{in}", "--size", "32x32", "--ratio", "0.5", "-o", "{out}.png"], expect)
    return case


def gen_stream(rng, seeds):
    name = rng.choice(sorted(seeds.stream))
    full = seeds.stream[name]
    kinds = ["truncate", "truncate", "flip", "flip", "reseal_flip", "reseal_flip", "count",
             "count_huge", "roots_over", "base_over", "roots_zero", "root_nan", "trailing",
             "magic", "clean"]
    kind = rng.choice(kinds)
    strict = GARBAGE
    data = None
    b = bytearray(full)
    n, t, roots, base = struct.unpack_from("<4I", full, 8)
    if kind == "truncate":
        data = truncate(rng, full)
    elif kind == "flip":
        data, _ = flip(rng, full)
    elif kind == "reseal_flip":
        data = seal_stream(flip(rng, full, start=STREAM_HEADER)[0])
        strict = UNKNOWN
    elif kind == "count":
        i = rng.randrange(2)
        struct.pack_into("<I", b, 8 + 4 * i, (n, t)[i] + rng.choice([-1, 1, 2]))
    elif kind == "count_huge":
        i = rng.randrange(4)
        struct.pack_into("<I", b, 8 + 4 * i, rng.choice([2 ** 32 - 1, 2 ** 31, 2 ** 28]))
    elif kind == "roots_over":
        struct.pack_into("<I", b, 16, n + rng.choice([1, 100]))
    elif kind == "base_over":
        struct.pack_into("<I", b, 20, t + rng.choice([1, 100]))
    elif kind == "roots_zero":
        struct.pack_into("<I", b, 16, 0)
    elif kind == "root_nan":
        at = STREAM_HEADER + 4 * rng.randrange(min(3 * roots, (len(full) - STREAM_HEADER) // 4))
        b[at : at + 4] = struct.pack("<f", rng.choice([float("nan"), float("inf"), -float("inf")]))
    elif kind == "trailing":
        b += bytes(rng.randrange(256) for _ in range(rng.randint(1, 16)))
    elif kind == "magic":
        b[rng.randrange(8)] ^= rng.randrange(1, 256)
    else:
        strict = VALID
    if data is None:
        data = seal_stream(bytes(b))
    case = Case("stream", "%s/%s" % (kind, name[:-7]), ".stream", data)
    case.run(["decode", "{in}"], strict)
    cut = rng.randrange(0, len(data) + 16)
    # A prefix decode does not check the checksum: only header and packet
    # corruption can be caught there. --bytes at or past the end decodes the
    # whole file, strictly.
    prefix_expect = UNKNOWN
    if kind in ("roots_over", "base_over", "roots_zero", "magic") and cut >= STREAM_HEADER:
        prefix_expect = GARBAGE
    if cut < STREAM_HEADER:
        prefix_expect = GARBAGE  # not even a header
    if cut >= len(data):
        prefix_expect = strict
    case.run(["decode", "{in}", "--bytes", str(cut)], prefix_expect)
    if rng.random() < 0.5:
        case.run(["decode", "{in}", "-o", "{out}.obj", "--json"], strict)
    return case


# Absurd arguments: (argv, expectation). "{seed:stream}" etc. name seeds.
G = ["--generated", "torus:200"]


def args_table():
    t = []
    add = lambda argv, e: t.append((argv, e))
    for v, e in [("0", UNKNOWN), ("-1", GARBAGE), ("NaN", GARBAGE), ("1e3", GARBAGE), ("", GARBAGE),
                 ("18446744073709551615", UNKNOWN), ("18446744073709551616", GARBAGE), ("4294967296", UNKNOWN)]:
        add(["strips"] + G + ["--repeat", v], e)
        add(["extract"] + G + ["--ratio", "0.5", "--repeat", v], e)
    for v, e in [("0", UNKNOWN), ("18446744073709551615", UNKNOWN), ("-3", GARBAGE)]:
        add(["strips"] + G + ["--repeat", "1", "--min-patch", v], e)
    for v in ["NaN", "inf", "-inf", "1e39"]:
        add(["strips"] + G + ["--repeat", "1", "--swap-penalty", v], GARBAGE)
    add(["strips"] + G + ["--repeat", "1", "--swap-penalty", "-1e38"], UNKNOWN)
    for v, e in [("NaN", GARBAGE), ("-1", GARBAGE), ("-0", UNKNOWN), ("0", UNKNOWN), ("1", UNKNOWN),
                 ("2", GARBAGE), ("inf", GARBAGE), ("-inf", GARBAGE), ("1e308", GARBAGE), ("1e-320", UNKNOWN)]:
        add(["simplify"] + G + ["--samples", "500", "--ratio", v], e)
        add(["extract"] + G + ["--repeat", "1", "--ratio", v], e)
    for v, e in [("0", UNKNOWN), ("-1", GARBAGE), ("18446744073709551615", UNKNOWN), ("1e3", GARBAGE)]:
        add(["simplify"] + G + ["--samples", "500", "--triangles", v], e)
        add(["extract"] + G + ["--repeat", "1", "--triangles", v], e)
    for v, e in [("0", UNKNOWN), ("-1", GARBAGE), ("NaN", GARBAGE), ("1000000000", UNKNOWN),
                 ("18446744073709551615", UNKNOWN)]:
        add(["simplify"] + G + ["--ratio", "0.5", "--samples", v], e)
    for v, e in [("NaN", GARBAGE), ("inf", GARBAGE), ("-1", GARBAGE), ("1e30", UNKNOWN)]:
        add(["simplify"] + G + ["--ratio", "0.5", "--samples", "500", "--pair-distance", v], e)
    for v, e in [("NaN", GARBAGE), ("inf", GARBAGE), ("-1e308", GARBAGE), ("1e308", UNKNOWN)]:
        add(["simplify"] + G + ["--ratio", "0.5", "--samples", "500", "--boundary-weight", v], e)
    for v, e in [("0", UNKNOWN), ("-1", GARBAGE), ("NaN", GARBAGE), ("1e9", GARBAGE), ("", GARBAGE),
                 ("1000000000", UNKNOWN), ("18446744073709551615", UNKNOWN), ("some", GARBAGE)]:
        add(["verify"] + G + ["--lods", v], e)
    for v, e in [("0", UNKNOWN), ("-1", GARBAGE), ("1000000000", UNKNOWN), ("18446744073709551615", UNKNOWN)]:
        add(["compare"] + G + ["--requests", v], e)
    for v, e in [("18446744073709551615", UNKNOWN), ("-1", GARBAGE)]:
        add(["extract"] + G + ["--repeat", "1", "--lod", v], e)
    for v, e in [("NaN", GARBAGE), ("-1", GARBAGE), ("0", GARBAGE), ("1", UNKNOWN), ("inf", UNKNOWN),
                 ("-inf", GARBAGE), ("1e308", UNKNOWN), ("1e-308", GARBAGE), ("", GARBAGE)]:
        add(["build"] + G + ["-o", "{out}.mts", "--band-slack", v], e)
    for v, e in [("0", UNKNOWN), ("-1", GARBAGE), ("18446744073709551615", UNKNOWN), ("1e9", GARBAGE),
                 ("NaN", GARBAGE), ("27", UNKNOWN), ("28", UNKNOWN)]:
        add(["decode", "{seed:stream}", "--bytes", v], e)
    for g, e in [("icosphere:1e9", UNKNOWN), ("grid:1073741824", UNKNOWN), ("torus:1073741825", GARBAGE),
                 ("torus:0", GARBAGE), ("torus:-5", GARBAGE), ("torus:NaN", GARBAGE), ("torus:inf", GARBAGE),
                 ("torus:1e-9", GARBAGE), ("grid:1.5", UNKNOWN), ("icosphere:0.4", GARBAGE), ("cube:10", GARBAGE),
                 ("torus:", GARBAGE), (":100", GARBAGE), ("torus:1k5", GARBAGE), ("torus:99999999999999999999M", GARBAGE),
                 ("icosphere:1", UNKNOWN), ("grid:1", UNKNOWN), ("torus:1", UNKNOWN), ("torus:500M", UNKNOWN)]:
        add(["strips", "--generated", g, "--repeat", "1"], e)
    add(["build", "--generated", "icosphere:1e9", "-o", "{out}.mts"], UNKNOWN)
    add(["encode", "--generated", "grid:1073741824", "-o", "{out}.stream"], UNKNOWN)
    for s, e in [("0x0", GARBAGE), ("1x1", UNKNOWN), ("100000x100000", UNKNOWN), ("-1x5", GARBAGE),
                 ("NaNxNaN", GARBAGE), ("4294967295x1", UNKNOWN), ("32x", GARBAGE), ("x", GARBAGE)]:
        add(["render"] + G + ["--size", s, "-o", "{out}.png"], e)
    for v, e in [("0", UNKNOWN), ("18446744073709551615", UNKNOWN), ("-1", GARBAGE)]:
        add(["render"] + G + ["--size", "32x32", "--scene", v, "-o", "{out}.png"], e)
        add(["bench", "render"] + G + ["--size", "32x32", "--frames", "1", "--scene", v, "--json"], e)
        add(["bench", "render"] + G + ["--size", "32x32", "--scene", "0", "--frames", v, "--json"], e)
    # A negative value as its own word is taken by clap for an unknown flag:
    # pass it as --flag=VALUE so that the value's own check is reached.
    for argv, _ in t:
        for i in range(len(argv) - 2, -1, -1):
            if argv[i].startswith("--") and argv[i + 1].startswith("-") and not argv[i + 1].startswith("--"):
                argv[i : i + 2] = ["%s=%s" % (argv[i], argv[i + 1])]
    add(["info", "{seed:mts}", "--json", "--json"], GARBAGE)
    add(["info"], GARBAGE)
    add(["decode"], GARBAGE)
    add(["build", "--generated", "torus:200"], GARBAGE)
    return t


# Values that may legitimately take long (a valid huge size or count): left
# out of --quick.
SLOW_VALUES = ("1e9", "1073741824", "18446744073709551615", "1000000000", "4294967296", "500M",
               "100000x100000", "4294967295x1")


def quick_args_table():
    return [(argv, e) for argv, e in args_table() if not any(v in a for a in argv for v in SLOW_VALUES)]


def gen_args(rng, seeds, index, quick=False):
    table = quick_args_table() if quick else args_table()
    argv, expect = table[(3 * index if quick else index) % len(table)]
    case = Case("args", " ".join(argv[:1] + [a for a in argv[1:] if not a.startswith("{")])[:80])
    case.run(list(argv), expect, target=False)
    return case


def extreme_case(rng, kind):
    """Valid but extreme meshes, and non-meshes. Returns (ext, data or
    path, expectation)."""
    if kind == "coords_1e20":
        p, f = torus_mesh(16, 10)
        return ".obj", obj_text([tuple(c * 1e20 for c in q) for q in p], f), VALID
    if kind == "coords_3e38":
        p, f = torus_mesh(12, 8)
        s = 3e38 / 1.35
        return ".obj", obj_text([tuple(c * s for c in q) for q in p], f), VALID
    if kind == "edges_1e-25":
        p, f = torus_mesh(16, 10)
        return ".obj", obj_text([tuple(c * 1e-25 for c in q) for q in p], f), VALID
    if kind == "denormals":
        p, f = torus_mesh(10, 8)
        s = rng.choice([1e-40, 1e-44, 1e-38])
        return ".obj", obj_text([tuple(c * s for c in q) for q in p], f), VALID
    if kind == "denormals_ply":
        p, f = torus_mesh(10, 8)
        return ".ply", ply_bytes([tuple(c * 1e-42 for c in q) for q in p], f, enc="binary_little_endian"), VALID
    if kind == "huge_polygon":
        n = 100000
        pos = [(math.cos(2 * math.pi * i / n), math.sin(2 * math.pi * i / n), 0.0) for i in range(n)]
        return ".obj", obj_text(pos, [tuple(range(n))]), VALID
    if kind == "huge_polygon_ply":
        n = 100000
        pos = [(math.cos(2 * math.pi * i / n), math.sin(2 * math.pi * i / n), 0.0) for i in range(n)]
        return ".ply", ply_bytes(pos, [tuple(range(n))], enc="binary_little_endian", count="int"), VALID
    if kind == "million_coincident":
        return ".obj", b"v 0 0 0\nv 1 0 0\nv 0 1 0\n" + b"f 1 2 3\n" * 1000000, VALID
    if kind == "coincident_ply":
        n = 300000
        head = ("ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                "property float z\nelement face %d\nproperty list uchar int vertex_indices\nend_header\n" % n).encode()
        return ".ply", head + struct.pack("<9f", 0, 0, 0, 1, 0, 0, 0, 1, 0) + struct.pack("<B3i", 3, 0, 1, 2) * n, VALID
    if kind == "nonmanifold_fan":
        n = 2000
        pos = [(0.0, 0.0, 0.0), (1.0, 0.0, 0.0)] + [(0.5, math.cos(i), math.sin(i)) for i in range(n)]
        return ".obj", obj_text(pos, [(0, 1, i + 2) for i in range(n)]), VALID
    if kind == "degenerate":
        p, f = torus_mesh(8, 6)
        f = list(f) + [(0, 0, 1), (2, 2, 2), (3, 4, 3)] * rng.randint(1, 50)
        rng.shuffle(f)
        return ".obj", obj_text(p, f), VALID
    if kind == "all_degenerate":
        return ".obj", b"v 0 0 0\nv 1 0 0\nv 0 1 0\n" + b"f 1 1 2\nf 2 2 2\nf 3 1 3\n" * 100, VALID
    if kind == "collinear":
        n = rng.choice([3, 10, 1000])
        pos = [(float(i), 2.0 * i, 3.0 * i) for i in range(n)]
        return ".obj", obj_text(pos, [(i, i + 1, i + 2) for i in range(n - 2)]), VALID
    if kind == "collinear_mixed":
        p, f = torus_mesh(8, 6)
        p = list(p) + [(10.0, 0.0, 0.0), (11.0, 0.0, 0.0), (12.0, 0.0, 0.0)]
        k = len(p)
        return ".obj", obj_text(p, list(f) + [(k - 3, k - 2, k - 1)]), VALID
    if kind == "coincident_vertices":
        n = rng.choice([3, 100, 5000])
        pos = [(1.0, 1.0, 1.0)] * n
        return ".obj", obj_text(pos, [(i, i + 1, i + 2) for i in range(n - 2)]), VALID
    if kind == "duplicated_vertices":
        p, f = torus_mesh(10, 8)
        pos, faces = [], []
        for t in f:
            faces.append(tuple(range(len(pos), len(pos) + 3)))
            pos += [p[i] for i in t]
        return ".obj", obj_text(pos, faces), VALID
    if kind == "lines_points":
        p, f = torus_mesh(6, 4)
        text = obj_text(p, f).decode()
        text += "l 1 2 3 4\np 1 2 3\nl 1/1 2/2\n"
        if rng.random() < 0.5:
            text = "".join(l + "\n" for l in text.splitlines() if not l.startswith("f "))
            return ".obj", text.encode(), GARBAGE
        return ".obj", text.encode(), VALID
    if kind in ("vt_out_of_range", "vn_out_of_range"):
        p, f = torus_mesh(6, 4)
        text = obj_text(p, f).decode()
        text += "vt 0 0\nvn 0 0 1\n"
        text += "f 1/5/1 2/1/1 3/1/1\n" if kind == "vt_out_of_range" else "f 1/1/9 2/1/1 3/1/1\n"
        return ".obj", text.encode(), GARBAGE
    if kind == "cr_only":
        p, f = torus_mesh(8, 6)
        return ".obj", obj_text(p, f).replace(b"\n", b"\r"), VALID
    if kind == "crlf":
        p, f = torus_mesh(8, 6)
        return rng.choice([".obj", ".ply"]), (obj_text(p, f) if rng.random() < 0.5 else ply_bytes(p, f)).replace(b"\n", b"\r\n"), VALID
    if kind == "utf16":
        p, f = torus_mesh(8, 6)
        return rng.choice([".obj", ".ply"]), obj_text(p, f).decode().encode("utf-16"), GARBAGE
    if kind == "utf8_bom":
        p, f = torus_mesh(8, 6)
        return ".obj", b"\xef\xbb\xbf" + obj_text(p, f), VALID
    if kind == "binary_garbage":
        n = rng.choice([1, 17, 4096, 1 << 20])
        return rng.choice([".obj", ".ply", ".mts", ".stream", ""]), bytes(rng.randrange(256) for _ in range(min(n, 65536))) * max(1, n // 65536), GARBAGE
    if kind == "zeros":
        return rng.choice([".obj", ".ply", ".mts", ".stream", ""]), bytes(rng.choice([1, 1000, 1 << 22])), GARBAGE
    if kind == "dev_zero":
        return None, "/dev/zero", GARBAGE
    if kind == "dev_null":
        return None, "/dev/null", GARBAGE
    if kind == "directory":
        return None, "{dir}", GARBAGE
    if kind == "missing":
        return None, "{dir}/no-such-file.obj", GARBAGE
    if kind == "empty":
        return rng.choice([".obj", ".ply", ".mts", ".stream", ""]), b"", GARBAGE
    if kind == "whitespace":
        return rng.choice([".obj", ".ply"]), b" \n\t\n" * 1000, GARBAGE
    if kind == "long_comment":
        p, f = torus_mesh(8, 6)
        return ".obj", b"#" + b"c" * (10 << 20) + b"\n" + obj_text(p, f), VALID
    if kind == "many_objects":
        p, f = torus_mesh(8, 6)
        return ".obj", b"o x\ng y\n" * 100000 + obj_text(p, f), VALID
    if kind == "many_vertices_few_faces":
        n = 200000
        return ".obj", b"".join(b"v %d 0 %d\n" % (i, i % 7) for i in range(n)) + b"f 1 2 3\nf %d %d 1\n" % (n, n - 1), VALID
    if kind == "ply_no_faces":
        p, _ = torus_mesh(6, 4)
        return ".ply", ply_bytes(p, [], enc="ascii"), GARBAGE
    if kind == "ply_int_coords":
        p, f = torus_mesh(8, 6)
        return ".ply", ply_bytes([tuple(int(c * 1000) for c in q) for q in p], f, enc="binary_big_endian", coord="int"), VALID
    raise ValueError(kind)


EXTREME_KINDS = [
    "coords_1e20", "coords_3e38", "edges_1e-25", "denormals", "denormals_ply", "huge_polygon",
    "huge_polygon_ply", "million_coincident", "coincident_ply", "nonmanifold_fan", "degenerate",
    "all_degenerate", "collinear", "collinear_mixed", "coincident_vertices", "duplicated_vertices",
    "lines_points", "vt_out_of_range", "vn_out_of_range", "cr_only", "crlf", "utf16", "utf8_bom",
    "binary_garbage", "zeros", "dev_zero", "dev_null", "directory", "missing", "empty", "whitespace",
    "long_comment", "many_objects", "many_vertices_few_faces", "ply_no_faces", "ply_int_coords",
]
# Heavy kinds get two runs, not three.
HEAVY = {"huge_polygon", "huge_polygon_ply", "million_coincident", "coincident_ply", "long_comment",
         "many_objects", "many_vertices_few_faces", "dev_zero"}


LIGHT_KINDS = [k for k in EXTREME_KINDS if k not in HEAVY]


def gen_extreme(rng, seeds, index, quick=False):
    """Cycles through the kinds; the heavy ones (seconds or more per run)
    only in the first two passes, and never in --quick."""
    n = len(EXTREME_KINDS)
    if quick:
        kind = LIGHT_KINDS[index % len(LIGHT_KINDS)]
    elif index < 2 * n:
        kind = EXTREME_KINDS[index % n]
    else:
        kind = rng.choice(LIGHT_KINDS)
    ext, data, expect = extreme_case(rng, kind)
    if ext is None:
        case = Case("extreme", kind, None, None, path=data)
    else:
        case = Case("extreme", kind, ext, data)
    if kind in HEAVY:
        if index < n:
            case.run(["strips", "{in}", "--repeat", "1"], expect)
            case.run(["build", "{in}", "-o", "{out}.mts"], expect)
        else:
            case.run(["simplify", "{in}", "--ratio", "0.5", "--samples", "500"], expect)
            case.run(["encode", "{in}", "-o", "{out}.stream"], expect)
        return case
    mesh_runs(case, rng, expect)
    if kind == "duplicated_vertices":
        case.runs[1] = (["build", "{in}", "--weld", "-o", "{out}.mts"], expect, True)
    if ext in (".mts", ".stream", "") or ext is None:
        case.run(["info", "{in}"], expect)
        case.run(["decode", "{in}"], expect)
    return case


# --------------------------------------------------------------------------
# Running and classifying


class Seeds:
    pass


def make_seeds(mts_bin, root, timeout):
    """Valid seeds written by `mts` itself, and OBJ/PLY seed files."""
    s = Seeds()
    s.dir = os.path.join(root, "seeds")
    os.makedirs(s.dir)
    cube = os.path.join(s.dir, "cube.obj")
    cp, cq = cube_mesh()
    with open(cube, "wb") as f:
        f.write(obj_text(cp, cq))
    tp, tf = torus_mesh(12, 8)
    s.obj_path = os.path.join(s.dir, "torus.obj")
    with open(s.obj_path, "wb") as f:
        f.write(obj_text(tp, tf))
    jobs = {
        # The structured mutations rebuild the recipe (version 1, the
        # --recipe-only file); the ready files (version 3) get the byte-level
        # ones.
        "torus.mts": ["build", "--generated", "torus:200", "--recipe-only", "-o"],
        "ico_optimal.mts": ["build", "--generated", "icosphere:80", "--optimal", "--recipe-only", "-o"],
        "grid_single.mts": ["build", "--generated", "grid:50", "--single-band", "--recipe-only", "-o"],
        "cube.mts": ["build", cube, "--recipe-only", "-o"],
        "torus_v3.mts": ["build", "--generated", "torus:200", "-o"],
        "ico_optimal_v3.mts": ["build", "--generated", "icosphere:80", "--optimal", "-o"],
        "torus.stream": ["encode", "--generated", "torus:200", "-o"],
        "ico.stream": ["encode", "--generated", "icosphere:80", "-o"],
        "grid.stream": ["encode", "--generated", "grid:32", "-o"],
        "cube.stream": ["encode", cube, "-o"],
    }
    s.mts, s.stream = {}, {}
    for name, argv in jobs.items():
        out = os.path.join(s.dir, name)
        p = subprocess.run([mts_bin] + argv + [out], stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL,
                           stderr=subprocess.PIPE, timeout=max(60, timeout * 3))
        if p.returncode != 0 or not os.path.exists(out):
            raise RuntimeError("seed %s: `mts %s` failed: %s" % (name, " ".join(argv), p.stderr.decode(errors="replace")[:500]))
        with open(out, "rb") as f:
            data = f.read()
        (s.mts if name.endswith(".mts") else s.stream)[name] = data
    for name, data in s.mts.items():
        MtsFile(data)  # the layout is the one this harness knows
        if seal_mts(data) != data:
            raise RuntimeError("seed %s: resealing changes it; the .mts checksum is not the one of its version" % name)
    for name, data in s.stream.items():
        if seal_stream(data) != data:
            raise RuntimeError("seed %s: resealing changes it; the stream checksum is not FNV-1a/32" % name)
    s.stream_path = os.path.join(s.dir, "torus.stream")
    s.mts_path = os.path.join(s.dir, "torus.mts")
    return s


def build_case(seed, index, family, seeds, family_index, render_budget, quick=False):
    rng = random.Random("%s:%d:%s" % (seed, index, family))
    render_ok = render_budget(family_index)
    if family == "obj":
        return gen_obj(rng, seeds)
    if family == "ply":
        return gen_ply(rng, seeds)
    if family == "mts":
        return gen_mts(rng, seeds, render_ok)
    if family == "stream":
        return gen_stream(rng, seeds)
    if family == "args":
        return gen_args(rng, seeds, family_index, quick)
    return gen_extreme(rng, seeds, family_index, quick)


OOM_MARKS = ("memory allocation of", "capacity overflow", "out of memory", "cannot allocate memory",
             "os error 12", "allocation failed")
PANIC_MARKS = ("panicked at", "has overflowed its stack", "fatal runtime error")


def execute(argv, cwd, timeout, mem_bytes):
    def limits():
        resource.setrlimit(resource.RLIMIT_AS, (mem_bytes, mem_bytes))
        resource.setrlimit(resource.RLIMIT_CORE, (0, 0))
        resource.setrlimit(resource.RLIMIT_FSIZE, (4 << 30, 4 << 30))

    env = dict(os.environ, RUST_BACKTRACE="0", LC_ALL="C", NO_COLOR="1")
    with tempfile.TemporaryFile(dir=cwd) as err:
        t0 = time.monotonic()
        p = subprocess.Popen(argv, cwd=cwd, stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL, stderr=err,
                             preexec_fn=limits, start_new_session=True, env=env)
        timed_out = False
        try:
            rc = p.wait(timeout=timeout)
        except subprocess.TimeoutExpired:
            timed_out = True
            try:
                os.killpg(p.pid, signal.SIGKILL)
            except ProcessLookupError:
                pass
            rc = p.wait()
        elapsed = time.monotonic() - t0
        err.seek(0)
        stderr = err.read(64 * 1024).decode("utf-8", errors="replace")
    return rc, timed_out, elapsed, stderr


def classify(rc, timed_out, stderr, expect, target):
    low = stderr.lower()
    if timed_out:
        return "hang"
    if any(m in low for m in OOM_MARKS) or rc == -signal.SIGKILL:
        return "oom"
    if any(m in low for m in PANIC_MARKS) or rc < 0:
        return "panic"
    if rc == 0:
        return "garbage accepted" if expect == GARBAGE else "ok"
    if target and target not in stderr and os.path.basename(target) not in stderr:
        return "unnamed error"
    return "clean error"


def names_place(stderr):
    return bool(PLACE_RE.search(stderr))


def first_lines(stderr, n=3):
    """The first lines of stderr, from the panic or allocation failure when
    there is one (a graphics driver may talk first)."""
    lines = [l.strip()[:300] for l in stderr.splitlines() if l.strip()]
    for i, l in enumerate(lines):
        if any(m in l.lower() for m in PANIC_MARKS + OOM_MARKS):
            return lines[i : i + n]
    return lines[:n]


def signature(cls, cmd, stderr, family, kind):
    """What tells one failure cause from another: the class, the command,
    and the panic location or first stderr line with numbers and paths
    blanked; for accepted garbage and hangs (no message), the input's
    family and kind."""
    if cls == "garbage accepted":
        return (cls, "", "%s/%s" % (family, kind.split("/")[0]))
    if cls == "hang":
        return (cls, cmd, "%s/%s" % (family, kind.split("/")[0]))
    lines = [l for l in stderr.splitlines() if l.strip()]
    key = ""
    for l in lines:
        if "panicked at" in l or "memory allocation" in l or "overflowed" in l:
            key = l
            idx = lines.index(l)
            if "panicked at" in l and idx + 1 < len(lines):
                key += " | " + lines[idx + 1]
            break
    if not key and lines:
        key = lines[0]
    key = re.sub(r"/\S*", "<path>", key)
    key = re.sub(r"\d+", "N", key)
    return (cls, cmd, key[:200])


def run_case(case_spec, ctx):
    index, family, family_index = case_spec
    case = build_case(ctx.seed, index, family, ctx.seeds, family_index, ctx.render_budget, ctx.quick)
    cdir = os.path.join(ctx.root, "c%05d" % index)
    os.makedirs(cdir)
    if case.path is not None:
        target = case.path.replace("{dir}", cdir)
        size = 0
    elif case.data is None:
        target, size = None, 0  # args: no input file
    else:
        target = os.path.join(cdir, "input%s" % (case.ext or ""))
        with open(target, "wb") as f:
            f.write(case.data)
        size = len(case.data)
    results = []
    for k, (argv, expect, names_target) in enumerate(case.runs):
        out = os.path.join(cdir, "out%d" % k)
        real = []
        for a in argv:
            a = a.replace("{in}", target or "").replace("{out}", out)
            a = a.replace("{seed:obj}", ctx.seeds.obj_path).replace("{seed:stream}", ctx.seeds.stream_path)
            a = a.replace("{seed:mts}", ctx.seeds.mts_path)
            real.append(a)
        rc, timed_out, elapsed, stderr = execute([ctx.mts] + real, cdir, ctx.timeout, ctx.mem_bytes)
        has_file = names_target and case.family != "args"
        cls = classify(rc, timed_out, stderr, expect, target if has_file else None)
        r = dict(index=index, family=case.family, kind=case.kind, cls=cls, rc=rc, seconds=round(elapsed, 3),
                 expect=expect, argv=real, input_bytes=size, stderr=first_lines(stderr),
                 file_error=has_file and cls in ("clean error", "unnamed error"),
                 place=names_place(stderr) if has_file and cls in ("clean error", "unnamed error") else None,
                 sig=list(signature(cls, (argv[0] + " " + argv[1]) if argv[0] == "bench" else argv[0], stderr,
                                    case.family, case.kind if case.family != "args" else " ".join(argv))))
        results.append(r)
    bad = [r for r in results if r["cls"] != "clean error" and r["cls"] != "ok"]
    kept = None
    if case.path is not None and not case.path.startswith("{dir}"):
        kept = case.path
    elif bad and ctx.keep and case.path is None and target is not None:
        name = "%05d-%s-%s%s" % (index, case.family, re.sub(r"[^A-Za-z0-9_.-]+", "_", case.kind), case.ext or "")
        kept = os.path.join(os.path.abspath(ctx.keep), name)
        shutil.copyfile(target, kept)
    # Shown command lines: the kept input, the seeds under --keep, and the
    # rest relative to the (deleted) case directory.
    for r in results:
        r["kept"] = kept
        shown = []
        for a in r["argv"]:
            if kept and a == target:
                a = kept
            a = a.replace(ctx.seeds.dir, ctx.seed_shown).replace(cdir + "/", "").replace(cdir, ".")
            shown.append(a)
        r["argv"] = shown
    shutil.rmtree(cdir, ignore_errors=True)
    return results


def plan(count, families, seed):
    """(index, family, index within family) for every input: counts by
    weight over the chosen families, interleaved by a seeded shuffle."""
    total_w = sum(WEIGHTS[f] for f in families)
    counts = {f: count * WEIGHTS[f] // total_w for f in families}
    rest = count - sum(counts.values())
    for f in sorted(families, key=lambda f: -WEIGHTS[f])[:rest]:
        counts[f] += 1
    order = [f for f in families for _ in range(counts[f])]
    random.Random("plan:%s" % seed).shuffle(order)
    seen = collections.Counter()
    out = []
    for i, f in enumerate(order):
        out.append((i, f, seen[f]))
        seen[f] += 1
    return out


class Ctx:
    pass


def summarize(results, families):
    table = {}
    for f in families + ["total"]:
        table[f] = dict(inputs=0, runs=0, **{c: 0 for c in CLASSES}, file_errors=0, naming_place=0)
    inputs = collections.defaultdict(set)
    for r in results:
        for f in (r["family"], "total"):
            t = table[f]
            t["runs"] += 1
            t[r["cls"]] += 1
            inputs[f].add(r["index"])
            if r["file_error"]:
                t["file_errors"] += 1
                t["naming_place"] += bool(r["place"])
    for f, t in table.items():
        t["inputs"] = len(inputs[f])
        t["place_share"] = round(t["naming_place"] / t["file_errors"], 3) if t["file_errors"] else None
    return table


def print_table(table, out):
    cols = [("inputs", "inputs"), ("runs", "runs"), ("clean error", "clean-err"), ("ok", "ok"),
            ("panic", "panic"), ("hang", "hang"), ("oom", "oom"), ("garbage accepted", "garbage-acc"),
            ("unnamed error", "unnamed")]
    head = "%-8s" % "family" + "".join("%*s" % (max(6, len(h) + 1), h) for _, h in cols) + "  place%"
    print(head, file=out)
    for f, t in table.items():
        line = "%-8s" % f + "".join("%*d" % (max(6, len(h) + 1), t[k]) for k, h in cols)
        share = "-" if t["place_share"] is None else "%.0f%%" % (100 * t["place_share"])
        line += "  %6s" % share
        print(line, file=out)


def shell_join(argv):
    import shlex
    return " ".join(shlex.quote(a) for a in argv)


def main():
    ap = argparse.ArgumentParser(description="Hostile-input harness for the mts CLI (see the docstring).")
    ap.add_argument("--mts", required=True, help="path of the mts binary")
    ap.add_argument("--seed", type=int, default=None, help="random seed (default 1; --quick: %d)" % QUICK_SEED)
    g = ap.add_mutually_exclusive_group()
    g.add_argument("--count", type=int, default=None, help="number of inputs (default %d)" % DEFAULT_COUNT)
    g.add_argument("--quick", action="store_true", help="the CI slice: fixed seed, %d inputs" % QUICK_COUNT)
    ap.add_argument("--timeout", type=float, default=None, help="seconds per run (default 20; --quick: %d)" % QUICK_TIMEOUT)
    ap.add_argument("--mem-gb", type=float, default=4.0, help="address-space cap per run, GB (default 4)")
    ap.add_argument("--families", default=",".join(FAMILIES), help="comma-separated subset of " + ",".join(FAMILIES))
    ap.add_argument("--json", help="write the JSON summary here")
    ap.add_argument("--keep", help="copy the input of every non-clean case into this directory")
    ap.add_argument("--jobs", type=int, default=2, help="runs in parallel (default 2)")
    ap.add_argument("--list-limit", type=int, default=0, help="list at most this many non-clean runs (0: all)")
    ap.add_argument("--progress", action="store_true", help="print progress to stderr")
    a = ap.parse_args()

    mts_bin = os.path.abspath(a.mts)
    if not (os.path.isfile(mts_bin) and os.access(mts_bin, os.X_OK)):
        print("hostile.py: %s is not an executable file" % a.mts, file=sys.stderr)
        return 2
    families = [f.strip() for f in a.families.split(",") if f.strip()]
    unknown = [f for f in families if f not in FAMILIES]
    if unknown or not families:
        print("hostile.py: unknown families %s (choose from %s)" % (unknown, ",".join(FAMILIES)), file=sys.stderr)
        return 2
    seed = a.seed if a.seed is not None else (QUICK_SEED if a.quick else 1)
    count = QUICK_COUNT if a.quick else (a.count if a.count is not None else DEFAULT_COUNT)
    timeout = a.timeout if a.timeout is not None else (QUICK_TIMEOUT if a.quick else 20.0)
    if a.keep:
        os.makedirs(a.keep, exist_ok=True)
    root = tempfile.mkdtemp(prefix="mts-hostile-")
    t0 = time.monotonic()
    try:
        # Run a copy: a rebuild of the binary during the run must not mix
        # two binaries in one report (or find none for a moment).
        snap = os.path.join(root, "mts")
        try:
            shutil.copy2(mts_bin, snap)
            with open(snap, "rb") as f:
                digest = hashlib.sha1(f.read()).hexdigest()
        except OSError as e:
            print("hostile.py: cannot copy %s: %s" % (mts_bin, e), file=sys.stderr)
            return 2
        try:
            seeds = make_seeds(snap, root, timeout)
        except (RuntimeError, subprocess.TimeoutExpired, struct.error, IndexError) as e:
            print("hostile.py: cannot make the seeds: %s" % e, file=sys.stderr)
            return 2
        ctx = Ctx()
        ctx.mts, ctx.seed, ctx.seeds, ctx.root = snap, seed, seeds, root
        ctx.timeout, ctx.mem_bytes, ctx.keep, ctx.quick = timeout, int(a.mem_gb * (1 << 30)), a.keep, a.quick
        ctx.seed_shown = "seeds"
        if a.keep:
            ctx.seed_shown = os.path.join(os.path.abspath(a.keep), "seeds")
            shutil.rmtree(ctx.seed_shown, ignore_errors=True)
            shutil.copytree(seeds.dir, ctx.seed_shown)
        # Rendering is slow on CPU: one .mts input in 25 gets a render run,
        # one in --quick.
        if a.quick:
            ctx.render_budget = lambda fi: fi == 3
        else:
            ctx.render_budget = lambda fi: fi % 25 == 3
        specs = plan(count, families, seed)
        results = []
        lock = threading.Lock()
        done = [0]

        def work(spec):
            r = run_case(spec, ctx)
            with lock:
                done[0] += 1
                if a.progress and done[0] % 50 == 0:
                    print("  %d/%d inputs, %.0f s" % (done[0], len(specs), time.monotonic() - t0), file=sys.stderr)
            return r

        with ThreadPoolExecutor(max_workers=max(1, a.jobs)) as ex:
            for rs in ex.map(work, specs):
                results.extend(rs)
    finally:
        shutil.rmtree(root, ignore_errors=True)
    elapsed = time.monotonic() - t0

    table = summarize(results, families)
    out = sys.stdout
    print("mts hostile inputs: %s (sha1 %s)" % (a.mts, digest[:12]), file=out)
    print("seed %d, %d inputs, %d runs, timeout %g s, memory cap %g GB, %d jobs, %.0f s"
          % (seed, table["total"]["inputs"], table["total"]["runs"], timeout, a.mem_gb, a.jobs, elapsed), file=out)
    print_table(table, out)
    bad = [r for r in results if r["cls"] not in ("clean error", "ok")]
    failing = [r for r in bad if r["cls"] in FAILING]
    causes = collections.OrderedDict()
    for r in sorted(bad, key=lambda r: (r["input_bytes"], r["index"])):
        key = tuple(r["sig"])
        if key not in causes:
            causes[key] = dict(cls=r["cls"], command=shell_join(["mts"] + r["argv"]), family=r["family"],
                               kind=r["kind"], input_bytes=r["input_bytes"], stderr=r["stderr"][:1], runs=0,
                               kept=r.get("kept"))
        causes[key]["runs"] += 1
    if bad:
        print("\nnon-clean runs (%d; %d panic/hang/oom/garbage accepted):" % (len(bad), len(failing)), file=out)
        shown = bad if not a.list_limit else bad[: a.list_limit]
        for r in sorted(shown, key=lambda r: (FAILING + ("unnamed error",)).index(r["cls"]) * 10 ** 6 + r["index"]):
            print("  [%s] %s/%s  (%s s, exit %s)" % (r["cls"], r["family"], r["kind"], r["seconds"], r["rc"]), file=out)
            print("    mts %s" % shell_join(r["argv"]), file=out)
            if r.get("kept"):
                print("    input: %s" % r["kept"], file=out)
            for l in r["stderr"]:
                print("    | %s" % l, file=out)
        if len(shown) < len(bad):
            print("  ... %d more (see --json)" % (len(bad) - len(shown)), file=out)
        print("\ndistinct causes (%d), smallest input first:" % len(causes), file=out)
        for c in causes.values():
            print("  [%s] x%d  %s  (%s, %d bytes)" % (c["cls"], c["runs"], c["command"], c["kind"], c["input_bytes"]), file=out)
            if c["stderr"]:
                print("    | %s" % c["stderr"][0], file=out)
    no_place = collections.defaultdict(collections.Counter)
    for r in results:
        if r["file_error"] and not r["place"] and r["stderr"]:
            msg = re.sub(r"\d+", "N", re.sub(r"/\S*|input(\.\w+)?\b", "<file>", r["stderr"][0]))
            no_place[r["family"]][msg[:200]] += 1
    if a.json:
        summary = dict(errors_naming_no_place={f: c.most_common(20) for f, c in no_place.items()},binary=mts_bin, binary_sha1=digest, seed=seed, count=count, quick=a.quick, timeout_s=timeout, mem_gb=a.mem_gb,
                       jobs=a.jobs, families=families, elapsed_s=round(elapsed, 1), table=table,
                       failed=bool(failing), non_clean=bad, causes=list(causes.values()))
        with open(a.json, "w") as f:
            json.dump(summary, f, indent=1)
    return 1 if failing else 0


if __name__ == "__main__":
    sys.exit(main())
