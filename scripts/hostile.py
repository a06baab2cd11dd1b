#!/usr/bin/env python3
"""Hostile-input harness for the `mts` command line (issues 19 and 31).

Feeds the CLI inputs built to break it and classifies every run. Python 3
standard library only; everything it reads is generated in a temporary
directory, starting from seeds that `mts` itself writes.

Commands
--------
CI slice (fixed seed 19, timeout 10 s): the issue-19 families' 600 inputs
(about 1,700 runs; no heavy extreme mesh, no argument that is slow even
when handled right, one render run), the same inputs as before issue 31,
then a fixed slice of each issue-31 family (161 inputs, about 300 runs),
of the issue-33 one, hier (24 inputs, 72 runs), of the issue-34 one,
coded (24 inputs, 72 runs) and of the issue-35 one, meshopt (24 inputs, 48
runs: QUICK_SLICE); about a minute on 2 cores with a sound binary::

    python3 scripts/hostile.py --mts target/release/mts --quick

Full run (default: seed 1, 3,700 inputs over all families by WEIGHTS,
about 10,000 runs, --jobs 2; a few minutes on 2 cores with a sound binary,
each hang adds up to --timeout)::

    python3 scripts/hostile.py --mts target/release/mts --json hostile.json --keep hostile-cases

The issue-31 families alone (the figure in its closing note)::

    python3 scripts/hostile.py --mts target/release/mts \
        --families gltf,amplify,fifo,output,view,props,reseal,hier,coded,meshopt --count 600

Other options: --seed N, --count N (inputs), --timeout S (20), --mem-gb G (4),
--families obj,ply,mts,stream,args,extreme,gltf,amplify,fifo,output,view,
props,reseal,hier,coded,meshopt, --jobs N (2), --list-limit N. The same seed, count and
--families give the same inputs whatever --jobs says (each input is drawn
from its own generator, seeded by seed and index). With --quick, --families
picks among the slices (the issue-19 ones share 600 inputs as before).

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

Issue-31 families (glTF from the harness's own writer, Gltf; every valid
glTF case is converted to OBJ and its triangles, as position triples,
compared with the ones the generator wrote):
gltf     structure, indices, primitive modes, sparse accessors, extras.
         Accepted (and read right): u8/u16/u32/no indices, TRIANGLE_STRIP
         and TRIANGLE_FAN, points and lines beside triangles (skipped),
         TRS / matrix / child transforms with negative scales (winding),
         the `scene` chosen, no nodes, root nodes without scenes, sparse
         POSITION with and without a bufferView (sparse indices u8, u16,
         u32), `extras` of any JSON value (array, string, number, null,
         object...) on the root, asset, scene, node, mesh, primitive,
         accessor, bufferView, buffer, material, unknown extensions not
         required, asset.version 2.0/2.1/2.99, a GLB with an unknown chunk,
         byteStride 16..252, a chain of 60,000 nodes, 20,000 root nodes, two
         primitives sharing an accessor, KHR_mesh_quantization required.
         Refused: any index of 2^32 and more (2^32 + k wraps onto a valid
         k), negative, fractional or 2^31 (node.mesh, scene, scene.nodes,
         node.children, primitive.indices, attributes.POSITION,
         accessor.bufferView, bufferView.buffer, primitive.material);
         asset.version 1.0/3.0/10.0/0.9/1.9/"two"/"", minVersion 3.0; modes
         7/100/-1/2^32+4, only points and lines; a list not a multiple of 3;
         index values past the vertices; accessors, views and buffers out
         of range (2^53, 2^63, 2^64-1); byteStride 4, 8, 2^32; wrong types
         and component types; non-finite positions, transforms that
         overflow f32, a zero rotation; bad sparse accessors (index past
         the count, count past the accessor's, float or signed indices,
         short values, count 2^31..2^64-1); node cycles, two parents, a
         root twice; unknown required extensions; GLB truncation, version,
         length and chunk errors; bad URIs; bad JSON (100,000 nested
         arrays too); documents without triangles. Byte flips: no verdict.
amplify  small files that ask for many triangles: 2,000 to 100,000 nodes
         instancing one 10,000- or 50,000-triangle mesh (20 M to 5 G
         triangles), one mesh of 3,000 to 50,000 primitives sharing
         accessors, one TRIANGLE_STRIP of 25 M one-byte indices (first
         pass only: a 25 MB file), a 1 M-byte strip shared by 64 or 500
         primitives, an accessor without bufferView of 3e8 to 1e12 zeros,
         complete binary node trees of 32,767 and 131,071 nodes: refused
         with a message naming the file and a limit ("limit", "at most",
         "more than"...: LIMIT_RE); `--max-triangles 100` on 2,000
         triangles refused the same way. Accepted within the time limit
         and read right: 20 x 2,000 and 5 x 8,000 instances, a 20,000-
         triangle strip, and `--max-triangles 100000000`.
fifo     special files as input: a FIFO, /dev/zero, /dev/urandom, /dev/null
         (symlinks named x.obj, .ply, .glb, .gltf, .mts, .stream),
         directories and symlinks to them, /dev/zero and /dev/stdin by
         path, a .gltf whose buffer is a FIFO, /dev/zero or a directory, a
         FIFO given to `render --scene-with` and as `distance`'s reference:
         refused within 5 s naming the file, the message saying what it is
         ("not a regular file", "directory", "device"...: SPECIAL_RE); an
         OBJ whose .mtl or texture is a FIFO: accepted without
         --properties, no verdict but no hang with it.
output   every printing command (strips, simplify, info, extract, verify,
         compare, build, distance, encode, decode, render, their --json)
         with stdout on /dev/full (refused, the error naming standard
         output) and on a pipe whose read end is closed before the start
         (ends quietly: exit 0, 141 or SIGPIPE, no error text); --version,
         --help, `help build` (no verdict). `-o` naming the input itself
         (same path, ./path, a symlink, a hard link; convert to .obj, .ply,
         .glb, build, simplify, encode, extract, decode): a refusal leaves
         the input's bytes as they were, a success leaves a valid result
         (converted back: the same triangles). `-o` into a missing folder,
         a read-only one (chmod, and chattr +i as root; skipped where
         neither stops writes), onto a folder, with an unknown extension:
         refused, nothing left behind. `-o` onto an existing file when the
         input is bad, or when the write fails half-way (RLIMIT_FSIZE 2 KB,
         SIGXFSZ ignored: EFBIG): refused, the existing file unchanged,
         nothing left in its folder. `extract --ratio 0.5 -o x.ply` (.obj,
         .glb, .gltf), `decode -o`, `simplify -o`: accepted, the file reads
         back.
view     `mts view` with absurd arguments (--scene 2^64-1, 1e9, 1048577,
         2^32, -1, nan, empty; --frames -1, 2^64, nan): refused before any
         window (runs have no DISPLAY, so a window attempt shows as "wrong
         message"; VIEW_ARG_RE); view of a bad model or --scene-with file
         (refused, named). `render --scene 1/3/50` (also --pixel-error -0)
         on meshes plain `render` accepts (all vertices coincident,
         coordinates 1e20, 2.2e38, 1e-25 and denormal, one triangle): must
         be accepted like the plain render. `--pixel-error` -0, 0, 0.5,
         1000 accepted; nan, inf, -1, 1001, 1e39, -inf, empty refused.
         Runs that find no GPU adapter are "skipped".
props    --uv-weight / --normal-weight / --color-weight: nan, inf, -inf,
         -1, 1e39, empty refused; -0 (as a word and as --flag=-0), 0, 0.5
         accepted. `convert --properties` (to .obj, .glb, .gltf, .ply),
         `build`, `strips`, `simplify -o` of an OBJ whose .mtl names a
         missing texture, or is missing: accepted (a warning). glTF with
         NORMAL, TEXCOORD_0, COLOR_0 (vec3 float, vec4 u8/u16 normalized)
         and an image that is not there: accepted and read right; COLOR_0
         VEC2, NORMAL of another count or NaN, TEXCOORD_0 VEC3, texture or
         image index 2^32: refused. OBJ -> glTF/PLY -> OBJ round trip.
reseal   version-3 files (torus, optimal icosphere, one-band grid, torus
         with properties) with one field changed and the file resealed
         (V3File): a record's vertex +-1 or two swapped, a label, a code's
         distance, BREAK or MORE bit, a slot size, a band's first LoD or
         strip offset, a strip's record or beginning offset, a beginning's
         record or label, the LoD -> triangle table, a step's kept or
         removed vertex; also the vertex width re-encoded at 4 (valid) and
         the file unchanged. `verify --lods all` decides: where it refuses
         (a mismatch, or a refusal at load), `info` and `extract --ratio` /
         `--lod` must refuse too (else garbage accepted). A changed LoD ->
         triangle table must be refused by all four.
hier     version-4 files (`build --hierarchy`: a terrain, a torus with
         properties and seams; V4File) truncated, flipped, resealed
         flipped, and with one field changed and the file resealed: a HIER
         count +-1 or huge, a section's length, tag, trailing bytes,
         version (3, 5, ...) and section count; per group its record's
         length +-1, a list count huge, a NaN radius or floor, another
         floor, an input cluster, its children, the own-vertices flag (all
         refused by `info` and `verify`); a vertex-map entry or a flip in
         a group's model sections (possibly valid: `verify` sweeps
         cameras for cracks). `extract` must refuse every one (a
         hierarchy is not a model) naming the file.
coded    version-5 files (`mts build`'s default: a torus, an
         optimal-placement icosphere at level 3, a torus with properties;
         V5File) truncated, flipped, resealed flipped, and with one field
         changed and the file resealed: a section's part count, a part's
         decoded length (+-1, doubled, huge), its coding byte, a
         transposed part's row width (or a plain frame called transposed),
         a coded part called stored, a byte flipped in a Zstandard frame or the frame
         cut, MODL's parts swapped, a hand-made frame of RLE blocks (a
         "bomb": kilobytes decoding to up to 256 MiB, announced honestly
         or not), the section count, trailing bytes. All refused by
         `verify`, `info` and `extract` but a flip in a frame, which
         `verify` decides.
meshopt  glTF whose buffer views are compressed with EXT_meshopt_compression
         (`mts convert --compress`: a torus with properties, one without,
         one of 140k triangles with 32-bit indices; MeshoptDoc) or
         KHR_meshopt_compression, read by `convert -o x.obj` and one of
         convert to .ply, strips, build, encode (not build or encode on the
         140k seed). Accepted and read right (the triangles of the seed's
         `--quantize` twin): the seed as written (.glb, and .gltf + .bin),
         rewritten with input.bin or a data URI, with KHR_ for EXT_, integers
         written as floats (8.0), a good KHR_ object beside a bogus EXT_ one
         (KHR_ wins), two streams of one layout swapped, a hand-made stream
         of zeros (version 0, or version 1 under KHR_: 64 x and 1024 x; up
         to 4 M elements) for a view whose zeros leave the mesh valid, the
         compressed bytes in buffer 1 given data. Refused naming the view
         ("bufferView N", MO_VIEW_RE): a count of 2^32 to 2^64-1 with the
         view's byteLength made stride x count (where the rules let it
         through, refused by the expansion bound or the limit as well:
         MO_LIMIT_RE), zero streams announcing 2^26 or 2^28 elements, more
         than --max-triangles allows, or 2^30 from 4,096 (these runs under
         a 512 MB address-space cap and 5 s: MO_AMPLIFY); byteLength or
         byteOffset past buffer 0; byteStride 0, 2, 3, 6, 10, 258, 260...
         for attributes, 0, 1, 3, 6, 8, 16 for indices; unknown modes; a
         stream decoded with another codec; filters the mode or stride
         forbids, unknown ones, COLOR under EXT_; a TRIANGLES count not a
         multiple of 3; the view's own byteLength not stride x count, or its
         byteStride another; negative, fractional, string, null, boolean,
         array, object, 1e300, 2^53 and 2^64 values, missing fields; a
         missing buffer; an attribute stream one byte short or long; buffer
         0 cut short. Refused naming the file: the views reading the
         fallback (no data: the primitive skipped, no triangles left) or
         zeros in it, a count below the accessor's, an extension name
         misspelled in a view or in extensionsRequired. No verdict: byte
         flips and splices in a stream, an index stream cut or extended, a
         larger count, another allowed filter, random bytes in the
         fallback, a fallback uri that cannot be read (missing, malformed, a
         FIFO, a directory, /dev/zero: never loaded, never a hang), the
         views under one name and extensionsUsed under the other.

Checksums (read from src/model/format.rs and src/baselines/cluster/stream.rs):
.mts: header "MTSMODEL" | version u32 | section count u32 | file length u64
| FNV-1a/64 (offset basis 0xcbf29ce484222325, prime 0x100000001b3) of every
byte after the 32-byte header (versions 3 and 4: its four-lane word form,
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
                  SIGKILL (the address-space cap, RLIMIT_AS = --mem-gb, or
                  a run's own lower one: meshopt's MO_AMPLIFY).
panic             "panicked at" / "has overflowed its stack" in stderr, or
                  death by any other signal (SIGABRT, SIGSEGV, ...).
garbage accepted  exit 0 on an input the CLI must refuse (truncated .mts,
                  unresealed flips, out-of-range indices, NaN arguments...).
ok                exit 0 on a valid or possibly valid input.
valid refused     non-zero exit on an input that must be accepted (the
                  issue-31 families' ACCEPT), or a closed-pipe run that did
                  not end quietly.
wrong message     a refusal without what the case requires: one `error:`
                  line for a full stdout, no limit named
                  (amplify), not saying the file is special (fifo), a view
                  argument not refused before the window; or error text
                  on a closed pipe. clap's "unexpected argument" never
                  counts as the required message.
wrong result      the exit status is right but the files are not: the mesh
                  read differs from the one written, an input destroyed by
                  `-o` naming it, an existing output changed by a failed
                  run, a file left behind by one.
unnamed error     non-zero exit, no panic, but stderr does not name the
                  input file under test (only checked for file inputs; the
                  issue-31 families may name other accepted names, such as
                  "standard output" or the output path).
clean error       non-zero exit, no panic, the input file named.
skipped           the environment cannot run it (no GPU adapter, no way to
                  make a folder read-only, an input that could not be made).
For file errors (clean or unnamed) the harness also records whether the
message names a place: "line N", "byte N", "offset N", "column N", or an
element and index ("vertex 3", "face 12", "step 4", "strip index 7", ...).

Runs use a copy of the binary taken at the start (its sha1 is reported),
have stdin on /dev/null, stdout discarded (unless the case says /dev/full
or a closed pipe), no DISPLAY, RUST_BACKTRACE=0, their own process group
and working directory. Exit status: 0 when no run is a panic, hang, oom,
garbage accepted, valid refused, wrong message or wrong result; 1
otherwise; 2 when the harness cannot run (binary missing, seeds cannot be
made, a seed's layout is not the one the harness knows).
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

# The issue-19 families, then the issue-31 ones (and issue 33's hier, issue
# 34's coded, issue 35's meshopt).
OLD_FAMILIES = ["obj", "ply", "mts", "stream", "args", "extreme"]
NEW_FAMILIES = ["gltf", "amplify", "fifo", "output", "view", "props", "reseal", "hier", "coded", "meshopt"]
FAMILIES = OLD_FAMILIES + NEW_FAMILIES
# Share of the inputs per family.
WEIGHTS = {"obj": 26, "ply": 25, "mts": 19, "stream": 15, "extreme": 9, "args": 6,
           "gltf": 14, "amplify": 1, "fifo": 2, "output": 6, "view": 2, "props": 3, "reseal": 9, "hier": 6,
           "coded": 6, "meshopt": 6}
DEFAULT_COUNT = 3700
QUICK_COUNT = 600  # the issue-19 families' share of --quick
# --quick: a fixed slice of each issue-31 family, after those 600 inputs.
QUICK_SLICE = {"gltf": 36, "amplify": 4, "fifo": 10, "output": 64, "view": 10, "props": 13, "reseal": 24,
               "hier": 24, "coded": 24, "meshopt": 24}
QUICK_SEED = 19
QUICK_TIMEOUT = 10

# VALID: valid or possibly valid (issue 19: exit 0 is "ok", a refusal is
# not counted against the CLI); ACCEPT: valid, must be accepted.
GARBAGE, VALID, UNKNOWN, ACCEPT = "garbage", "valid", "unknown", "accept"
# A resealed ready file that lies only where loading's documented sample
# does not look (crates/mts/src/model/digest.rs: LoD 0 and one LoD drawn per
# load are compared with the recipe): accepted, it is counted, not failed.
TRUSTED = "trusted"
CLASSES = ["clean error", "ok", "panic", "hang", "oom", "garbage accepted", "valid refused", "wrong message",
           "wrong result", "unnamed error", "skipped", "trusted lie"]
FAILING = ("panic", "hang", "oom", "garbage accepted", "valid refused", "wrong message", "wrong result")

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
        self.path = path  # a fixed path (/dev/zero, "{dir}/x") instead of data
        # (argv with "{in}"/"{out}"/"{outK}"/"{dir}"/"{seed:*}", expect,
        # names_target, options): see run_case for the options.
        self.runs = []
        # Files made in the case directory before the runs, in order: (name,
        # bytes | ("fifo",) | ("dir",) | ("rodir",) | ("symlink", target) |
        # ("hardlink", existing name)).
        self.files = []

    def run(self, argv, expect, target=True, **opts):
        """expect: GARBAGE, VALID, UNKNOWN, ACCEPT, or a function of the
        case's results so far that returns one (or None: the run is
        skipped, its input was not made)."""
        self.runs.append((argv, expect, target, opts))


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
        case.runs[1] = (["build", "{in}", "--weld", "-o", "{out}.mts"], expect, True, {})
    if ext in (".mts", ".stream", "") or ext is None:
        case.run(["info", "{in}"], expect)
        case.run(["decode", "{in}"], expect)
    return case


# --------------------------------------------------------------------------
# Issue 31: glTF documents, amplification, special files, outputs, view
# arguments, properties and resealed version-3 files.
#
# Expectations are stricter here: ACCEPT means the input is valid and must
# be accepted (a refusal is "valid refused"), and a run may carry a message
# it must give when it refuses (`must`, else "wrong message"), the names one
# of which the error must give (else "unnamed error"), and a check of the
# files it leaves behind (`post`, else "wrong result").

F32, U8, U16, U32, I8, I16 = 5126, 5121, 5123, 5125, 5120, 5122
CFMT = {I8: "b", U8: "B", I16: "h", U16: "H", U32: "I", F32: "f"}
LIMIT_RE = r"(?i)limit|at most|the most|more than|too many|exceed"
SPECIAL_RE = r"(?i)regular file|not a file|directory|device|fifo|pipe|special"
VIEW_ARG_RE = r"(?i)outside|invalid value|\.\.=|at most|too many|limit|exceed|not a whole number|between"


class Gltf:
    """A glTF 2.0 document under construction: JSON plus one binary buffer
    (the GLB BIN chunk, a data URI or a .bin file, chosen when written)."""

    def __init__(self):
        self.j = collections.OrderedDict()
        self.j["asset"] = {"version": "2.0", "generator": "mts hostile.py"}
        for k in ("scenes", "nodes", "meshes", "materials", "accessors", "bufferViews", "buffers"):
            self.j[k] = []
        self.j["materials"].append({"pbrMetallicRoughness": {"baseColorFactor": [1.0, 1.0, 1.0, 1.0]}})
        self.bin = bytearray()

    def view(self, data, target=None, stride=None):
        while len(self.bin) % 4:
            self.bin.append(0)
        v = {"buffer": 0, "byteOffset": len(self.bin), "byteLength": len(data)}
        if stride:
            v["byteStride"] = stride
        if target:
            v["target"] = target
        self.bin += data
        self.j["bufferViews"].append(v)
        return len(self.j["bufferViews"]) - 1

    def accessor(self, view, ctype, typ, count, **extra):
        a = {"componentType": ctype, "type": typ, "count": count}
        if view is not None:
            a["bufferView"] = view
        a.update(extra)
        self.j["accessors"].append(a)
        return len(self.j["accessors"]) - 1

    def positions(self, pos):
        data = struct.pack("<%df" % (3 * len(pos)), *[c for p in pos for c in p])
        v = self.view(data, 34962)
        lo = [min(p[i] for p in pos) for i in range(3)]
        hi = [max(p[i] for p in pos) for i in range(3)]
        return self.accessor(v, F32, "VEC3", len(pos), min=lo, max=hi)

    def indices(self, idx, ctype=U16):
        data = struct.pack("<%d%s" % (len(idx), CFMT[ctype]), *idx)
        v = self.view(data, 34963)
        return self.accessor(v, ctype, "SCALAR", len(idx))

    def mesh(self, primitives):
        self.j["meshes"].append({"primitives": primitives})
        return len(self.j["meshes"]) - 1

    def node(self, **kw):
        self.j["nodes"].append(dict(kw))
        return len(self.j["nodes"]) - 1

    def scene(self, nodes):
        self.j["scenes"].append({"nodes": list(nodes)})
        return len(self.j["scenes"]) - 1

    def set_buffer(self, style, bin_name="input.bin"):
        """Declares buffer 0 for `style` (glb, datauri, external); done
        before any mutation of the JSON so that buffer fields can be
        mutated too."""
        b = {"byteLength": len(self.bin)}
        if style == "datauri":
            import base64
            b["uri"] = "data:application/octet-stream;base64," + base64.b64encode(bytes(self.bin)).decode()
        elif style == "external":
            b["uri"] = bin_name
        self.j["buffers"] = [b] if self.bin or style != "glb" else []
        if not self.j["buffers"]:
            del self.j["buffers"]

    def text(self):
        j = collections.OrderedDict((k, v) for k, v in self.j.items() if not (isinstance(v, list) and not v))
        return json.dumps(j).encode()

    def files(self, style, bin_name="input.bin"):
        """(main file bytes, {extra file name: bytes})."""
        if style == "glb":
            return glb_pack(self.text(), bytes(self.bin) if self.bin else None), {}
        if style == "external":
            return self.text(), {bin_name: bytes(self.bin)}
        return self.text(), {}


def glb_pack(text, binary, extra_chunks=(), json_pad=b" "):
    body = bytearray()
    t = text + json_pad * ((-len(text)) % 4)
    body += struct.pack("<I4s", len(t), b"JSON") + t
    if binary is not None:
        b = binary + b"\0" * ((-len(binary)) % 4)
        body += struct.pack("<I4s", len(b), b"BIN\0") + b
    for kind, data in extra_chunks:
        d = data + b"\0" * ((-len(data)) % 4)
        body += struct.pack("<I4s", len(d), kind) + d
    return b"glTF" + struct.pack("<II", 2, 12 + len(body)) + bytes(body)


def hf_grid(n, m):
    """A height field of exact binary fractions: (n+1)(m+1) vertices, 2nm
    triangles, vertex 0 at the origin, no two vertices alike."""
    pos = [(i / 8, j / 8, ((i * 7 + j * 3) % 5) / 16) for j in range(m + 1) for i in range(n + 1)]
    tris = []
    for j in range(m):
        for i in range(n):
            a = j * (n + 1) + i
            b, c, d = a + 1, a + n + 2, a + n + 1
            tris.append((a, b, c))
            tris.append((a, c, d))
    return pos, tris


def strip_indices(n, m):
    """A grid's rows as one triangle strip joined by repeated indices."""
    out = []
    for j in range(m):
        row = []
        for i in range(n + 1):
            row += [j * (n + 1) + i, (j + 1) * (n + 1) + i]
        if out:
            out += [out[-1], row[0]]
            if len(out) % 2:  # keep the next row's parity
                out.append(row[0])
        out += row
    return out


def topology(mode, ix):
    """The glTF 2.0 specification's triangles of an index list (3.7.2.1):
    strip p_i = (v_i, v_{i+1+i%2}, v_{i+2-i%2}), fan p_i = (v_{i+1},
    v_{i+2}, v_0); triangles repeating an index are dropped."""
    tris = []
    if mode == 4:
        tris = [tuple(ix[i : i + 3]) for i in range(0, len(ix) - 2, 3)]
    elif mode == 5:
        tris = [(ix[i], ix[i + 1 + i % 2], ix[i + 2 - i % 2]) for i in range(len(ix) - 2)]
    elif mode == 6:
        tris = [(ix[i + 1], ix[i + 2], ix[0]) for i in range(len(ix) - 2)]
    return [t for t in tris if len(set(t)) == 3]


def mat_mul(a, b):
    return [[sum(a[r][k] * b[k][c] for k in range(4)) for c in range(4)] for r in range(4)]


IDENTITY4 = [[1.0 if r == c else 0.0 for c in range(4)] for r in range(4)]


def trs_matrix(t=(0, 0, 0), q=(0, 0, 0, 1), s=(1, 1, 1)):
    x, y, z, w = q
    r = [[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
         [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
         [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]]
    m = [[r[i][k] * s[k] for k in range(3)] + [t[i]] for i in range(3)]
    return m + [[0.0, 0.0, 0.0, 1.0]]


def col_major(m):
    return [m[r][c] for c in range(4) for r in range(4)]


def det3(m):
    return (m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
            + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]))


def tri_keys(pos, tris, mat=None, into=None):
    """A multiset of triangles as position triples (1/1024 grid), each
    turned to start at its smallest corner (orientation kept); under `mat`
    with a negative determinant the winding is flipped, as a reader
    flips it."""
    c = into if into is not None else collections.Counter()
    if mat is not None and mat != IDENTITY4:
        pts = [tuple(sum(mat[r][k] * p[k] for k in range(3)) + mat[r][3] for r in range(3)) for p in pos]
        flip = det3(mat) < 0
    else:
        pts, flip = pos, False
    keys = [tuple(int(round(x * 1024)) for x in p) for p in pts]
    for t in tris:
        k = [keys[t[0]], keys[t[2]], keys[t[1]]] if flip else [keys[i] for i in t]
        r = k.index(min(k))
        c[tuple(k[r:] + k[:r])] += 1
    return c


def read_obj_mesh(path):
    """Positions and triangles of an OBJ written by `mts convert` (polygons
    fanned)."""
    pos, tris = [], []
    with open(path, "rb") as f:
        for line in f:
            w = line.split()
            if not w:
                continue
            if w[0] == b"v":
                pos.append(tuple(float(x) for x in w[1:4]))
            elif w[0] == b"f":
                ix = []
                for t in w[1:]:
                    i = int(t.split(b"/")[0])
                    ix.append(i - 1 if i > 0 else len(pos) + i)
                for k in range(1, len(ix) - 1):
                    tris.append((ix[0], ix[k], ix[k + 1]))
    return pos, tris


def obj_check(expected, what="the generator wrote"):
    """A post check of `convert {in} -o {out}.obj`: the triangles read are
    the ones `expected` (a tri_keys Counter) holds."""
    def post(env):
        if env.rc != 0:
            return None
        path = env.out + ".obj"
        try:
            pos, tris = read_obj_mesh(path)
            got = tri_keys(pos, tris)
        except (OSError, ValueError, IndexError) as e:
            return "the written OBJ cannot be read back: %s" % e
        if got == expected:
            return None
        missing, extra = expected - got, got - expected
        return "read %d triangles where %s %d (%d missing, %d not written)" % (
            sum(got.values()), what, sum(expected.values()), sum(missing.values()), sum(extra.values()))
    return post


def mesh_gltf(n=6, m=4, ctype=U16, mode=4, g=None):
    """A document with one mesh (a height field), one node, one scene; the
    expected triangle multiset."""
    g = g or Gltf()
    pos, tris = hf_grid(n, m)
    pa = g.positions(pos)
    if mode == 4:
        ix = [i for t in tris for i in t]
    elif mode == 5:
        ix = strip_indices(n, m)
    else:
        raise ValueError(mode)
    prim = {"attributes": {"POSITION": pa}, "mode": mode, "material": 0}
    if ctype is not None:
        prim["indices"] = g.indices(ix, ctype)
        exp_tris = topology(mode, ix)
    else:
        # No indices: vertices in order, so the positions are laid out per
        # corner.
        flat = [pos[i] for i in ix]
        g = Gltf()
        pa = g.positions(flat)
        prim = {"attributes": {"POSITION": pa}, "mode": mode, "material": 0}
        pos = flat
        exp_tris = topology(mode, list(range(len(flat))))
    g.mesh([prim])
    g.scene([g.node(mesh=0)])
    g.j["scene"] = 0
    return g, pos, exp_tris


def fan_gltf(ctype=U8):
    g = Gltf()
    ring = [(3, 0), (2, 2), (0, 3), (-2, 2), (-3, 0), (-2, -2), (0, -3), (2, -2)]
    pos = [(0.0, 0.0, 0.5)] + [(x / 4, y / 4, 0.0) for x, y in ring]
    ix = [0] + list(range(1, len(pos))) + [1]
    pa = g.positions(pos)
    g.mesh([{"attributes": {"POSITION": pa}, "indices": g.indices(ix, ctype), "mode": 6}])
    g.scene([g.node(mesh=0)])
    return g, pos, topology(6, ix)


class GCase:
    """What a glTF generator returns: the builder (or raw bytes), the style,
    the expectation, the expected triangles (for ACCEPT) and a kind."""

    def __init__(self, kind, expect, g=None, style="glb", expected=None, raw=None, extra=None, ext=None,
                 names=None):
        self.kind, self.expect, self.g, self.style = kind, expect, g, style
        self.expected, self.raw, self.extra, self.ext = expected, raw, extra or {}, ext
        self.names = names


def gltf_style(rng):
    return rng.choice(["glb", "glb", "datauri", "external"])


def gen_gltf_case(rng, kind):
    """One glTF input of `kind` (see GLTF_KINDS)."""
    style = gltf_style(rng)
    if kind == "plain":
        ctype = rng.choice([U8, U16, U32, None])
        g, pos, tris = mesh_gltf(6, 4, ctype)
        return GCase("plain:%s/%s" % ({U8: "u8", U16: "u16", U32: "u32", None: "unindexed"}[ctype], style),
                     ACCEPT, g, style, tri_keys(pos, tris))
    if kind == "mode_strip":
        ctype = rng.choice([U8, U16, U32])
        g, pos, tris = mesh_gltf(rng.choice([5, 8]), rng.choice([3, 4]), ctype, mode=5)
        return GCase("mode_strip/%s" % style, ACCEPT, g, style, tri_keys(pos, tris))
    if kind == "mode_fan":
        g, pos, tris = fan_gltf(rng.choice([U8, U16, U32]))
        return GCase("mode_fan/%s" % style, ACCEPT, g, style, tri_keys(pos, tris))
    if kind == "mixed_modes":
        g, pos, tris = mesh_gltf(5, 3, U16)
        pa = g.j["meshes"][0]["primitives"][0]["attributes"]["POSITION"]
        others = []
        for mode in rng.sample([0, 1, 2, 3], rng.randint(1, 4)):
            others.append({"attributes": {"POSITION": pa}, "indices": g.indices([0, 1, 2, 3, 4, 5], U16), "mode": mode})
        prims = g.j["meshes"][0]["primitives"] + others
        rng.shuffle(prims)
        g.j["meshes"][0]["primitives"] = prims
        return GCase("mixed_modes/%s" % style, ACCEPT, g, style, tri_keys(pos, tris))
    if kind == "transform":
        g, pos, tris = mesh_gltf(4, 3, U16)
        g.j["nodes"], g.j["scenes"] = [], []
        expected = collections.Counter()
        roots = []
        for k in range(rng.randint(1, 4)):
            t = (k * 4.0, rng.choice([0.0, 0.5, -2.0]), rng.choice([0.0, 0.125]))
            s = rng.choice([(1, 1, 1), (2, 2, 2), (0.5, 1, 2), (-1, 1, 1), (1, -2, 1)])
            q = rng.choice([(0, 0, 0, 1), (0, 0, math.sqrt(0.5), math.sqrt(0.5)), (1, 0, 0, 0)])
            local = trs_matrix(t, q, s)
            how = rng.choice(["trs", "matrix", "child"])
            if how == "trs":
                n = g.node(mesh=0, translation=list(t), rotation=list(q), scale=list(s))
                world = local
            elif how == "matrix":
                n = g.node(mesh=0, matrix=col_major(local))
                world = local
            else:
                c = g.node(mesh=0, scale=[1, 1, 0.5])
                n = g.node(children=[c], translation=list(t), rotation=list(q), scale=list(s))
                world = mat_mul(local, trs_matrix(s=(1, 1, 0.5)))
            roots.append(n)
            tri_keys(pos, tris, world, expected)
        g.scene(roots)
        g.j["scene"] = 0
        return GCase("transform/%s" % style, ACCEPT, g, style, expected)
    if kind == "scene_select":
        g, pos, tris = mesh_gltf(4, 3, U16)
        g.node(mesh=0, translation=[10.0, 0.0, 0.0])
        g.scene([1])
        g.j["scene"] = 1
        return GCase("scene_select/%s" % style, ACCEPT, g, style, tri_keys(pos, tris, trs_matrix((10.0, 0, 0))))
    if kind == "no_nodes":
        g, pos, tris = mesh_gltf(4, 3, U16)
        del g.j["scene"]
        g.j["nodes"], g.j["scenes"] = [], []
        return GCase("no_nodes/%s" % style, ACCEPT, g, style, tri_keys(pos, tris))
    if kind == "roots_no_scene":
        g, pos, tris = mesh_gltf(4, 3, U16)
        del g.j["scene"]
        g.j["scenes"] = []
        g.node(children=[g.node(mesh=0, translation=[0.0, 8.0, 0.0])])
        e = tri_keys(pos, tris)
        tri_keys(pos, tris, trs_matrix((0, 8.0, 0)), e)
        return GCase("roots_no_scene/%s" % style, ACCEPT, g, style, e)
    if kind in ("sparse_view", "sparse_noview"):
        ctype = rng.choice([U8, U16, U32])
        g = Gltf()
        pos, tris = hf_grid(7, 5)
        new = list(pos)
        if kind == "sparse_view":
            ids = sorted(rng.sample(range(len(pos)), rng.randint(1, 6)))
            for i in ids:
                new[i] = (pos[i][0], pos[i][1], pos[i][2] + 0.25)
            base = g.view(struct.pack("<%df" % (3 * len(pos)), *[c for p in pos for c in p]), 34962)
        else:
            ids = list(range(1, len(pos)))  # vertex 0 is the origin: zeros
            base = None
        vals = [c for i in ids for c in new[i]]
        iv = g.view(struct.pack("<%d%s" % (len(ids), CFMT[ctype]), *ids))
        vv = g.view(struct.pack("<%df" % len(vals), *vals))
        lo = [min(p[i] for p in new) for i in range(3)]
        hi = [max(p[i] for p in new) for i in range(3)]
        pa = g.accessor(base, F32, "VEC3", len(pos), min=lo, max=hi,
                        sparse={"count": len(ids), "indices": {"bufferView": iv, "componentType": ctype},
                                "values": {"bufferView": vv}})
        ix = [i for t in tris for i in t]
        g.mesh([{"attributes": {"POSITION": pa}, "indices": g.indices(ix, U16)}])
        g.scene([g.node(mesh=0)])
        name = {U8: "u8", U16: "u16", U32: "u32"}[ctype]
        return GCase("%s:%s/%s" % (kind, name, style), ACCEPT, g, style, tri_keys(new, tris))
    if kind == "extras":
        g, pos, tris = mesh_gltf(4, 3, U16)
        g.set_buffer(style)
        values = [[1, 2, 3], "hello", 3, None, {"a": {"b": [True, False, None]}}, 1.5e300, -0.0, "", [], {}, False]
        places = ["root", "asset", "scene", "node", "mesh", "primitive", "accessor", "bufferView", "buffer", "material"]
        chosen = rng.sample(places, rng.randint(1, 4))
        for p in chosen:
            v = rng.choice(values)
            obj = {"root": g.j, "asset": g.j["asset"], "scene": g.j["scenes"][0], "node": g.j["nodes"][0],
                   "mesh": g.j["meshes"][0], "primitive": g.j["meshes"][0]["primitives"][0],
                   "accessor": g.j["accessors"][0], "bufferView": g.j["bufferViews"][0],
                   "buffer": g.j["buffers"][0], "material": g.j["materials"][0]}[p]
            obj["extras"] = v
        return GCase("extras:%s/%s" % ("+".join(sorted(chosen)), style), ACCEPT, g, style, tri_keys(pos, tris))
    if kind == "extensions_unknown":
        g, pos, tris = mesh_gltf(4, 3, U16)
        g.j["extensionsUsed"] = ["EXT_hostile_unknown"]
        g.j["nodes"][0]["extensions"] = {"EXT_hostile_unknown": {"x": [1, 2]}}
        g.j["meshes"][0]["primitives"][0]["extensions"] = {"EXT_hostile_unknown": None}
        return GCase("extensions_unknown/%s" % style, ACCEPT, g, style, tri_keys(pos, tris))
    if kind == "required_ext":
        g, pos, tris = mesh_gltf(4, 3, U16)
        ext = rng.choice(["EXT_hostile_unknown", "KHR_draco_mesh_compression", "KHR_mesh_quantization"])
        g.j["extensionsUsed"] = [ext]
        g.j["extensionsRequired"] = [ext]
        if ext == "KHR_mesh_quantization":
            return GCase("required_ext:quantization/%s" % style, ACCEPT, g, style, tri_keys(pos, tris))
        return GCase("required_ext:unknown/%s" % style, GARBAGE, g, style)
    if kind == "version":
        g, pos, tris = mesh_gltf(4, 3, U16)
        v, e = rng.choice([("2.0", ACCEPT), ("2.1", ACCEPT), ("2.99", ACCEPT), ("3.0", GARBAGE), ("1.0", GARBAGE),
                           ("10.0", GARBAGE), ("1.9", GARBAGE), ("0.9", GARBAGE), ("two", GARBAGE), ("", GARBAGE),
                           ("3", UNKNOWN), ("2", UNKNOWN), ("2.0.1", UNKNOWN), (None, UNKNOWN)])
        minv = rng.choice([None, None, "2.0", "2.1", "3.0"])
        if v is None:
            del g.j["asset"]["version"]
        else:
            g.j["asset"]["version"] = v
        if minv:
            g.j["asset"]["minVersion"] = minv
            if minv == "3.0":
                e = GARBAGE
            elif minv == "2.1" and e == ACCEPT:
                e = UNKNOWN  # a 2.0 reader may refuse what needs 2.1
        label = "%s/%s" % ("missing" if v is None else v or "empty", "min" + minv if minv else "")
        group = {ACCEPT: "2.x", GARBAGE: "not-2.x", UNKNOWN: "odd"}[e]
        if minv == "3.0":
            group = "min-3.0"
        return GCase("version:%s/%s/%s" % (group, label, style), e, g, style,
                     tri_keys(pos, tris) if e == ACCEPT else None)
    if kind == "glb_padding":
        g, pos, tris = mesh_gltf(4, 3, U16)
        g.set_buffer("glb")
        raw = glb_pack(g.text() + b"   \n", bytes(g.bin), extra_chunks=[(b"XTRA", b"\x01\x02\x03")])
        return GCase("glb_padding", ACCEPT, raw=raw, expected=tri_keys(pos, tris), ext=".glb")
    if kind == "stride":
        g = Gltf()
        pos, tris = hf_grid(5, 3)
        stride = rng.choice([16, 20, 24, 252])
        data = b"".join(struct.pack("<3f", *p) + b"\xab" * (stride - 12) for p in pos)
        v = g.view(data, 34962, stride=stride)
        pa = g.accessor(v, F32, "VEC3", len(pos), min=[min(p[i] for p in pos) for i in range(3)],
                        max=[max(p[i] for p in pos) for i in range(3)])
        g.mesh([{"attributes": {"POSITION": pa}, "indices": g.indices([i for t in tris for i in t], U16)}])
        g.scene([g.node(mesh=0)])
        return GCase("stride:%d/%s" % (stride, style), ACCEPT, g, style, tri_keys(pos, tris))
    if kind == "deep_chain":
        g, pos, tris = mesh_gltf(3, 2, U16)
        depth = rng.choice([2000, 20000, 60000])
        g.j["nodes"] = [{"children": [i + 1], "translation": [0.125, 0.0, 0.0]} for i in range(depth - 1)]
        g.j["nodes"].append({"mesh": 0, "translation": [0.125, 0.0, 0.0]})
        g.j["scenes"] = [{"nodes": [0]}]
        return GCase("deep_chain:%d/%s" % (depth, style), ACCEPT, g, style,
                     tri_keys(pos, tris, trs_matrix((0.125 * depth, 0.0, 0.0))))
    if kind == "many_roots":
        g, pos, tris = mesh_gltf(3, 2, U16)
        n = rng.choice([1000, 20000])
        g.j["nodes"] = [{} for _ in range(n)] + [{"mesh": 0}]
        g.j["scenes"] = [{"nodes": list(range(n + 1))}]
        return GCase("many_roots:%d/%s" % (n, style), ACCEPT, g, style, tri_keys(pos, tris))
    if kind == "shared_accessor":
        g, pos, tris = mesh_gltf(4, 4, U16)
        prim = g.j["meshes"][0]["primitives"][0]
        ix = [i for t in tris for i in t]
        half = (len(tris) // 2) * 3
        a1 = g.indices(ix[:half], U32)
        a2 = g.indices(ix[half:], U8)
        g.j["meshes"][0]["primitives"] = [dict(prim, indices=a1), dict(prim, indices=a2)]
        return GCase("shared_accessor/%s" % style, ACCEPT, g, style, tri_keys(pos, tris))

    # Garbage.
    if kind == "index_2_32":
        g, pos, tris = mesh_gltf(4, 3, U16)
        g.node(mesh=0)  # node 1 unused: children can name it
        g.set_buffer(style)
        field = rng.choice(["node.mesh", "scene", "scene.nodes", "node.children", "primitive.indices",
                            "attributes.POSITION", "accessor.bufferView", "bufferView.buffer", "primitive.material"])
        v = rng.choice([2 ** 32, 2 ** 32 + 1, 2 ** 33, 2 ** 32 * 3, 2 ** 63, 2 ** 64, 2 ** 64 + 1, 2 ** 31,
                        10 ** 30, -1, -(2 ** 32), 1.5, 1e300, "0"])
        prim = g.j["meshes"][0]["primitives"][0]
        if field == "node.mesh":
            g.j["nodes"][0]["mesh"] = v
        elif field == "scene":
            g.j["scene"] = v
        elif field == "scene.nodes":
            g.j["scenes"][0]["nodes"] = [v]
        elif field == "node.children":
            g.j["nodes"][0]["children"] = [v]
        elif field == "primitive.indices":
            prim["indices"] = v
        elif field == "attributes.POSITION":
            prim["attributes"]["POSITION"] = v
        elif field == "accessor.bufferView":
            g.j["accessors"][rng.randrange(2)]["bufferView"] = v
        elif field == "bufferView.buffer":
            g.j["bufferViews"][rng.randrange(2)]["buffer"] = v
        else:
            prim["material"] = v
        return GCase("index_2_32:%s/%s/%s" % (field, v, style), GARBAGE, g, style)
    if kind == "mode_bad":
        g, pos, tris = mesh_gltf(4, 3, U16)
        prim = g.j["meshes"][0]["primitives"][0]
        v = rng.choice([7, 100, -1, 2 ** 32 + 4, "4", 4.5, None])
        if v is None:  # only points and lines: nothing to read
            prim["mode"] = rng.choice([0, 1, 2, 3])
            return GCase("mode_bad:no_triangles/%s" % style, GARBAGE, g, style)
        prim["mode"] = v
        return GCase("mode_bad/%s/%s" % (v, style), GARBAGE, g, style)
    if kind == "tri_count":
        g = Gltf()
        pos, tris = hf_grid(4, 3)
        ix = [i for t in tris for i in t][: -rng.choice([1, 2])]
        pa = g.positions(pos)
        g.mesh([{"attributes": {"POSITION": pa}, "indices": g.indices(ix, U16)}])
        g.scene([g.node(mesh=0)])
        return GCase("tri_count/%s" % style, GARBAGE, g, style)
    if kind == "index_value":
        ctype = rng.choice([U8, U16, U32])
        g = Gltf()
        pos, tris = hf_grid(4, 3)
        ix = [i for t in tris for i in t]
        ix[rng.randrange(len(ix))] = rng.choice([len(pos), len(pos) + 1, {U8: 255, U16: 65535, U32: 2 ** 32 - 1}[ctype]])
        pa = g.positions(pos)
        g.mesh([{"attributes": {"POSITION": pa}, "indices": g.indices(ix, ctype), "mode": rng.choice([4, 5, 6])}])
        g.scene([g.node(mesh=0)])
        return GCase("index_value/%s" % style, GARBAGE, g, style)
    if kind == "accessor_range":
        g, pos, tris = mesh_gltf(4, 3, U16)
        a = g.j["accessors"][rng.randrange(2)]
        what = rng.choice(["offset", "count", "offset_huge", "count_huge"])
        if what == "offset":
            a["byteOffset"] = rng.choice([4, 12, 1000])
        elif what == "count":
            a["count"] += rng.choice([1, 3, 1000])
        elif what == "offset_huge":
            a["byteOffset"] = rng.choice([2 ** 32, 2 ** 53, 2 ** 63 - 1, 2 ** 64 - 4])
        else:
            a["count"] = rng.choice([2 ** 31, 2 ** 32 - 1, 2 ** 32 + 3, 2 ** 62, 2 ** 64 - 1])
        return GCase("accessor_range:%s/%s" % (what, style), GARBAGE, g, style)
    if kind == "view_range":
        g, pos, tris = mesh_gltf(4, 3, U16)
        v = g.j["bufferViews"][rng.randrange(2)]
        what = rng.choice(["length", "offset", "offset_huge", "length_huge"])
        if what == "length":
            v["byteLength"] += len(g.bin)
        elif what == "offset":
            v["byteOffset"] += len(g.bin)
        elif what == "offset_huge":
            v["byteOffset"] = rng.choice([2 ** 63, 2 ** 64 - 1, 2 ** 32])
        else:
            v["byteLength"] = rng.choice([2 ** 63, 2 ** 64 - 1, 2 ** 32])
        return GCase("view_range:%s/%s" % (what, style), GARBAGE, g, style)
    if kind == "buffer_short":
        g, pos, tris = mesh_gltf(4, 3, U16)
        g.set_buffer(style)
        g.j["buffers"][0]["byteLength"] = len(g.bin) + rng.choice([1, 4, 2 ** 40, 2 ** 64 - 1])
        return GCase("buffer_short/%s" % style, GARBAGE, g, style)
    if kind == "stride_bad":
        g = Gltf()
        pos, tris = hf_grid(4, 3)
        stride, e = rng.choice([(4, GARBAGE), (8, GARBAGE), (2 ** 32, GARBAGE), (2 ** 32 + 16, GARBAGE),
                                (13, UNKNOWN), (256, UNKNOWN)])
        s = max(12, min(stride, 300))
        data = b"".join(struct.pack("<3f", *p) + b"\0" * (s - 12) for p in pos)
        v = g.view(data, 34962, stride=stride)
        pa = g.accessor(v, F32, "VEC3", len(pos))
        g.mesh([{"attributes": {"POSITION": pa}, "indices": g.indices([i for t in tris for i in t], U16)}])
        g.scene([g.node(mesh=0)])
        return GCase("stride_bad:%d/%s" % (stride, style), e, g, style)
    if kind == "type_bad":
        g, pos, tris = mesh_gltf(4, 3, U16)
        a = rng.choice(["position_type", "position_ctype", "index_ctype", "index_type", "ctype_unknown"])
        acc = g.j["accessors"]
        if a == "position_type":
            acc[0]["type"] = rng.choice(["VEC2", "SCALAR", "MAT4", "VEC5", ""])
        elif a == "position_ctype":
            acc[0]["componentType"] = rng.choice([5130, 5124, 0])
        elif a == "index_ctype":
            acc[1]["componentType"] = rng.choice([F32, I16, I8, 5124])
        elif a == "index_type":
            acc[1]["type"] = rng.choice(["VEC2", "VEC3"])
        else:
            acc[rng.randrange(2)]["componentType"] = rng.choice([9999, -1, 2 ** 32 + U16])
        return GCase("type_bad:%s/%s" % (a, style), GARBAGE, g, style)
    if kind == "nonfinite":
        what = rng.choice(["position", "translation", "matrix", "scale_overflow", "rotation_zero"])
        if what == "position":
            g = Gltf()
            pos, tris = hf_grid(4, 3)
            pos = list(pos)
            i = rng.randrange(len(pos))
            p = list(pos[i])
            p[rng.randrange(3)] = rng.choice([float("nan"), float("inf"), -float("inf")])
            pos[i] = tuple(p)
            data = struct.pack("<%df" % (3 * len(pos)), *[c for q in pos for c in q])
            pa = g.accessor(g.view(data, 34962), F32, "VEC3", len(pos))
            g.mesh([{"attributes": {"POSITION": pa}, "indices": g.indices([i for t in tris for i in t], U16)}])
            g.scene([g.node(mesh=0)])
        else:
            g, pos, tris = mesh_gltf(4, 3, U16)
            node = g.j["nodes"][0]
            if what == "translation":
                node["translation"] = [1e39, 0, 0]  # JSON has no NaN: an f32 overflow
            elif what == "matrix":
                node["matrix"] = [1e39] + [0.0] * 4 + [1.0] + [0.0] * 4 + [1.0] + [0.0] * 4 + [1.0]
            elif what == "scale_overflow":
                node["children"] = [g.node(mesh=0, scale=[3e38, 3e38, 3e38])]
                del node["mesh"]
                node["scale"] = [3e38, 3e38, 3e38]
            else:
                node["rotation"] = [0.0, 0.0, 0.0, 0.0]
        return GCase("nonfinite:%s/%s" % (what, style), GARBAGE, g, style)
    if kind == "sparse_bad":
        g = Gltf()
        pos, tris = hf_grid(5, 3)
        what = rng.choice(["index_range", "count_over", "decreasing", "values_short", "indices_float",
                           "indices_signed", "count_zero", "count_huge", "no_values_view"])
        ids = [1, 4, 9]
        ctype = U16
        e = GARBAGE
        count = len(ids)
        if what == "index_range":
            ids = [1, 4, len(pos) + rng.choice([0, 5, 60000])]
        elif what == "count_over":
            count = len(pos) + 1
        elif what == "decreasing":
            ids, e = [9, 4, 1], UNKNOWN
        elif what == "indices_float":
            ctype = F32
        elif what == "indices_signed":
            ctype = I16
        elif what == "count_zero":
            count, e = 0, UNKNOWN
        elif what == "count_huge":
            count = rng.choice([2 ** 31, 2 ** 32 - 1, 2 ** 64 - 1])
        base = g.view(struct.pack("<%df" % (3 * len(pos)), *[c for p in pos for c in p]), 34962)
        iv = g.view(struct.pack("<%d%s" % (len(ids), CFMT[ctype]), *ids))
        vals = [0.5] * (3 * len(ids) if what != "values_short" else 4)
        vv = g.view(struct.pack("<%df" % len(vals), *vals))
        sp = {"count": count, "indices": {"bufferView": iv, "componentType": ctype}, "values": {"bufferView": vv}}
        if what == "no_values_view":
            sp["values"] = {"bufferView": 2 ** 32 + vv}
        pa = g.accessor(base, F32, "VEC3", len(pos), sparse=sp)
        g.mesh([{"attributes": {"POSITION": pa}, "indices": g.indices([i for t in tris for i in t], U16)}])
        g.scene([g.node(mesh=0)])
        return GCase("sparse_bad:%s/%s" % (what, style), e, g, style)
    if kind == "node_graph":
        g, pos, tris = mesh_gltf(4, 3, U16)
        what = rng.choice(["cycle", "self", "two_parents", "child_range", "root_twice", "root_is_child"])
        n0 = 0
        n1 = g.node(mesh=0)
        n2 = g.node()
        nodes = g.j["nodes"]
        if what == "cycle":
            nodes[n0]["children"] = [n1]
            nodes[n1]["children"] = [n2]
            nodes[n2]["children"] = [n0]
        elif what == "self":
            nodes[n1]["children"] = [n1]
            g.j["scenes"][0]["nodes"] = [n0, n1]
        elif what == "two_parents":
            nodes[n0]["children"] = [n1]
            nodes[n2]["children"] = [n1]
            g.j["scenes"][0]["nodes"] = [n0, n2]
        elif what == "child_range":
            nodes[n0]["children"] = [rng.choice([3, 2 ** 31, 2 ** 32 - 1])]
        elif what == "root_twice":
            g.j["scenes"][0]["nodes"] = [n0, n0]
        else:
            nodes[n0]["children"] = [n1]
            g.j["scenes"][0]["nodes"] = [n0, n1]
        if what in ("cycle",) and rng.random() < 0.5:
            del g.j["scene"]
            g.j["scenes"] = []
        return GCase("node_graph:%s/%s" % (what, style), GARBAGE, g, style)
    if kind == "glb_struct":
        g, pos, tris = mesh_gltf(4, 3, U16)
        g.set_buffer("glb")
        full = glb_pack(g.text(), bytes(g.bin))
        b = bytearray(full)
        what = rng.choice(["truncate", "version", "length", "first_bin", "chunk_len", "no_json", "flip", "flip"])
        e = GARBAGE
        if what == "truncate":
            b = bytearray(full[: rng.randrange(1, len(full))])
        elif what == "version":
            struct.pack_into("<I", b, 4, rng.choice([1, 3, 0, 2 ** 32 - 1]))
        elif what == "length":
            struct.pack_into("<I", b, 8, len(full) + rng.choice([-4, 4, 2 ** 31, -len(full)]) & 0xFFFFFFFF)
        elif what == "first_bin":
            b[16:20] = b"BIN\0"
        elif what == "chunk_len":
            struct.pack_into("<I", b, 12, rng.choice([len(full), 2 ** 32 - 1, 2 ** 31 - 1, 2 ** 32 - 8]))
        elif what == "no_json":
            b = bytearray(b"glTF" + struct.pack("<II", 2, 12))
        else:
            b, _ = flip(rng, full, start=12)
            b = bytearray(b)
            e = UNKNOWN
        return GCase("glb_struct:%s" % what, e, raw=bytes(b), ext=".glb")
    if kind == "uri_bad":
        g, pos, tris = mesh_gltf(4, 3, U16)
        what = rng.choice(["base64", "missing_bin", "dotdot", "absolute", "empty_uri", "bad_escape", "not_data"])
        g.set_buffer("external")
        b = g.j["buffers"][0]
        names = None
        if what == "base64":
            b["uri"] = "data:application/octet-stream;base64,@@@not*base64!!"
        elif what == "missing_bin":
            b["uri"] = "missing-buffer.bin"
            names = ["missing-buffer.bin"]
        elif what == "dotdot":
            b["uri"] = "../../../../../../no-such-dir/x.bin"
            names = ["x.bin"]
        elif what == "absolute":
            b["uri"] = "/no-such-dir/y.bin"
            names = ["y.bin"]
        elif what == "empty_uri":
            b["uri"] = ""
        elif what == "bad_escape":
            b["uri"] = "bad%zzname.bin"
        else:
            b["uri"] = "data:application/octet-stream,raw-bytes"
        return GCase("uri_bad:%s" % what, GARBAGE, g, "gltf_raw", ext=".gltf", names=names)
    if kind == "json_bad":
        g, pos, tris = mesh_gltf(4, 3, U16)
        g.set_buffer("datauri")
        text = g.text()
        what = rng.choice(["truncated", "not_json", "empty", "array", "null", "nested", "utf16"])
        if what == "truncated":
            raw = text[: rng.randrange(1, len(text) - 1)]
        elif what == "not_json":
            raw = b"glTF? no: this is text\n"
        elif what == "empty":
            raw = b""
        elif what == "array":
            raw = b"[" + text + b"]"
        elif what == "null":
            raw = b"null"
        elif what == "nested":
            raw = b"[" * 100000 + b"]" * 100000
        else:
            raw = text.decode().encode("utf-16")
        return GCase("json_bad:%s" % what, GARBAGE, raw=raw, ext=".gltf")
    if kind == "empty_doc":
        what = rng.choice(["asset_only", "no_primitives", "count_zero", "empty_scene"])
        if what == "asset_only":
            return GCase("empty_doc:asset_only", GARBAGE, raw=b'{"asset": {"version": "2.0"}}', ext=".gltf")
        g, pos, tris = mesh_gltf(4, 3, U16)
        if what == "no_primitives":
            g.j["meshes"][0]["primitives"] = []
        elif what == "count_zero":
            g.j["accessors"][0]["count"] = 0
            g.j["accessors"][1]["count"] = 0
            del g.j["accessors"][0]["min"], g.j["accessors"][0]["max"]
        else:
            g.j["scenes"][0]["nodes"] = [g.node()]
        return GCase("empty_doc:%s/%s" % (what, style), GARBAGE, g, style)
    raise ValueError(kind)


# kind -> weight in the full run; the --quick slice walks QUICK_GLTF in order.
GLTF_KINDS = {
    "plain": 4, "mode_strip": 3, "mode_fan": 2, "mixed_modes": 2, "transform": 3, "scene_select": 1,
    "no_nodes": 1, "roots_no_scene": 1, "sparse_view": 3, "sparse_noview": 3, "extras": 4,
    "extensions_unknown": 1, "required_ext": 2, "version": 4, "glb_padding": 1, "stride": 2,
    "deep_chain": 1, "many_roots": 1, "shared_accessor": 1,
    "index_2_32": 8, "mode_bad": 2, "tri_count": 1, "index_value": 3, "accessor_range": 3, "view_range": 2,
    "buffer_short": 2, "stride_bad": 2, "type_bad": 3, "nonfinite": 3, "sparse_bad": 3, "node_graph": 3,
    "glb_struct": 4, "uri_bad": 2, "json_bad": 2, "empty_doc": 2,
}
QUICK_GLTF = ["plain", "mode_strip", "mode_fan", "sparse_view", "sparse_noview", "extras", "version",
              "index_2_32", "transform", "mixed_modes", "index_2_32", "version", "extras", "sparse_view",
              "node_graph", "glb_struct", "accessor_range", "type_bad", "sparse_bad", "index_2_32",
              "nonfinite", "stride", "required_ext", "uri_bad", "empty_doc", "index_value", "view_range",
              "buffer_short", "json_bad", "deep_chain", "scene_select", "no_nodes", "mode_bad", "index_2_32",
              "extras", "version"]


def gen_gltf(rng, seeds, index, quick=False):
    kinds = sorted(GLTF_KINDS)
    if quick:
        kind = QUICK_GLTF[index % len(QUICK_GLTF)]
    elif index < len(kinds):
        kind = kinds[index]
    else:
        kind = rng.choices(kinds, weights=[GLTF_KINDS[k] for k in kinds])[0]
    gc = gen_gltf_case(rng, kind)
    extra = dict(gc.extra)
    if gc.raw is not None:
        ext, data = gc.ext, gc.raw
    else:
        style = gc.style
        if "buffers" not in gc.g.j or not gc.g.j.get("buffers"):
            gc.g.set_buffer("external" if style == "gltf_raw" else style)
        if style == "gltf_raw":
            data, ext = gc.g.text(), ".gltf"
            if gc.g.j.get("buffers") and gc.g.j["buffers"][0].get("uri") == "input.bin":
                extra["input.bin"] = bytes(gc.g.bin)
        else:
            data, files = gc.g.files(style)
            extra.update(files)
            ext = ".glb" if style == "glb" else ".gltf"
    case = Case("gltf", gc.kind, ext, data)
    for name, content in extra.items():
        case.files.append((name, content))
    names = ["{in}"] + (gc.names or [])
    if gc.expect == ACCEPT:
        case.run(["convert", "{in}", "-o", "{out}.obj"], ACCEPT, names=names, post=obj_check(gc.expected))
        case.run(rng.choice([["strips", "{in}", "--repeat", "1"], ["build", "{in}", "-o", "{out}.mts"]]),
                 ACCEPT, names=names)
    else:
        case.run(["convert", "{in}", "-o", "{out}.obj"], gc.expect, names=names)
        case.run(rng.choice([["strips", "{in}", "--repeat", "1"], ["build", "{in}", "-o", "{out}.mts"],
                             ["encode", "{in}", "-o", "{out}.stream"]]), gc.expect, names=names)
    return case


def grid_glb_parts(tris_wanted):
    """A height-field mesh of about `tris_wanted` triangles in a fresh
    document: (builder, position accessor, index accessor, pos, tris)."""
    n = max(1, int(math.sqrt(tris_wanted / 4)))
    m = max(1, tris_wanted // (2 * n))
    g = Gltf()
    pos = [(i / 8, j / 8, ((i * 7 + j * 3) % 5) / 16) for j in range(m + 1) for i in range(n + 1)]
    tris = []
    for j in range(m):
        for i in range(n):
            a = j * (n + 1) + i
            tris.append((a, a + 1, a + n + 2))
            tris.append((a, a + n + 2, a + n + 1))
    pa = g.positions(pos)
    ia = g.indices([i for t in tris for i in t], U16 if len(pos) < 65536 else U32)
    return g, pa, ia, pos, tris


def gen_amplify_case(rng, kind):
    """(kind label, main bytes, ext, expectation, expected triangles or
    None, extra argv)."""
    if kind == "instanced":
        nodes, per = rng.choice([(2000, 10000), (2000, 10000), (20000, 10000), (100000, 50000)])
        g, pa, ia, pos, tris = grid_glb_parts(per)
        g.mesh([{"attributes": {"POSITION": pa}, "indices": ia}])
        g.j["nodes"] = [{"mesh": 0, "translation": [40.0 * (k % 100), 40.0 * (k // 100), 0.0]} for k in range(nodes)]
        g.scene(range(nodes))
        g.set_buffer("glb")
        return "instanced:%dx%d" % (nodes, len(tris)), g.files("glb")[0], ".glb", GARBAGE, None, []
    if kind == "primitives":
        prims, per = rng.choice([(3000, 10000), (50000, 2000)])
        g, pa, ia, pos, tris = grid_glb_parts(per)
        g.mesh([{"attributes": {"POSITION": pa}, "indices": ia}] * prims)
        g.scene([g.node(mesh=0)])
        g.set_buffer("glb")
        return "primitives:%dx%d" % (prims, len(tris)), g.files("glb")[0], ".glb", GARBAGE, None, []
    if kind in ("strip_u8", "strip_u8_reuse"):
        g = Gltf()
        pos = [(math.cos(i * 0.7) * (1 + i / 64), math.sin(i * 0.7) * (1 + i / 64), (i % 7) / 8) for i in range(256)]
        pa = g.positions(pos)
        if kind == "strip_u8":
            count, prims = 25000000, 1
        else:
            count, prims = 1000000, rng.choice([64, 500])
        data = bytes(range(256)) * (count // 256) + bytes(range(count % 256))
        ia = g.accessor(g.view(data, 34963), U8, "SCALAR", count)
        g.mesh([{"attributes": {"POSITION": pa}, "indices": ia, "mode": 5}] * prims)
        g.scene([g.node(mesh=0)])
        g.set_buffer("glb")
        return "%s:%dx%d" % (kind, prims, count), g.files("glb")[0], ".glb", GARBAGE, None, []
    if kind == "zero_accessor":
        count = rng.choice([2 ** 31, 2 ** 32 - 1, 10 ** 12, 300000000])
        mode = rng.choice([4, 5])
        g = Gltf()
        pa = g.accessor(None, F32, "VEC3", count - count % 3, min=[0, 0, 0], max=[0, 0, 0])
        g.mesh([{"attributes": {"POSITION": pa}, "mode": mode}])
        g.scene([g.node(mesh=0)])
        return "zero_accessor:%d,mode%d" % (count, mode), g.text(), ".gltf", GARBAGE, None, []
    if kind == "nested_tree":
        depth, per = rng.choice([(14, 1000), (16, 500)])
        g, pa, ia, pos, tris = grid_glb_parts(per)
        g.mesh([{"attributes": {"POSITION": pa}, "indices": ia}])
        count = 2 ** (depth + 1) - 1
        g.j["nodes"] = [{"mesh": 0, "children": [2 * k + 1, 2 * k + 2] if 2 * k + 2 < count else [],
                         "translation": [1.0 if k % 2 else -1.0, 0.5, 0.0]} for k in range(count)]
        for nd in g.j["nodes"]:
            if not nd["children"]:
                del nd["children"]
        g.scene([0])
        g.set_buffer("glb")
        return "nested_tree:%dx%d" % (count, len(tris)), g.files("glb")[0], ".glb", GARBAGE, None, []
    if kind in ("below", "max_raise"):
        nodes, per = rng.choice([(20, 2000), (5, 8000)])
        g, pa, ia, pos, tris = grid_glb_parts(per)
        g.mesh([{"attributes": {"POSITION": pa}, "indices": ia}])
        expected = collections.Counter()
        for k in range(nodes):
            g.node(mesh=0, translation=[40.0 * k, 0.0, 0.0])
            tri_keys(pos, tris, trs_matrix((40.0 * k, 0.0, 0.0)), expected)
        g.scene(range(nodes))
        g.set_buffer("glb")
        extra = ["--max-triangles", "100000000"] if kind == "max_raise" else []
        return "%s:%dx%d" % (kind, nodes, len(tris)), g.files("glb")[0], ".glb", ACCEPT, expected, extra
    if kind == "below_strip":
        g = Gltf()
        n, m = 200, 100
        pos, _ = hf_grid(n, m)
        ix = strip_indices(n, m)
        pa = g.positions(pos)
        g.mesh([{"attributes": {"POSITION": pa}, "indices": g.indices(ix, U16), "mode": 5}])
        g.scene([g.node(mesh=0)])
        g.set_buffer("glb")
        return "below_strip:%d" % len(ix), g.files("glb")[0], ".glb", ACCEPT, tri_keys(pos, topology(5, ix)), []
    if kind == "max_lower":
        g, pa, ia, pos, tris = grid_glb_parts(2000)
        g.mesh([{"attributes": {"POSITION": pa}, "indices": ia}])
        g.scene([g.node(mesh=0)])
        g.set_buffer("glb")
        return "max_lower:100", g.files("glb")[0], ".glb", GARBAGE, None, ["--max-triangles", "100"]
    raise ValueError(kind)


AMPLIFY_KINDS = ["instanced", "below", "strip_u8_reuse", "zero_accessor", "primitives", "nested_tree",
                 "below_strip", "max_lower", "max_raise", "strip_u8"]
HEAVY_AMPLIFY = {"strip_u8"}
QUICK_AMPLIFY = ["instanced", "below", "zero_accessor", "max_lower"]


def gen_amplify(rng, seeds, index, quick=False):
    if quick:
        kind = QUICK_AMPLIFY[index % len(QUICK_AMPLIFY)]
    elif index < len(AMPLIFY_KINDS):
        kind = AMPLIFY_KINDS[index]
    else:
        kind = rng.choice([k for k in AMPLIFY_KINDS if k not in HEAVY_AMPLIFY])
    label, data, ext, expect, expected, extra = gen_amplify_case(rng, kind)
    case = Case("amplify", label, ext, data)
    if expect == ACCEPT:
        case.run(["convert", "{in}", "-o", "{out}.obj"] + extra, ACCEPT, post=obj_check(expected))
        case.run(["strips", "{in}", "--repeat", "1"] + extra, ACCEPT)
    else:
        case.run(["convert", "{in}", "-o", "{out}.obj"] + extra, GARBAGE, must=LIMIT_RE)
        case.run(rng.choice([["build", "{in}", "-o", "{out}.mts"], ["strips", "{in}", "--repeat", "1"]]) + extra,
                 GARBAGE, must=LIMIT_RE)
    return case


# --- special files as input ------------------------------------------------

MESH_READERS = [
    ["build", "{in}", "-o", "{out}.mts"],
    ["strips", "{in}", "--repeat", "1"],
    ["convert", "{in}", "-o", "{out}.obj"],
    ["distance", "{in}", "{seed:obj}", "--samples", "300"],
    ["simplify", "{in}", "--ratio", "0.5", "--samples", "300"],
]
MODEL_READERS = [["info", "{in}"], ["extract", "{in}", "--ratio", "0.5", "--repeat", "1"], ["verify", "{in}", "--lods", "4"],
                 ["render", "{in}", "--size", "16x16", "-o", "{out}.png"]]
STREAM_READERS = [["decode", "{in}"], ["decode", "{in}", "--bytes", "100"]]


def readers_for(ext, rng, n=2):
    pool = MODEL_READERS if ext == ".mts" else STREAM_READERS if ext == ".stream" else MESH_READERS
    return rng.sample(pool, min(n, len(pool)))


FIFO_KINDS = ["fifo", "devzero", "dir", "gltf_buffer", "devurandom", "devnull", "dirlink", "devzero_path",
              "stdin", "mtl_fifo", "texture_fifo", "scene_with_fifo", "distance_ref_fifo"]
QUICK_FIFO = ["fifo", "devzero", "dir", "gltf_buffer", "fifo", "devzero", "mtl_fifo", "scene_with_fifo",
              "texture_fifo", "devzero_path"]


def gen_fifo(rng, seeds, index, quick=False):
    if quick:
        kind = QUICK_FIFO[index % len(QUICK_FIFO)]
    else:
        kind = FIFO_KINDS[index % len(FIFO_KINDS)] if index < 2 * len(FIFO_KINDS) else rng.choice(FIFO_KINDS)
    short = dict(timeout=5)
    if kind in ("fifo", "devzero", "dir", "devurandom", "devnull", "dirlink"):
        ext = rng.choice([".obj", ".ply", ".glb", ".gltf", ".mts", ".stream"])
        if kind in ("devurandom", "devnull"):
            ext = rng.choice([".obj", ".ply", ".glb"])
        spec = {"fifo": ("fifo",), "devzero": ("symlink", "/dev/zero"), "dir": ("dir",),
                "devurandom": ("symlink", "/dev/urandom"), "devnull": ("symlink", "/dev/null"),
                "dirlink": ("symlink", "{dir}/adir")}[kind]
        case = Case("fifo", "%s:%s" % (kind, ext), None, None, path="{dir}/in" + ext)
        if kind == "dirlink":
            case.files.append(("adir", ("dir",)))
        case.files.append(("in" + ext, spec))
        for argv in readers_for(ext, rng):
            case.run(argv, GARBAGE, must=SPECIAL_RE, **short)
        return case
    if kind == "devzero_path":
        case = Case("fifo", "devzero_path", None, None, path="/dev/zero")
        for argv in rng.sample([["build", "{in}", "-o", "{out}.mts"], ["info", "{in}"], ["decode", "{in}"],
                                ["strips", "{in}", "--repeat", "1"]], 2):
            case.run(argv, GARBAGE, must=SPECIAL_RE, **short)
        return case
    if kind == "stdin":
        case = Case("fifo", "stdin", None, None, path="/dev/stdin")
        case.run(rng.choice([["build", "{in}", "-o", "{out}.mts"], ["info", "{in}"]]), GARBAGE, must=SPECIAL_RE,
                 **short)
        return case
    if kind == "gltf_buffer":
        what = rng.choice(["fifo", "devzero", "dir", "devurandom"])
        g, pos, tris = mesh_gltf(4, 3, U16)
        g.set_buffer("external", "buf.bin")
        case = Case("fifo", "gltf_buffer:%s" % what, ".gltf", g.text())
        case.files.append(("buf.bin", {"fifo": ("fifo",), "devzero": ("symlink", "/dev/zero"), "dir": ("dir",),
                                       "devurandom": ("symlink", "/dev/urandom")}[what]))
        for argv in rng.sample(MESH_READERS[:3], 2):
            case.run(argv, GARBAGE, must=SPECIAL_RE, names=["{in}", "buf.bin"], **short)
        return case
    if kind in ("mtl_fifo", "texture_fifo"):
        pos, tris = hf_grid(4, 3)
        text = obj_text_props(pos, tris, mtllib="m.mtl")
        case = Case("fifo", kind, ".obj", text)
        if kind == "mtl_fifo":
            case.files.append(("m.mtl", ("fifo",)))
        else:
            case.files.append(("m.mtl", b"newmtl skin\nmap_Kd tex.png\n"))
            case.files.append(("tex.png", ("fifo",)))
        # With --positions-only the .mtl is not read at all.
        case.run(["convert", "{in}", "--positions-only", "-o", "{out}.obj"], ACCEPT, names=["{in}", "m.mtl", "tex.png"], **short)
        out = rng.choice([".obj", ".glb", ".ply"])
        case.run(["convert", "{in}", "--properties", "-o", "{out}" + out], UNKNOWN, names=["{in}", "m.mtl", "tex.png"],
                 **short)
        return case
    if kind == "scene_with_fifo":
        case = Case("fifo", "scene_with_fifo", None, None, path="{dir}/w.obj")
        case.files.append(("w.obj", ("fifo",)))
        case.run(["render", "--generated", "torus:200", "--scene", "2", "--scene-with", "{in}", "--size", "16x16",
                  "-o", "{out}.png"], GARBAGE, must=SPECIAL_RE, **short)
        return case
    if kind == "distance_ref_fifo":
        case = Case("fifo", "distance_ref_fifo", None, None, path="{dir}/r.obj")
        case.files.append(("r.obj", ("fifo",)))
        case.run(["distance", "{seed:obj}", "{in}", "--samples", "300"], GARBAGE, must=SPECIAL_RE, **short)
        return case
    raise ValueError(kind)


def obj_text_props(pos, tris, mtllib=None, material="skin"):
    out = []
    if mtllib:
        out.append("mtllib %s\n" % mtllib)
    for p in pos:
        out.append("v %s %s %s\n" % tuple(fmt(c) for c in p))
    for i, p in enumerate(pos):
        out.append("vt %s %s\n" % (fmt(p[0]), fmt(p[1])))
    out.append("vn 0.0 0.0 1.0\n")
    if mtllib:
        out.append("usemtl %s\n" % material)
    for t in tris:
        out.append("f " + " ".join("%d/%d/1" % (i + 1, i + 1) for i in t) + "\n")
    return "".join(out).encode()


# --- outputs ----------------------------------------------------------------

PRINTING = [
    ("strips", ["strips", "{seed:obj}", "--repeat", "1"]),
    ("strips --json", ["strips", "{seed:obj}", "--repeat", "1", "--json"]),
    ("simplify", ["simplify", "{seed:obj}", "--ratio", "0.5", "--samples", "300"]),
    ("simplify --json", ["simplify", "{seed:obj}", "--ratio", "0.5", "--samples", "300", "--json"]),
    ("info", ["info", "{seed:mts3}"]),
    ("info --json", ["info", "{seed:mts3}", "--json"]),
    ("extract", ["extract", "{seed:mts3}", "--ratio", "0.5", "--repeat", "1"]),
    ("extract --json", ["extract", "{seed:mts3}", "--ratio", "0.5", "--repeat", "1", "--json"]),
    ("extract --method pm", ["extract", "{seed:mts3}", "--lod", "3", "--repeat", "1", "--method", "pm"]),
    ("verify", ["verify", "{seed:mts3}", "--lods", "4"]),
    ("verify --json", ["verify", "{seed:mts3}", "--lods", "4", "--json"]),
    ("compare", ["compare", "--generated", "torus:200", "--requests", "5"]),
    ("compare --json", ["compare", "--generated", "torus:200", "--requests", "5", "--json"]),
    ("build", ["build", "{seed:obj}", "-o", "{out}.mts"]),
    ("build --json", ["build", "{seed:obj}", "-o", "{out}.mts", "--json"]),
    ("distance", ["distance", "{seed:obj}", "{seed:obj}", "--samples", "300"]),
    ("distance --json", ["distance", "{seed:obj}", "{seed:obj}", "--samples", "300", "--json"]),
    ("encode", ["encode", "{seed:obj}", "-o", "{out}.stream"]),
    ("encode --json", ["encode", "{seed:obj}", "-o", "{out}.stream", "--json"]),
    ("decode", ["decode", "{seed:stream}"]),
    ("decode --json", ["decode", "{seed:stream}", "--json"]),
    ("decode --bytes", ["decode", "{seed:stream}", "--bytes", "100"]),
    ("render", ["render", "--generated", "torus:200", "--size", "16x16", "-o", "{out}.png"]),
    ("render --scene", ["render", "--generated", "torus:200", "--scene", "3", "--size", "16x16", "-o", "{out}.png"]),
    ("--version", ["--version"]),
    ("--help", ["--help"]),
    ("help build", ["help", "build"]),
]
# Printing that comes from clap (help, version): no panic asked, nothing more.
CLAP_PRINTING = {"--version", "--help", "help build"}
STDOUT_NAMES = ["standard output", "stdout"]
PRECIOUS = b"precious: this file was here before the run and must survive it\n" * 8


def sha(path):
    try:
        with open(path, "rb") as f:
            return hashlib.sha1(f.read()).hexdigest()
    except OSError as e:
        return "unreadable: %s" % e.strerror


def listing(d):
    try:
        return sorted(os.listdir(d))
    except OSError:
        return None


def unchanged(path, what="the input"):
    """A post check: `path` has the bytes it had before the run (hashed by
    the pre hook)."""
    def post(env):
        before = env.state.get("hash:" + path)
        now = sha(path.replace("{dir}", env.cdir))
        if now != before:
            return "%s %s was changed although the command failed" % (what, os.path.basename(path))
        return None
    return post


def nothing_left(dirname, allowed=()):
    """A post check: directory `dirname` lists what it listed before the run
    (plus `allowed`)."""
    def post(env):
        d = dirname.replace("{dir}", env.cdir)
        before = env.state.get("list:" + dirname)
        now = listing(d)
        if before is None and now is None:
            return None
        if now is None:
            return "the directory %s is gone" % os.path.basename(d)
        new = [n for n in now if n not in (before or []) and n not in allowed]
        if new:
            return "the failed run left %s behind" % ", ".join(sorted(new))
        return None
    return post


def all_of(*checks):
    def post(env):
        for c in checks:
            m = c(env)
            if m:
                return m
        return None
    return post


def result_or_intact(path, verify_argv, expected=None):
    """-o naming the input itself: a refusal leaves the input as it was; a
    success leaves a correct result there (`verify_argv` accepts it, and
    with `expected`, converting it gives those triangles)."""
    def post(env):
        p = path.replace("{dir}", env.cdir)
        if env.rc != 0:
            if sha(p) != env.state.get("hash:" + path):
                return "the input %s was changed or destroyed by a run that failed" % os.path.basename(path)
            return None
        rc, err = env.mts([a.replace("{p}", p) for a in verify_argv])
        if rc != 0:
            return "the result left at %s is not valid: %s" % (os.path.basename(path), err.strip().splitlines()[:1])
        if expected is not None:
            chk = os.path.join(env.cdir, "check.obj")
            rc, err = env.mts(["convert", p, "-o", chk])
            if rc != 0:
                return "the result cannot be converted back: %s" % err.strip().splitlines()[:1]
            pos, tris = read_obj_mesh(chk)
            if tri_keys(pos, tris) != expected:
                return "the result does not hold the input's triangles"
        return None
    return post


def converts_back(ext_path):
    """An ACCEPT run's output file reads back as a mesh with triangles."""
    def post(env):
        if env.rc != 0:
            return None
        p = ext_path.replace("{out}", env.out)
        if not os.path.exists(p):
            return "no file written at %s" % os.path.basename(p)
        rc, err = env.mts(["strips", p, "--repeat", "1"])
        if rc != 0:
            return "the file written does not read back: %s" % (err.strip().splitlines() or [""])[0]
        return None
    return post


def make_readonly(path):
    """Makes directory `path` unwritable: chmod, and as root (whom modes do
    not stop) the immutable attribute. True when a file can no longer be
    created in it."""
    os.chmod(path, 0o555)
    probe = os.path.join(path, ".probe")
    try:
        with open(probe, "wb"):
            pass
    except OSError:
        return True
    os.unlink(probe)
    if shutil.which("chattr"):
        subprocess.run(["chattr", "+i", path], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        try:
            with open(probe, "wb"):
                pass
        except OSError:
            return True
        os.unlink(probe)
    return False


def undo_readonly(path):
    if shutil.which("chattr"):
        subprocess.run(["chattr", "-i", path], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        os.chmod(path, 0o755)
    except OSError:
        pass


# Writers: label -> (argv with {src} (an OBJ) / {o} (the output), output ext)
WRITERS = {
    "build": (["build", "{src}", "-o", "{o}"], ".mts"),
    "convert": (["convert", "{src}", "-o", "{o}"], ".obj"),
    "convert-ply": (["convert", "{src}", "-o", "{o}"], ".ply"),
    "convert-glb": (["convert", "{src}", "-o", "{o}"], ".glb"),
    "simplify": (["simplify", "{src}", "--ratio", "0.5", "--samples", "300", "--no-meshopt", "-o", "{o}"], ".obj"),
    "extract": (["extract", "{seed:mts3}", "--ratio", "0.5", "--repeat", "1", "-o", "{o}"], ".obj"),
    "encode": (["encode", "{src}", "-o", "{o}"], ".stream"),
    "decode": (["decode", "{seed:stream}", "-o", "{o}"], ".obj"),
    "render": (["render", "{src}", "--size", "16x16", "-o", "{o}"], ".png"),
}
BIG_SOURCE = ["--generated", "torus:5000"]

OUTPUT_KINDS = ["stdout_full", "stdout_closed", "self_output", "missing_dir", "readonly_dir", "dir_target",
                "unknown_ext", "existing_bad_input", "existing_fsize", "extract_out"]


def gen_output(rng, seeds, index, quick=False):
    if quick:
        # Every printing command to /dev/full and to a closed pipe, then
        # one of each file kind.
        n = len(PRINTING)
        if index < 2 * n:
            kind = "stdout_full" if index < n else "stdout_closed"
            sel = PRINTING[index % n]
        else:
            kind = OUTPUT_KINDS[2 + (index - 2 * n) % (len(OUTPUT_KINDS) - 2)]
            sel = None
    else:
        kind = OUTPUT_KINDS[index % len(OUTPUT_KINDS)]
        sel = PRINTING[(index // len(OUTPUT_KINDS)) % len(PRINTING)] if kind.startswith("stdout") else None
    if kind in ("stdout_full", "stdout_closed"):
        label, argv = sel
        case = Case("output", "%s:%s" % (kind, label))
        if kind == "stdout_full":
            expect = UNKNOWN if label in CLAP_PRINTING else GARBAGE
            case.run(list(argv), expect, target=False, stdout="full", names=STDOUT_NAMES, one_line=True)
        else:
            expect = UNKNOWN if label in CLAP_PRINTING else ACCEPT
            case.run(list(argv), expect, target=False, stdout="closed")
        return case
    pos, tris = hf_grid(6, 4)
    src_obj = obj_text(pos, tris)
    expected = tri_keys(pos, tris)
    if kind == "self_output":
        how = rng.choice(["same", "same", "symlink", "hardlink", "dotpath"])
        what = rng.choice(["convert", "convert-ply", "convert-glb", "build", "simplify", "encode", "extract-mts",
                           "decode-stream"])
        case = Case("output", "self_output:%s,%s" % (what, how), None, None, path="{dir}/a.obj")
        if what == "convert-ply":
            case.path = "{dir}/a.ply"
            case.files.append(("a.ply", ply_bytes(pos, tris, enc=rng.choice(["ascii", "binary_little_endian"]))))
        elif what == "convert-glb":
            case.path = "{dir}/a.glb"
            g, _, _ = mesh_gltf(6, 4, U16)
            g.set_buffer("glb")
            case.files.append(("a.glb", g.files("glb")[0]))
        elif what == "extract-mts":
            case.path = "{dir}/m.mts"
            case.files.append(("m.mts", seeds.mts["torus_v3.mts"]))
        elif what == "decode-stream":
            case.path = "{dir}/s.stream"
            case.files.append(("s.stream", seeds.stream["torus.stream"]))
        else:
            case.files.append(("a.obj", src_obj))
        inp = case.path
        out = inp
        if how == "symlink":
            out = "{dir}/link" + os.path.splitext(inp)[1]
            case.files.append((os.path.basename(out), ("symlink", os.path.basename(inp))))
        elif how == "hardlink":
            out = "{dir}/hard" + os.path.splitext(inp)[1]
            case.files.append((os.path.basename(out), ("hardlink", os.path.basename(inp))))
        elif how == "dotpath":
            out = "{dir}/./" + os.path.basename(inp)
        if what.startswith("convert"):
            argv = ["convert", "{in}", "-o", out]
            check = result_or_intact(inp, ["strips", "{p}", "--repeat", "1"], expected)
        elif what == "build":
            argv = ["build", "{in}", "-o", out]
            check = result_or_intact(inp, ["info", "{p}"])
        elif what == "simplify":
            argv = ["simplify", "{in}", "--ratio", "0.5", "--samples", "300", "--no-meshopt", "-o", out]
            check = result_or_intact(inp, ["strips", "{p}", "--repeat", "1"])
        elif what == "encode":
            argv = ["encode", "{in}", "-o", out]
            check = result_or_intact(inp, ["decode", "{p}"])
        elif what == "extract-mts":
            argv = ["extract", "{in}", "--ratio", "0.5", "--repeat", "1", "-o", out]
            check = result_or_intact(inp, ["info", "{p}"])
        else:
            argv = ["decode", "{in}", "-o", out]
            check = result_or_intact(inp, ["decode", "{p}"])
        case.run(argv, UNKNOWN, names=["{in}", os.path.basename(out)], hash=[inp], post=check)
        return case
    label = rng.choice(sorted(WRITERS))
    template, oext = WRITERS[label]
    case = Case("output", "%s:%s" % (kind, label), ".obj", src_obj)

    def argv_for(o, src="{in}"):
        a = []
        for t in template:
            if t == "{src}":
                a += BIG_SOURCE if src == "big" else [src]
            else:
                a.append(t.replace("{o}", o))
        return a
    if kind == "missing_dir":
        o = "{dir}/missing/sub/x" + oext
        case.run(argv_for(o), GARBAGE, names=["missing/sub/x" + oext, "missing/sub"],
                 post=lambda env: "a file or folder was created under missing/" if os.path.exists(
                     os.path.join(env.cdir, "missing")) else None)
        return case
    if kind == "readonly_dir":
        case.files.append(("ro", ("rodir",)))
        o = "{dir}/ro/x" + oext
        case.run(argv_for(o), GARBAGE, names=["ro/x" + oext, "/ro"], needs="rodir", list=["{dir}/ro"],
                 post=nothing_left("{dir}/ro"))
        return case
    if kind == "dir_target":
        case.files.append(("target" + oext, ("dir",)))
        o = "{dir}/target" + oext
        case.run(argv_for(o), GARBAGE, names=["target" + oext], list=["{dir}/target" + oext, "{dir}"],
                 post=all_of(nothing_left("{dir}/target" + oext), nothing_left("{dir}")))
        return case
    if kind == "unknown_ext":
        if label in ("build", "encode", "render"):
            label = "convert"
            template, oext = WRITERS[label]
        o = "{dir}/x." + rng.choice(["xyz", "OBJX", "mts2", "", "obj.tmp"])
        o = o.rstrip(".")
        case.kind = "unknown_ext:%s" % label
        case.run(argv_for(o), GARBAGE, names=[os.path.basename(o)], list=["{dir}"], post=nothing_left("{dir}"))
        return case
    if kind == "existing_bad_input":
        good = "{dir}/good" + oext
        case.files.append(("good" + oext, PRECIOUS))
        bad = rng.choice([b"v 1 2\nf 1 2 3\n", b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n", b"", b"\x00" * 100])
        case.data = bad
        if label in ("extract", "decode"):
            # their input is the model / stream: make that one bad
            bad_name = "bad.mts" if label == "extract" else "bad.stream"
            src = seeds.mts["torus_v3.mts"] if label == "extract" else seeds.stream["torus.stream"]
            case.files.append((bad_name, src[: len(src) // 2]))
            argv = [a.replace("{seed:mts3}", "{dir}/" + bad_name).replace("{seed:stream}", "{dir}/" + bad_name)
                    for a in argv_for(good)]
            names = [bad_name]
        else:
            argv = argv_for(good)
            names = ["{in}"]
        case.run(argv, GARBAGE, names=names, hash=[good], list=["{dir}"],
                 post=all_of(unchanged(good, "the existing output"), nothing_left("{dir}")))
        return case
    if kind == "existing_fsize":
        if label == "render":
            label = "convert-glb"
            template, oext = WRITERS[label]
        good = "{dir}/good" + oext
        case.files.append(("good" + oext, PRECIOUS))
        case.kind = "existing_fsize:%s" % label
        case.run(argv_for(good, src="big"), GARBAGE, names=["good" + oext], fsize=2048, hash=[good], list=["{dir}"],
                 post=all_of(unchanged(good, "the existing output"), nothing_left("{dir}")))
        return case
    if kind == "extract_out":
        which = rng.choice(["extract", "extract", "decode", "simplify"])
        e = rng.choice([".ply", ".obj", ".glb", ".gltf"])
        if which == "extract":
            argv = ["extract", "{seed:mts3}", "--ratio", "0.5", "--repeat", "1", "-o", "{out}" + e]
        elif which == "decode":
            argv = ["decode", "{seed:stream}", "-o", "{out}" + e]
        else:
            argv = ["simplify", "{in}", "--ratio", "0.5", "--samples", "300", "-o", "{out}" + e]
        case.kind = "extract_out:%s%s" % (which, e)
        case.run(argv, ACCEPT, names=["{in}"], post=converts_back("{out}" + e))
        return case
    raise ValueError(kind)


# --- view and scene arguments -----------------------------------------------

VIEW_ARGS = [
    (["--scene", "18446744073709551615"], GARBAGE), (["--scene", "1000000000"], GARBAGE),
    (["--scene", "1048577"], GARBAGE), (["--scene", "4294967296"], GARBAGE),
    (["--scene", "18446744073709551616"], GARBAGE), (["--scene=-1"], GARBAGE), (["--scene", "nan"], GARBAGE),
    (["--scene", "1e9"], GARBAGE), (["--scene="], GARBAGE), (["--scene", "0"], UNKNOWN),
    (["--frames=-1"], GARBAGE), (["--frames", "18446744073709551616"], GARBAGE), (["--frames", "nan"], GARBAGE),
    (["--scene", "18446744073709551615", "--frames", "1"], GARBAGE),
    (["--scene", "2000000", "--checker"], GARBAGE),
]
PIXEL_ERRORS = [("-0", ACCEPT), ("=-0", ACCEPT), ("0", ACCEPT), ("1000", ACCEPT), ("0.5", ACCEPT),
                ("nan", GARBAGE), ("inf", GARBAGE), ("=-1", GARBAGE), ("1001", GARBAGE), ("=", GARBAGE),
                ("1e39", GARBAGE), ("=-inf", GARBAGE)]
NO_ADAPTER_RE = r"(?i)no (suitable )?(gpu|graphics )?adapter|adapter.*not found|no vulkan|failed to find a (suitable )?adapter"


def extreme_scene_mesh(rng, what=None):
    what = what or rng.choice(["coincident", "coords_1e20", "edges_1e-25", "coords_3e38", "denormals",
                               "one_triangle", "tiny_grid"])
    if what == "coincident":
        n = rng.choice([3, 30])
        return what, obj_text([(1.0, 1.0, 1.0)] * n, [(i, i + 1, i + 2) for i in range(n - 2)])
    p, f = torus_mesh(10, 6)
    if what == "coords_1e20":
        return what, obj_text([tuple(c * 1e20 for c in q) for q in p], f)
    if what == "edges_1e-25":
        return what, obj_text([tuple(c * 1e-25 for c in q) for q in p], f)
    if what == "coords_3e38":
        return what, obj_text([tuple(c * 2.2e38 for c in q) for q in p], f)
    if what == "denormals":
        return what, obj_text([tuple(c * 1e-41 for c in q) for q in p], f)
    if what == "one_triangle":
        return what, b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"
    gp, gf = grid_mesh(2, 1)
    return what, obj_text(gp, gf)


VIEW_KINDS = ["view_arg", "render_scene", "pixel_error", "view_file"]


def gen_view(rng, seeds, index, quick=False):
    if quick:
        order = ["view_arg", "view_arg", "render_scene", "pixel_error", "view_arg", "view_file", "pixel_error",
                 "view_arg", "render_scene", "view_arg"]
        kind = order[index % len(order)]
        sub = index
    else:
        kind = VIEW_KINDS[index % len(VIEW_KINDS)]
        sub = index // len(VIEW_KINDS)
    short = dict(timeout=10)
    if kind == "view_arg":
        args, expect = VIEW_ARGS[sub % len(VIEW_ARGS)]
        case = Case("view", "view_arg:%s" % " ".join(args))
        case.run(["view", "--generated", "torus:200"] + args, expect, target=False,
                 must=VIEW_ARG_RE if expect == GARBAGE else None, **short)
        return case
    if kind == "view_file":
        what = rng.choice(["missing_scene_with", "bad_model", "bad_scene_with"])
        if what == "bad_model":
            case = Case("view", "view_file:bad_model", ".mts", seeds.mts["torus_v3.mts"][:200])
            case.run(["view", "{in}"], GARBAGE, **short)
        elif what == "missing_scene_with":
            case = Case("view", "view_file:missing_scene_with", None, None, path="{dir}/missing.obj")
            case.run(["view", "--generated", "torus:200", "--scene", "3", "--scene-with", "{in}"], GARBAGE, **short)
        else:
            case = Case("view", "view_file:bad_scene_with", ".obj", b"v 0 0 0\nf 1 2 3\n")
            case.run(["view", "--generated", "torus:200", "--scene", "3", "--scene-with", "{in}"], GARBAGE, **short)
        return case
    if kind == "render_scene":
        # --quick: the issue's two meshes (all vertices coincident, 1e-25 edges)
        what, data = extreme_scene_mesh(rng, ["coincident", "edges_1e-25"][sub // 6 % 2] if quick else None)
        n = rng.choice(["1", "3", "50"])
        case = Case("view", "render_scene:%s" % what, ".obj", data)
        case.run(["render", "{in}", "--size", "32x32", "-o", "{out}.png"], UNKNOWN, skip_re=NO_ADAPTER_RE)

        def like_plain(prev):
            return ACCEPT if prev and prev[0]["cls"] == "ok" else UNKNOWN
        case.run(["render", "{in}", "--scene", n, "--size", "32x32", "-o", "{out}.png"], like_plain,
                 skip_re=NO_ADAPTER_RE)
        case.run(["render", "{in}", "--scene", n, "--pixel-error", "-0", "--size", "32x32", "-o", "{out}.png"],
                 like_plain, skip_re=NO_ADAPTER_RE)
        return case
    if kind == "pixel_error":
        v, expect = PIXEL_ERRORS[sub % len(PIXEL_ERRORS)]
        arg = ["--pixel-error" + v] if v.startswith("=") else ["--pixel-error", v]
        case = Case("view", "pixel_error:%s" % v)
        case.run(["render", "--generated", "torus:200", "--scene", "3", "--size", "16x16"] + arg + ["-o", "{out}.png"],
                 expect, target=False, skip_re=NO_ADAPTER_RE)
        return case
    raise ValueError(kind)


# --- properties ----------------------------------------------------------------

WEIGHT_VALUES = [("nan", GARBAGE), ("inf", GARBAGE), ("-inf", GARBAGE), ("=-inf", GARBAGE), ("=-1", GARBAGE),
                 ("1e39", GARBAGE), ("=", GARBAGE), ("NaN", GARBAGE), ("-0", ACCEPT), ("=-0", ACCEPT),
                 ("0", ACCEPT), ("0.5", ACCEPT), ("-0.0", ACCEPT)]
QUICK_WEIGHTS = [("--uv-weight", "nan"), ("--normal-weight", "inf"), ("--color-weight", "=-inf"),
                 ("--uv-weight", "-0"), ("--normal-weight", "=-0"), ("--color-weight", "-0")]
PROPS_KINDS = ["weights", "missing_texture", "gltf_props", "missing_mtl", "texture_dir", "roundtrip", "gltf_props_bad"]


def props_gltf(rng, bad=None):
    g = Gltf()
    pos, tris = hf_grid(5, 4)
    pa = g.positions(pos)
    n = len(pos)
    attrs = {"POSITION": pa}
    nrm = struct.pack("<%df" % (3 * n), *([0.0, 0.0, 1.0] * n))
    attrs["NORMAL"] = g.accessor(g.view(nrm), F32, "VEC3", n)
    uv = struct.pack("<%df" % (2 * n), *[c for p in pos for c in (p[0], p[1])])
    attrs["TEXCOORD_0"] = g.accessor(g.view(uv), F32, "VEC2", n)
    color = rng.choice(["vec3f", "vec4u8", "vec4u16", "none"])
    if color == "vec3f":
        attrs["COLOR_0"] = g.accessor(g.view(struct.pack("<%df" % (3 * n), *([0.5, 0.25, 1.0] * n))), F32, "VEC3", n)
    elif color == "vec4u8":
        attrs["COLOR_0"] = g.accessor(g.view(bytes([200, 100, 50, 255] * n)), U8, "VEC4", n, normalized=True)
    elif color == "vec4u16":
        attrs["COLOR_0"] = g.accessor(g.view(struct.pack("<%dH" % (4 * n), *([60000, 100, 5, 65535] * n))), U16,
                                      "VEC4", n, normalized=True)
    prim = {"attributes": attrs, "indices": g.indices([i for t in tris for i in t], U16), "material": 0}
    g.j["images"] = [{"uri": "missing-texture.png"}]
    g.j["textures"] = [{"source": 0}]
    g.j["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"] = {"index": 0}
    label = color
    if bad == "color_vec2":
        attrs["COLOR_0"] = g.accessor(g.view(uv), F32, "VEC2", n)
        label = bad
    elif bad == "normal_count":
        attrs["NORMAL"] = g.accessor(g.view(nrm), F32, "VEC3", n - 1)
        label = bad
    elif bad == "normal_nan":
        attrs["NORMAL"] = g.accessor(g.view(struct.pack("<%df" % (3 * n), *([float("nan"), 0.0, 1.0] * n))), F32,
                                     "VEC3", n)
        label = bad
    elif bad == "uv_vec3":
        attrs["TEXCOORD_0"] = g.accessor(g.view(nrm), F32, "VEC3", n)
        label = bad
    elif bad == "image_2_32":
        g.j["textures"][0]["source"] = 2 ** 32
        label = bad
    elif bad == "texture_2_32":
        g.j["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"]["index"] = 2 ** 32
        label = bad
    g.mesh([prim])
    g.scene([g.node(mesh=0)])
    return g, pos, tris, label


def gen_props(rng, seeds, index, quick=False):
    if quick:
        order = ["weights", "missing_texture", "weights", "gltf_props", "weights", "missing_texture", "weights",
                 "gltf_props_bad", "weights", "roundtrip", "weights", "missing_mtl", "texture_dir"]
        kind = order[index % len(order)]
        sub = index
    else:
        kind = PROPS_KINDS[index % len(PROPS_KINDS)]
        sub = index // len(PROPS_KINDS) + index
    pos, tris = hf_grid(5, 4)
    if kind == "weights":
        if quick:
            flag, v = QUICK_WEIGHTS[(sub // 2) % len(QUICK_WEIGHTS)]
            expect = dict(WEIGHT_VALUES)[v]
        else:
            flag = ["--uv-weight", "--normal-weight", "--color-weight"][sub % 3]
            v, expect = WEIGHT_VALUES[(sub * 7) % len(WEIGHT_VALUES)]
        arg = [flag + v] if v.startswith("=") else [flag, v]
        with_props = expect == ACCEPT or rng.random() < 0.7
        case = Case("props", "weights:%s %s%s" % (flag, v, "" if with_props else ",no-properties"), ".obj",
                    obj_text_props(pos, tris))
        argv = ["simplify", "{in}"] + (["--properties"] if with_props else ["--positions-only"]) + \
               ["--ratio", "0.5", "--samples", "300", "--no-meshopt"] + arg
        case.run(argv, expect, target=False)
        return case
    if kind in ("missing_texture", "missing_mtl", "texture_dir"):
        case = Case("props", kind, ".obj", obj_text_props(pos, tris, mtllib="m.mtl"))
        if kind == "missing_texture":
            case.files.append(("m.mtl", b"newmtl skin\nKd 1 1 1\nmap_Kd textures/missing.png\n"))
        elif kind == "texture_dir":
            case.files.append(("m.mtl", b"newmtl skin\nmap_Kd tex.png\n"))
            case.files.append(("tex.png", ("dir",)))
        expect = UNKNOWN if kind == "texture_dir" else ACCEPT
        for e in rng.sample([".obj", ".glb", ".gltf", ".ply"], 2):
            case.run(["convert", "--properties", "{in}", "-o", "{out}" + e], expect, names=["{in}", "tex.png"],
                     post=converts_back("{out}" + e) if expect == ACCEPT else None)
        case.run(rng.choice([["build", "--properties", "{in}", "-o", "{out}.mts"],
                             ["strips", "--properties", "{in}", "--repeat", "1"],
                             ["simplify", "--properties", "{in}", "--ratio", "0.5", "--samples", "300", "-o",
                              "{out}.glb"]]), expect, names=["{in}", "tex.png"])
        return case
    if kind in ("gltf_props", "gltf_props_bad"):
        bad = None
        if kind == "gltf_props_bad":
            bad = rng.choice(["color_vec2", "normal_count", "normal_nan", "uv_vec3", "image_2_32", "texture_2_32"])
        g, gpos, gtris, label = props_gltf(rng, bad)
        style = gltf_style(rng)
        g.set_buffer(style)
        data, files = g.files(style)
        ext = ".glb" if style == "glb" else ".gltf"
        case = Case("props", "%s:%s/%s" % (kind, label, style), ext, data)
        for name, content in files.items():
            case.files.append((name, content))
        if bad:
            case.run(["convert", "--properties", "{in}", "-o", "{out}.glb"], GARBAGE)
            case.run(["build", "--properties", "{in}", "-o", "{out}.mts"], GARBAGE)
        else:
            case.run(["convert", "--properties", "{in}", "-o", "{out}.obj"], ACCEPT, post=obj_check(tri_keys(gpos, gtris)))
            case.run(["convert", "--properties", "{in}", "-o", "{out}.glb"], ACCEPT, post=converts_back("{out}.glb"))
            case.run(["build", "--properties", "{in}", "-o", "{out}.mts"], ACCEPT)
        return case
    if kind == "roundtrip":
        case = Case("props", "roundtrip", ".obj", obj_text_props(pos, tris, mtllib="m.mtl"))
        case.files.append(("m.mtl", b"newmtl skin\nmap_Kd missing.png\n"))
        e = rng.choice([".glb", ".gltf", ".ply"])
        case.run(["convert", "--properties", "{in}", "-o", "{out}" + e], ACCEPT)
        case.run(["convert", "--properties", "{out0}" + e, "-o", "{out}.obj"],
                 lambda prev: ACCEPT if prev[0]["cls"] == "ok" else None,
                 post=obj_check(tri_keys(pos, tris), "the first conversion read"))
        return case
    raise ValueError(kind)


# --- resealed version-3 files -------------------------------------------------


class V3File:
    """A version-3 .mts file cut into sections, its MODL arrays decoded
    (layout of format.rs: model_payload / read_arrays)."""

    ARRAYS = ["band_lod", "band_strips", "strip_records", "strip_begins", "slot_size", "begin_node", "begin_res"]

    def __init__(self, data):
        self.version, count = struct.unpack_from("<II", data, 8)
        if self.version != 3:
            raise ValueError("not a version-3 file")
        pos = MTS_HEADER
        self.sections = []
        for _ in range(count):
            tag = bytes(data[pos : pos + 4])
            n = struct.unpack_from("<Q", data, pos + 4)[0]
            self.sections.append([tag, bytes(data[pos + 12 : pos + 12 + n])])
            pos += 12 + n
        if pos != len(data):
            raise ValueError("sections do not end at the end of the file")
        tags = [t for t, _ in self.sections]
        if tags != [b"META", b"POSI", b"STRP", b"STEP", b"PROP", b"CMPN", b"MODL"]:
            raise ValueError("sections %s" % tags)
        meta = self.sections[0][1]
        p = 0
        self.meta_counts = []
        for _ in range(5):
            v, p = get_varint(meta, p)
            self.meta_counts.append(v)
        max_lod = self.meta_counts[4]
        m = self.sections[6][1]
        p = 0
        self.counts = []
        for _ in range(5):
            v, p = get_varint(m, p)
            self.counts.append(v)
        strips, bands, begins, records, far = self.counts
        self.vw, self.lw = m[p], m[p + 1]
        p += 2
        lens = [bands, bands + 1, strips + 1, strips + 1, strips, begins, begins]
        self.a = {}
        for name, n in zip(self.ARRAYS, lens):
            self.a[name] = list(struct.unpack_from("<%dI" % n, m, p))
            p += 4 * n
        for name, w in (("rec_vertex", self.vw), ("rec_label", self.lw)):
            f = "H" if w == 2 else "I"
            self.a[name] = list(struct.unpack_from("<%d%s" % (records, f), m, p))
            p += w * records
        self.a["rec_code"] = list(m[p : p + records])
        p += records
        self.a["far"] = list(struct.unpack_from("<%dI" % (2 * far), m, p))
        p += 8 * far
        self.a["tri_counts"] = list(struct.unpack_from("<%dI" % (max_lod + 1), m, p))
        p += 4 * (max_lod + 1)
        if p != len(m):
            raise ValueError("MODL has %d bytes, the layout %d" % (len(m), p))
        st = self.sections[3][1]
        p = 0
        self.steps = []
        for _ in range(max_lod):
            r, p = get_varint(st, p)
            k, p = get_varint(st, p)
            e = struct.unpack_from("<f", st, p)[0]
            p += 4
            self.steps.append([r, k, e])

    def to_bytes(self):
        m = bytearray()
        for c in self.counts:
            put_varint(m, c)
        m += bytes([self.vw, self.lw])
        for name in self.ARRAYS:
            m += struct.pack("<%dI" % len(self.a[name]), *self.a[name])
        for name, w in (("rec_vertex", self.vw), ("rec_label", self.lw)):
            f = "H" if w == 2 else "I"
            m += struct.pack("<%d%s" % (len(self.a[name]), f), *self.a[name])
        m += bytes(self.a["rec_code"])
        m += struct.pack("<%dI" % len(self.a["far"]), *self.a["far"])
        m += struct.pack("<%dI" % len(self.a["tri_counts"]), *self.a["tri_counts"])
        self.sections[6][1] = bytes(m)
        st = bytearray()
        for r, k, e in self.steps:
            put_varint(st, r)
            put_varint(st, k)
            st += struct.pack("<f", e)
        self.sections[3][1] = bytes(st)
        body = bytearray()
        for tag, payload in self.sections:
            body += tag + struct.pack("<Q", len(payload)) + payload
        head = b"MTSMODEL" + struct.pack("<II", 3, len(self.sections)) + struct.pack("<QQ", 0, 0)
        return seal_mts(head + bytes(body))


RESEAL_FIELDS = ["rec_vertex", "rec_vertex", "rec_label", "rec_label", "rec_code", "rec_code", "slot_size",
                 "band_lod", "band_strips", "strip_records", "strip_begins", "begin_node", "begin_res", "tri_counts",
                 "step_kept", "step_removed", "vertex_width", "swap_records"]


def reseal_edit(rng, f, field):
    """Changes one field of the ready section (or the recipe's steps) of a
    parsed V3File in place; returns a label, or None when the field has
    nothing to change."""
    a = f.a
    nv = f.meta_counts[0] + f.meta_counts[1]
    if field in ("rec_vertex", "rec_label", "slot_size", "band_lod", "band_strips", "strip_records",
                 "strip_begins", "begin_node", "begin_res", "tri_counts"):
        arr = a[field]
        if not arr:
            return None
        i = rng.randrange(len(arr))
        if field == "rec_vertex" and rng.random() < 0.7:
            nz = [k for k, v in enumerate(arr) if v]
            i = rng.choice(nz) if nz else i
        limit = (1 << (8 * (f.vw if field == "rec_vertex" else f.lw if field == "rec_label" else 4))) - 1
        if field == "rec_vertex":
            limit = min(limit, nv - 1)
        d = rng.choice([1, 1, -1, 2])
        old = arr[i]
        v = old + d
        if v < 0 or v > limit:
            v = old - d
        if v < 0 or v > limit or v == old:
            return None
        arr[i] = v
        return "%s[%d]%+d" % (field, i, v - old)
    if field == "rec_code":
        arr = a["rec_code"]
        i = rng.randrange(len(arr))
        c = arr[i]
        how = rng.choice(["distance+1", "distance-1", "break", "more", "zero"])
        dist = c & 0x3F
        if how == "distance+1" and 1 <= dist < 62:
            c = (c & 0xC0) | (dist + 1)
        elif how == "distance-1" and dist > 1 and dist != 0x3F:
            c = (c & 0xC0) | (dist - 1)
        elif how == "break":
            c ^= 0x40
        elif how == "more":
            c ^= 0x80
        elif how == "zero" and dist:
            c &= 0xC0
        else:
            return None
        arr[i] = c
        return "rec_code[%d]:%s" % (i, how)
    if field in ("step_kept", "step_removed"):
        if not f.steps:
            return None
        s = rng.choice(f.steps)
        j = 1 if field == "step_kept" else 0
        v = rng.randrange(f.meta_counts[0])
        if v == s[j] or v == s[1 - j]:
            return None
        s[j] = v
        return field
    if field == "vertex_width":
        if f.vw != 2:
            return None
        f.vw = 4  # the same values, wider: a valid re-encoding
        return "vertex_width:4"
    if field == "swap_records":
        arr = a["rec_vertex"]
        nz = [k for k, v in enumerate(arr) if v]
        if len(nz) < 2:
            return None
        i, j = rng.sample(nz, 2)
        if arr[i] == arr[j]:
            return None
        arr[i], arr[j] = arr[j], arr[i]
        return "rec_vertex swapped"
    raise ValueError(field)


RESEAL_SEEDS = ["torus_v3.mts", "ico_optimal_v3.mts", "grid_single_v3.mts", "torus_props_v3.mts"]
# Seeds only the reseal family reads (the mts family's choice stays as in issue 19).
RESEAL_ONLY = ("grid_single_v3.mts", "torus_props_v3.mts")


def gen_reseal(rng, seeds, index, quick=False):
    name = RESEAL_SEEDS[index % len(RESEAL_SEEDS)]
    full = seeds.v3[name]
    if index % 23 == 7:
        field, label, data = "clean", "clean", full
    else:
        distinct = sorted(set(RESEAL_FIELDS))
        field = distinct[index % len(distinct)] if quick else rng.choice(RESEAL_FIELDS)
        label = None
        for _ in range(20):
            f = V3File(full)
            label = reseal_edit(rng, f, field)
            if label:
                break
            field = rng.choice(RESEAL_FIELDS)
        data = f.to_bytes() if label else full
        if not label:
            field = label = "clean"
    case = Case("reseal", "%s/%s:%s" % (field, name[:-4], label), ".mts", data)
    # verify --lods all decides whether the file lies (it checks the strips
    # and the LoD -> triangle table against the replay at every LoD), and
    # verify --lods 1 whether it lies at LoD 0. Loading guarantees LoD 0 (and
    # checks one LoD drawn per load): a file that lies at LoD 0 and loads is
    # garbage accepted; one that lies only elsewhere and loads is a
    # "trusted lie", counted apart.
    table = field == "tri_counts"
    case.run(["verify", "{in}", "--lods", "all"], ACCEPT if field == "clean" else GARBAGE if table else UNKNOWN)
    case.run(["verify", "{in}", "--lods", "1"], ACCEPT if field == "clean" else UNKNOWN)
    refused = ("clean error", "unnamed error", "valid refused", "wrong message")

    def by_verify(prev):
        every, first = prev[0], prev[1]
        if field == "clean":
            return ACCEPT
        # A mismatch at LoD 0 (not a refusal at load, which depends on the
        # LoD that process drew) breaks what loading guarantees.
        if first["cls"] in refused and any("breaks the invariant" in l for l in first["stderr"]):
            return GARBAGE
        if every["cls"] in refused or every["cls"] == "garbage accepted":
            return TRUSTED
        return UNKNOWN  # harmless, or verify itself crashed or hung: reported as such

    case.run(["info", "{in}"], by_verify)
    case.run(["extract", "{in}", "--ratio", rng.choice(["0.5", "0.1", "0.9"]), "--repeat", "1"], by_verify)
    lod = rng.randrange(0, max(1, V3File(full).meta_counts[4]))
    case.run(["extract", "{in}", "--lod", str(lod), "--repeat", "1", "--json"], by_verify)
    return case


# --- version-4 files: hierarchies ---------------------------------------------


def split_mts_sections(data, version, tags):
    """An .mts file of `version` with exactly the sections `tags` in order,
    as [tag, payload] pairs; ValueError otherwise."""
    found, count = struct.unpack_from("<II", data, 8)
    if found != version or count != len(tags):
        raise ValueError("not a version-%d file" % version)
    pos = MTS_HEADER
    sections = []
    for _ in range(count):
        tag = bytes(data[pos : pos + 4])
        n = struct.unpack_from("<Q", data, pos + 4)[0]
        sections.append([tag, bytes(data[pos + 12 : pos + 12 + n])])
        pos += 12 + n
    if pos != len(data):
        raise ValueError("sections do not end at the end of the file")
    if [t for t, _ in sections] != tags:
        raise ValueError("sections %s" % [t for t, _ in sections])
    return sections


class V4File:
    """A version-4 .mts file (a hierarchy, crates/mts/src/hierarchy/format.rs)
    cut into sections, its HIER counts decoded and its GRPS section cut into
    group records, each record's layout found."""

    TAGS = [b"HIER", b"POSI", b"PROP", b"CLUS", b"CSTR", b"GRPS"]

    def __init__(self, data):
        self.version, count = struct.unpack_from("<II", data, 8)
        self.sections = split_mts_sections(data, 4, self.TAGS)
        hier = self.sections[0][1]
        p = 0
        self.counts = []
        for _ in range(6):
            v, p = get_varint(hier, p)
            self.counts.append(v)
        if p != len(hier):
            raise ValueError("HIER has %d bytes, 6 varints %d" % (len(hier), p))
        grps = self.sections[5][1]
        p = 0
        self.groups = []
        while p < len(grps):
            n = struct.unpack_from("<Q", grps, p)[0]
            self.groups.append(bytearray(grps[p + 8 : p + 8 + n]))
            p += 8 + n
        if len(self.groups) != self.counts[5]:
            raise ValueError("%d group records for %d groups" % (len(self.groups), self.counts[5]))
        self.len_delta = {}
        self.trailing = b""
        self.section_count = 6

    @staticmethod
    def layout(record):
        """Offsets in a group record: level, the six floats, the three
        lists (count offset, value offsets), the vertex map (count offset,
        value offsets), the flag, the model sections [tag, start, length]."""
        out = {}
        _, p = get_varint(record, 0)
        out["floats"] = p
        p += 24
        out["lists"] = []
        for _ in range(4):
            at = p
            n, p = get_varint(record, p)
            values = []
            for _ in range(n):
                values.append(p)
                _, p = get_varint(record, p)
            out["lists"].append((at, values))
        out["flag"] = p
        p += 1
        out["model"] = []
        while p < len(record):
            tag = bytes(record[p : p + 4])
            n = struct.unpack_from("<Q", record, p + 4)[0]
            out["model"].append([tag, p + 12, n])
            p += 12 + n
        if p != len(record):
            raise ValueError("a group's model sections overrun its record")
        return out

    def to_bytes(self):
        hier = bytearray()
        for c in self.counts:
            put_varint(hier, c)
        self.sections[0][1] = bytes(hier)
        grps = bytearray()
        for r in self.groups:
            grps += struct.pack("<Q", len(r)) + bytes(r)
        self.sections[5][1] = bytes(grps)
        body = bytearray()
        for i, (tag, payload) in enumerate(self.sections):
            n = max(0, len(payload) + self.len_delta.get(i, 0))
            body += tag + struct.pack("<Q", n & 0xFFFFFFFFFFFFFFFF) + payload
        head = b"MTSMODEL" + struct.pack("<II", self.version, self.section_count) + struct.pack("<QQ", 0, 0)
        return seal_mts(head + bytes(body) + self.trailing)


def set_varint_at(record, at, value):
    """record (bytearray) with the varint at `at` replaced by `value`."""
    _, end = get_varint(record, at)
    v = bytearray()
    put_varint(v, value)
    record[at:end] = v


HIER_SEEDS = ("terrain_h.mts", "torus_props_h.mts")
HIER_KINDS = ["truncate", "flip", "reseal_flip", "hier_count", "hier_count_huge", "section_len", "tag", "trailing",
              "version", "section_count", "group_len", "group_list_huge", "group_nan", "group_floor",
              "group_input", "group_child", "group_flag", "group_map", "group_model_flip", "clean"]
# Edits that may leave a valid hierarchy (another one, or one that draws
# other vertices: verify's camera sweep may find its cracks).
HIER_UNKNOWN = ("reseal_flip", "group_map", "group_model_flip")


def hier_edit(rng, f, kind):
    """Applies `kind` to a parsed V4File in place; returns a label, or None
    when it has nothing to change."""
    g = rng.randrange(len(f.groups))
    r = f.groups[g]
    lay = V4File.layout(r)
    if kind == "hier_count":
        i = rng.randrange(6)
        d = rng.choice([-1, 1, 2])
        if f.counts[i] + d < 0:
            d = 1
        f.counts[i] += d
        return "count%d%+d" % (i, d)
    if kind == "hier_count_huge":
        i = rng.randrange(6)
        f.counts[i] = rng.choice([2 ** 28, 2 ** 32 - 1, 2 ** 40, 2 ** 64 - 1])
        return "count%d" % i
    if kind == "section_len":
        i = rng.randrange(6)
        f.len_delta[i] = rng.choice([-1, 1, 7, 2 ** 40, 2 ** 63])
        return "section%d" % i
    if kind == "tag":
        i = rng.randrange(6)
        f.sections[i][0] = rng.choice([b"XXXX", b"hier", b"MODL", b"\x00\x00\x00\x00", f.TAGS[(i + 1) % 6]])
        return "section%d" % i
    if kind == "trailing":
        f.trailing = bytes(rng.randrange(256) for _ in range(rng.randint(1, 16)))
        return "trailing"
    if kind == "version":
        f.version = rng.choice([0, 1, 2, 3, 5, 255, 2 ** 32 - 1])
        return "v%d" % f.version
    if kind == "section_count":
        f.section_count = rng.choice([0, 5, 7, 2 ** 32 - 1])
        return "sections%d" % f.section_count
    if kind == "group_len":
        # One byte moved between two records (or out of the last).
        d = rng.choice([-1, 1])
        if d < 0:
            f.groups[g] = r[:-1]
            if g + 1 < len(f.groups):
                f.groups[g + 1] = r[-1:] + f.groups[g + 1]
            else:
                f.trailing = b""
                f.len_delta[5] = 1
        elif g + 1 < len(f.groups) and f.groups[g + 1]:
            f.groups[g] = r + f.groups[g + 1][:1]
            f.groups[g + 1] = f.groups[g + 1][1:]
        else:
            f.groups[g] = r + b"\x00"
        return "group%d%+d" % (g, d)
    if kind == "group_list_huge":
        i = rng.randrange(4)
        set_varint_at(r, lay["lists"][i][0], rng.choice([2 ** 28, 2 ** 32 - 1, 2 ** 40, 2 ** 64 - 1]))
        return "group%d:list%d" % (g, i)
    if kind == "group_nan":
        k = rng.choice([0, 1, 2, 5])  # floor, diagonal, centre.x, radius
        v = rng.choice([float("nan"), float("inf"), -float("inf"), -1.0]) if k != 2 else float("nan")
        struct.pack_into("<f", r, lay["floats"] + 4 * k, v)
        return "group%d:float%d" % (g, k)
    if kind == "group_floor":
        old = struct.unpack_from("<f", r, lay["floats"])[0]
        struct.pack_into("<f", r, lay["floats"], old * 2 + 1)
        return "group%d:floor" % g
    if kind == "group_input":
        at, values = lay["lists"][0]
        if not values:
            return None
        k = rng.randrange(len(values))
        old, _ = get_varint(r, values[k])
        new = rng.choice([old + 1, max(0, old - 1), f.counts[2], f.counts[2] + 5, 0])
        if new == old:
            return None
        set_varint_at(r, values[k], new)
        return "group%d:input%d" % (g, k)
    if kind == "group_child":
        at, values = lay["lists"][2]
        if values:
            # One child fewer.
            del r[values[-1] : lay["lists"][3][0]]
            set_varint_at(r, at, len(values) - 1)
            return "group%d:child-" % g
        if g == 0:
            return None
        set_varint_at(r, at, 1)
        tail = bytearray()
        put_varint(tail, rng.randrange(g))
        r[at + 1 : at + 1] = tail
        return "group%d:child+" % g
    if kind == "group_flag":
        r[lay["flag"]] = rng.choice([1, 2, 255])
        return "group%d:flag" % g
    if kind == "group_map":
        at, values = lay["lists"][3]
        if not values:
            return None
        k = rng.randrange(len(values))
        delta, _ = get_varint(r, values[k])
        new = zigzag(unzigzag(delta) + rng.choice([-1, 1]))
        set_varint_at(r, values[k], new)
        return "group%d:map%d" % (g, k)
    if kind == "group_model_flip":
        tag, start, n = rng.choice(lay["model"])
        if n == 0:
            return None
        i = start + rng.randrange(n)
        r[i] ^= rng.randrange(1, 256)
        return "group%d:%s" % (g, tag.decode(errors="replace"))
    raise ValueError(kind)


def structured_case(rng, family, seeds, names, kinds, unknown, parse, edit, index, quick):
    """A case of a family of whole files taken apart (hier, coded): seed
    `names[index]` from `seeds`, one of `kinds` (truncate, flip,
    reseal_flip, clean, or an edit of the file `parse` gives, resealed);
    returns the case, its expectation and a judge for runs after `verify`
    (a possibly valid edit that verify refuses but another command loads is
    a "trusted lie", counted apart, as in the reseal family)."""
    name = names[index % len(names)]
    full = seeds[name]
    kind = kinds[index % len(kinds)] if quick else rng.choice(kinds)
    label, data = kind, None
    if kind == "truncate":
        data = truncate(rng, full)
    elif kind == "flip":
        data, _ = flip(rng, full)
    elif kind == "reseal_flip":
        data = seal_mts(flip(rng, full, start=MTS_HEADER)[0])
    elif kind != "clean":
        for _ in range(20):
            f = parse(full)
            label = edit(rng, f, kind)
            if label:
                data = f.to_bytes()
                break
    if data is None:
        kind = label = "clean"
        data = full
    expect = ACCEPT if kind == "clean" else UNKNOWN if kind in unknown else GARBAGE
    case = Case(family, "%s/%s:%s" % (kind, name[:-4], label), ".mts", data)
    refused = ("clean error", "unnamed error", "valid refused", "wrong message")

    def by_verify(prev):
        if expect != UNKNOWN:
            return expect
        return TRUSTED if prev[0]["cls"] in refused else UNKNOWN

    return case, expect, by_verify


def gen_hier(rng, seeds, index, quick=False):
    case, expect, by_verify = structured_case(rng, "hier", seeds.v4, HIER_SEEDS, HIER_KINDS, HIER_UNKNOWN,
                                              V4File, hier_edit, index, quick)
    # verify decides whether a possibly valid edit lies (a crack, a group's
    # model against its replay).
    case.run(["verify", "{in}", "--lods", "2"], expect)

    case.run(["info", "{in}", "--json"] if rng.random() < 0.3 else ["info", "{in}"], by_verify)
    # A hierarchy is not a model: the model's commands refuse every one.
    case.run(rng.choice([["extract", "{in}", "--lod", "0", "--repeat", "1"],
                         ["extract", "{in}", "--ratio", "0.5", "--repeat", "1"],
                         ["extract", "{in}", "--triangles", "100", "--repeat", "1", "--json"]]), GARBAGE)
    return case


# --- version-5 files: the coded model ------------------------------------------


class V5File:
    """A version-5 .mts file (crates/mts/src/model/compress.rs): the seven
    sections of version 3, each payload a part count and parts (coding u8:
    0 stored, 1 Zstandard, 2 transposed then a row width u8, 3 the steps by
    column; decoded length, coded length varints, bytes; MODL has six). A
    part is [coding, decoded, bytes, width]."""

    TAGS = [b"META", b"POSI", b"STRP", b"STEP", b"PROP", b"CMPN", b"MODL"]

    def __init__(self, data):
        self.version, count = struct.unpack_from("<II", data, 8)
        self.sections = []
        # Version 6 (crates/mts/src/model/prefix.rs): version 5 with coarse
        # chunks first, PRFX sections of one part each.
        # Version 7: a hierarchy's six sections (crates/mts/src/hierarchy/format.rs), one part each.
        if self.version == 6:
            tags = [b"PRFX"] * (count - len(self.TAGS)) + self.TAGS
        elif self.version == 7:
            tags = V4File.TAGS
        else:
            tags = self.TAGS
        for tag, payload in split_mts_sections(data, self.version if self.version in (6, 7) else 5, tags):
            p = 0
            k, p = get_varint(payload, p)
            parts = []
            for _ in range(k):
                coding = payload[p]
                p += 1
                width = None
                if coding == 2:
                    width = payload[p]
                    p += 1
                decoded, p = get_varint(payload, p)
                coded, p = get_varint(payload, p)
                parts.append([coding, decoded, payload[p : p + coded], width])
                p += coded
            if p != len(payload):
                raise ValueError("section %s: parts end at %d of %d" % (tag, p, len(payload)))
            self.sections.append([tag, parts])
        self.count_override = {}
        self.section_count = count
        self.trailing = b""

    def to_bytes(self):
        body = bytearray()
        for i, (tag, parts) in enumerate(self.sections):
            payload = bytearray()
            put_varint(payload, self.count_override.get(i, len(parts)))
            for coding, decoded, data, width in parts:
                payload.append(coding & 0xFF)
                if width is not None:
                    payload.append(width & 0xFF)
                put_varint(payload, decoded)
                put_varint(payload, len(data))
                payload += data
            body += tag + struct.pack("<Q", len(payload)) + payload
        head = b"MTSMODEL" + struct.pack("<II", self.version, self.section_count) + struct.pack("<QQ", 0, 0)
        return seal_mts(head + bytes(body) + self.trailing)


def zstd_rle_frame(blocks, byte=0):
    """A Zstandard frame of `blocks` RLE blocks of 128 KiB each (RFC 8878:
    magic, a descriptor without content size, a 128 KiB window, 3-byte block
    headers of type 1 with the repeat count, one byte each): a few bytes
    that decode to blocks x 128 KiB."""
    out = bytearray(struct.pack("<I", 0xFD2FB528))
    out += bytes([0x00, 7 << 3])
    for i in range(blocks):
        last = 1 if i + 1 == blocks else 0
        header = last | (1 << 1) | ((128 << 10) << 3)
        out += struct.pack("<I", header)[:3] + bytes([byte])
    return bytes(out)


CODED_SEEDS = ("torus_v5.mts", "ico_optimal_v5.mts", "torus_props_v5.mts", "torus_v6.mts", "torus_props_v6.mts",
               "terrain_h7.mts")
CODED_KINDS = ["truncate", "flip", "reseal_flip", "part_count", "decoded_len", "decoded_huge", "coding",
               "stored_lie", "frame_flip", "frame_cut", "parts_swapped", "bomb", "bomb_honest", "section_count",
               "trailing", "width", "width_claimed", "clean"]
# Edits that may leave a valid model (a frame whose flipped byte decodes to
# the same, or to arrays that pass the checks and draw otherwise; a plain
# frame called transposed, which changes nothing in a part of equal rows,
# such as the zero companions: verify decides).
CODED_UNKNOWN = ("reseal_flip", "frame_flip", "width_claimed")


def coded_edit(rng, f, kind):
    """Applies `kind` to a parsed V5File in place; returns a label, or None
    when it has nothing to change."""
    i = rng.randrange(len(f.sections))
    tag, parts = f.sections[i]
    j = rng.randrange(len(parts))
    part = parts[j]
    name = "%s.%d" % (tag.decode(), j)
    if kind == "part_count":
        f.count_override[i] = rng.choice([0, len(parts) + 1, len(parts) - 1 if len(parts) > 1 else 2, 2 ** 40])
        return "%s:%d" % (tag.decode(), f.count_override[i])
    if kind == "decoded_len":
        part[1] = max(0, part[1] + rng.choice([-1, 1, 2, -2, part[1]]))
        return name
    if kind == "decoded_huge":
        part[1] = rng.choice([2 ** 32, 2 ** 40, 2 ** 63, 2 ** 64 - 1, 10 ** 12])
        return name
    if kind == "coding":
        part[0] = rng.choice([4, 127, 255])
        part[3] = None
        return name
    if kind == "width":
        # A transposed part's row width: 0, past 16, or one its length is
        # not a multiple of.
        if part[0] != 2:
            return None
        bad = [w for w in (0, 17, 255, part[3] + 1, 5, 7) if w == 0 or w > 16 or part[1] % w != 0]
        part[3] = rng.choice(bad)
        return "%s:%s" % (name, part[3])
    if kind == "width_claimed":
        # A plain frame called transposed.
        if part[0] != 1:
            return None
        part[0], part[3] = 2, rng.choice([w for w in (2, 4, 12, 16) if part[1] % w == 0] or [1])
        return "%s:%s" % (name, part[3])
    if kind == "stored_lie":
        if part[0] not in (1, 2, 3):
            return None
        part[0], part[3] = 0, None
        return name
    if kind in ("frame_flip", "frame_cut"):
        coded = [(a, b) for a, (_, ps) in enumerate(f.sections) for b, p in enumerate(ps)
                 if p[0] in (1, 2, 3) and len(p[2]) > 8]
        if not coded:
            return None
        a, b = rng.choice(coded)
        p = f.sections[a][1][b]
        data = bytearray(p[2])
        if kind == "frame_flip":
            k = rng.randrange(4, len(data))
            data[k] ^= rng.randrange(1, 256)
        else:
            del data[rng.randrange(1, len(data)) :]
        p[2] = bytes(data)
        return "%s.%d" % (f.sections[a][0].decode(), b)
    if kind == "parts_swapped":
        modls = [ps for t, ps in f.sections if t == b"MODL"]
        if not modls:
            return None
        modl = modls[0]
        a, b = rng.sample(range(len(modl)), 2)
        modl[a], modl[b] = modl[b], modl[a]
        return "MODL.%d<->%d" % (a, b)
    if kind in ("bomb", "bomb_honest"):
        # A few kilobytes that decode to up to 256 MiB: announced honestly,
        # or as the part's own length (the decoder must stop there).
        blocks = rng.choice([64, 512, 2048])
        frame = zstd_rle_frame(blocks)
        part[0], part[3] = 1, None
        part[1] = blocks * (128 << 10) if kind == "bomb_honest" else part[1]
        part[2] = frame
        return "%s:%d" % (name, blocks)
    if kind == "section_count":
        f.section_count = rng.choice([c for c in (0, 6, 7, 8, 2 ** 32 - 1) if c != len(f.sections)])
        return str(f.section_count)
    if kind == "trailing":
        f.trailing = bytes(rng.randrange(256) for _ in range(rng.randint(1, 16)))
        return "trailing"
    return None


def gen_coded(rng, seeds, index, quick=False):
    case, expect, by_verify = structured_case(rng, "coded", seeds.v5, CODED_SEEDS, CODED_KINDS, CODED_UNKNOWN,
                                              V5File, coded_edit, index, quick)
    case.run(["verify", "{in}", "--lods", "4"], expect)

    case.run(["info", "{in}", "--json"] if rng.random() < 0.3 else ["info", "{in}"], by_verify)
    # A hierarchy (version 7) is not a model: extract refuses every one.
    hierarchy = len(case.data) > MTS_HEADER and case.data[8] == 7
    case.run(rng.choice([["extract", "{in}", "--lod", "0", "--repeat", "1"],
                         ["extract", "{in}", "--ratio", "0.5", "--repeat", "1", "--json"]]),
             GARBAGE if hierarchy else by_verify)
    if len(case.data) > MTS_HEADER and case.data[8] == 6:
        # A prefix of a version-6 file, as a reader opens it while the file
        # arrives: a clean one opens from its first chunk's end on (and is
        # refused, naming the file, before); an edited one may hold intact
        # chunks, so any clean outcome will do.
        n = rng.randrange(len(case.data) + 1)
        first_end = None
        if len(case.data) >= MTS_HEADER + 12 and case.data[MTS_HEADER:MTS_HEADER + 4] == b"PRFX":
            first_end = MTS_HEADER + 12 + struct.unpack_from("<Q", case.data, MTS_HEADER + 4)[0]
        if expect == ACCEPT and first_end is not None:
            prefix_expect = ACCEPT if n >= first_end else GARBAGE
        else:
            prefix_expect = UNKNOWN
        case.run(["extract", "{in}", "--bytes", str(n), "--ratio", "0.05", "--repeat", "1"], prefix_expect)
    return case


# --- glTF compressed with EXT_/KHR_meshopt_compression (issue 35) -------------

MO_EXT, MO_KHR = "EXT_meshopt_compression", "KHR_meshopt_compression"
MO_MODES = ("ATTRIBUTES", "TRIANGLES", "INDICES")
# A refusal of a compressed view names it: "bufferView 3" (the extension's
# rules, the stream's range, the decoder) or "buffer view 3" (an accessor
# running past the view as decoded).
MO_VIEW_RE = r"(?i)\bbuffer ?view \d+"
# ... and, for a count or a stream asking for more than any valid one, the
# limit or bound it passes.
MO_LIMIT_RE = r"(?is)(?=.*\bbuffer ?view \d+)(?=.*(?:limit|at most|the most|more than|too many|exceed))"
# Runs that ask for much more than the file holds (a count of 2^40, a
# stream of zeros announcing 2^28 elements) get a lower address-space cap
# and time limit: a reader that allocates what they announce fails
# ("oom"), one that decodes it "hangs".
MO_AMPLIFY = dict(mem=512 << 20, timeout=5)


class MeshoptDoc:
    """A glTF document written by `mts convert --compress` (a .glb: the BIN
    chunk, buffer 0, holds the compressed streams; buffer 1 is the fallback,
    without data, that the views' own buffer/byteOffset/byteLength name; each
    view's extension object gives buffer, byteOffset, byteLength,
    byteStride, count, mode, filter), taken apart to be edited and written
    in any style (glb, a .gltf with input.bin, a data URI)."""

    def __init__(self, data):
        if data[:4] != b"glTF" or struct.unpack_from("<I", data, 4)[0] != 2:
            raise ValueError("not a version-2 GLB")
        n, kind = struct.unpack_from("<I4s", data, 12)
        if kind != b"JSON":
            raise ValueError("its first chunk is not JSON")
        self.j = json.loads(data[20 : 20 + n].decode(), object_pairs_hook=collections.OrderedDict)
        m, kind = struct.unpack_from("<I4s", data, 20 + n)
        if kind != b"BIN\0":
            raise ValueError("its second chunk is not BIN")
        self.bin = bytearray(data[28 + n : 28 + n + m])
        self.name = MO_EXT
        buffers = self.j.get("buffers", [])
        if len(buffers) != 2 or "uri" in buffers[0] or "uri" in buffers[1]:
            raise ValueError("buffers %s, not the BIN chunk and a fallback without uri" % buffers)
        if not self.views() or buffers[0]["byteLength"] > len(self.bin):
            raise ValueError("no compressed view, or buffer 0 longer than the BIN chunk")
        for v, view, e in self.views():
            if (e.get("buffer") != 0 or view.get("buffer") != 1 or e.get("mode") not in MO_MODES
                    or e.get("byteOffset", 0) + e["byteLength"] > buffers[0]["byteLength"]
                    or view["byteLength"] != e["byteStride"] * e["count"]):
                raise ValueError("bufferView %d: %s" % (v, json.dumps(view)))
        if self.stream_end() != buffers[0]["byteLength"]:
            raise ValueError("the last stream does not end buffer 0")

    def views(self):
        """(index, view, extension object) of every compressed view."""
        return [(v, view, view["extensions"][self.name]) for v, view in enumerate(self.j["bufferViews"])
                if self.name in view.get("extensions", {})]

    def stream_end(self):
        return max(e.get("byteOffset", 0) + e["byteLength"] for _, _, e in self.views())

    def position_views(self):
        acc = self.j["accessors"]
        return {acc[p["attributes"]["POSITION"]].get("bufferView") for m in self.j["meshes"] for p in m["primitives"]
                if "POSITION" in p["attributes"]}

    def triangles(self):
        return sum(e["count"] for _, _, e in self.views() if e["mode"] == "TRIANGLES") // 3

    def rename(self, name):
        """The extension called `name` everywhere: views, the fallback
        buffer, extensionsUsed and extensionsRequired."""
        self.j = json.loads(json.dumps(self.j).replace(self.name, name), object_pairs_hook=collections.OrderedDict)
        self.name = name

    def fit(self, v):
        """View v's own byteLength made stride x count, and the fallback
        long enough to hold it: only the edit under test breaks a rule."""
        e = self.j["bufferViews"][v]["extensions"][self.name]
        self.j["bufferViews"][v]["byteLength"] = min(e["byteStride"] * e["count"], 2 ** 64 - 1)
        self.fit_fallback()

    def fit_fallback(self):
        fallback = self.j["buffers"][1]
        ends = [view.get("byteOffset", 0) + view["byteLength"] for view in self.j["bufferViews"]
                if view.get("buffer") == 1 and isinstance(view.get("byteLength"), int)]
        fallback["byteLength"] = min(max([fallback["byteLength"]] + ends), 2 ** 64 - 1)

    def append(self, stream):
        """Appends a stream to buffer 0 (4-aligned): its byteOffset."""
        while len(self.bin) % 4:
            self.bin.append(0)
        at = len(self.bin)
        self.bin += stream
        self.j["buffers"][0]["byteLength"] = len(self.bin)
        return at

    def shift(self, after, by, keep):
        """Moves every stream but view `keep`'s starting after byte `after`
        by `by` bytes (a splice that inserts or deletes)."""
        for v, _, e in self.views():
            if v != keep and e.get("byteOffset", 0) > after:
                e["byteOffset"] += by
        self.j["buffers"][0]["byteLength"] += by

    def write(self, style):
        """(main file bytes, extension, {extra file: bytes})."""
        b0 = self.j["buffers"][0]
        b0.pop("uri", None)
        if style == "external":
            b0["uri"] = "input.bin"
        elif style == "datauri":
            import base64
            b0["uri"] = "data:application/octet-stream;base64," + base64.b64encode(bytes(self.bin)).decode()
        text = json.dumps(self.j).encode()
        if style == "glb":
            return glb_pack(text, bytes(self.bin)), ".glb", {}
        return text, ".gltf", ({"input.bin": bytes(self.bin)} if style == "external" else {})


def meshopt_zero_stream(count, stride, version):
    """An attribute stream of `count` zero elements of `stride` bytes
    (meshoptimizer's vertex codec, vertexcodec.cpp): header 0xa0 | version;
    per block of min(8192 / stride rounded down to 16, 256) elements,
    version 0 spends 2 header bits per byte channel and group of 16 (0:
    zeros), version 1 one control byte per 4 channels (0xaa: zeros); the tail
    (the baseline element, and version 1's channel modes) padded to 32 or 24
    bytes. Version 0 expands 64 x, version 1 up to 1024 x."""
    block = min((8192 // stride) & ~15, 256)
    out = bytearray([0xA0 | version])
    done = 0
    while done < count:
        size = min(block, count - done)
        if version == 0:
            out += bytes(stride * ((((size + 15) & ~15) // 16 + 3) // 4))
        else:
            out += b"\xaa" * (stride // 4)
        done += size
    tail = stride + (0 if version == 0 else stride // 4)
    out += bytes(max(tail, 32 if version == 0 else 24))
    return bytes(out)


class MCase:
    """What a meshopt generator returns: a label, the expectation, the
    document (or raw bytes and files), the style, the message a refusal must
    give, extra arguments and options (MO_AMPLIFY)."""

    def __init__(self, label, expect, doc=None, style="glb", raw=None, ext=None, files=None, must=None, argv=(),
                 amplify=False):
        self.label, self.expect, self.doc, self.style = label, expect, doc, style
        self.raw, self.ext, self.files, self.must = raw, ext, dict(files or {}), must
        self.argv, self.amplify = list(argv), amplify


def meshopt_case(rng, kind, seeds, name):
    """One input of `kind` (MESHOPT_KINDS) from seed `name`, or None when the
    seed has no view the kind needs."""
    doc = MeshoptDoc(seeds.meshopt[name])
    style = rng.choice(["glb", "glb", "external", "datauri"])
    views = doc.views()
    v, view, e = rng.choice(views)
    attrs = [x for x in views if x[2]["mode"] == "ATTRIBUTES"]
    tris = [x for x in views if x[2]["mode"] == "TRIANGLES"]
    declared = doc.j["buffers"][0]["byteLength"]
    off, length = e.get("byteOffset", 0), e["byteLength"]
    tag = "%s/%s" % (name[:-4], style)

    def at(what, expect, **kw):
        return MCase("%s:%s/%s" % (kind, what, tag), expect, doc, style, **kw)

    if kind == "clean":
        return MCase("clean/%s" % name[:-4], ACCEPT, raw=seeds.meshopt[name], ext=".glb")
    if kind == "gltf_written":
        if name not in seeds.meshopt_gltf:
            return None
        text, bin_name, data = seeds.meshopt_gltf[name]
        return MCase("gltf_written/%s" % name[:-4], ACCEPT, raw=text, ext=".gltf", files={bin_name: data})
    if kind in ("khr", "restyled"):
        if kind == "khr" or rng.random() < 0.5:
            doc.rename(MO_KHR)
        if kind == "restyled":
            style = rng.choice(["external", "datauri"])
            tag = "%s/%s" % (name[:-4], style)
        return at(doc.name[:3], ACCEPT)
    if kind == "int_float":
        # Integers written as floats (8.0): glTF's JSON numbers, read so.
        field = rng.choice(["buffer", "byteOffset", "byteLength", "byteStride", "count"])
        e[field] = float(e.get(field, 0))
        return at("view%d.%s" % (v, field), ACCEPT)
    if kind == "both_names":
        # The KHR_ object wins over EXT_ in one view: a bogus EXT_ one beside
        # a good KHR_ one is read, the other way round refused.
        bogus = dict(e)
        bogus.update(rng.choice([{"buffer": 7}, {"byteStride": 6}, {"mode": "LINES"}, {"count": 2 ** 40},
                                 {"filter": "LINEAR"}]))
        khr_good = rng.random() < 0.6
        view["extensions"][MO_KHR] = dict(e) if khr_good else bogus
        if khr_good:
            view["extensions"][MO_EXT] = bogus
        for key in ("extensionsUsed", "extensionsRequired"):
            doc.j[key].append(MO_KHR)
        return at("view%d.%s" % (v, "khr_good" if khr_good else "khr_bogus"), ACCEPT if khr_good else GARBAGE,
                  must=MO_VIEW_RE)
    if kind == "stream_swap":
        # Two streams' places swapped: attributes of one layout (texture
        # coordinates and colours, 4 bytes, no filter) read each other's,
        # valid; the triangles read an attribute stream, refused.
        pos = doc.position_views()
        plain = [x for x in attrs if x[0] not in pos and x[2].get("filter", "NONE") == "NONE"]
        pairs = [(a, b) for a in plain for b in plain if a[0] < b[0] and a[2]["byteStride"] == b[2]["byteStride"]
                 and a[2]["count"] == b[2]["count"]]
        if pairs and rng.random() < 0.6:
            (a, _, ea), (b, _, eb) = rng.choice(pairs)
            expect = ACCEPT
        elif tris and attrs:
            (a, _, ea), (b, _, eb) = rng.choice(tris), rng.choice(attrs)
            expect = GARBAGE
        else:
            return None
        for k in ("byteOffset", "byteLength"):
            ea[k], eb[k] = eb.get(k, 0), ea.get(k, 0)
        return at("view%d<->%d" % (a, b), expect, must=MO_VIEW_RE)
    if kind in ("zero_stream", "bomb"):
        # A hand-made stream of zeros in place of an attribute view's:
        # valid (within the codec's expansion and the vertex limit), or
        # announcing more elements than the limit allows, or than its bytes
        # can hold.
        plain = [x for x in attrs if x[0] not in doc.position_views() and x[2].get("filter", "NONE") == "NONE"]
        if kind == "zero_stream" and not plain and rng.random() < 0.7:
            return None  # mostly a view whose zeros leave a valid mesh
        v, view, e = rng.choice(plain if plain and rng.random() < 0.7 else attrs)
        stride, version = e["byteStride"], rng.choice([0, 1])
        bomb = None if kind == "zero_stream" else rng.choice(["limit", "max", "dishonest"])
        if bomb == "limit":
            version = 1
        # Version 1 is the KHR_ extension's (EXT_ has version 0 only).
        if version == 1 and (bomb or rng.random() < 0.8):
            doc.rename(MO_KHR)
            view = doc.j["bufferViews"][v]
            e = view["extensions"][MO_KHR]
        argv, count, expect, must, what = [], None, GARBAGE, MO_LIMIT_RE, "%s.v%d" % (doc.name[:3], version)
        if kind == "zero_stream":
            n = rng.choice([e["count"], max(e["count"], 4096), max(e["count"], 1 << 20), max(e["count"], 1 << 22)])
            ok = (v not in doc.position_views() and e.get("filter", "NONE") == "NONE"
                  and (version == 0 or doc.name == MO_KHR))
            expect, must = (ACCEPT if ok else UNKNOWN), None
        else:
            what += "," + bomb
            if bomb == "limit":
                # Past three times the default 16 M triangles: 512 MiB or
                # 1 GiB from 0.5 or 1 MB.
                n = (1 << 28) if stride == 4 else (1 << 26)
            elif bomb == "max":
                n = 1 << 20
                argv = ["--max-triangles", str(max(10000, doc.triangles() + 1000))]
            else:
                # Announcing far more elements than the stream's bytes hold.
                n, count = 4096, rng.choice([1 << 30, 1 << 36])
        stream = meshopt_zero_stream(n, stride, version)
        e.update(byteOffset=doc.append(stream), byteLength=len(stream), count=count or n)
        doc.fit(v)
        return at("view%d:%s,%d" % (v, what, count or n), expect, must=must, argv=argv, amplify=True)
    if kind == "flip":
        k = rng.choice([1, 1, 2, 3, 8])
        for _ in range(k):
            doc.bin[off + rng.randrange(length)] ^= rng.randrange(1, 256)
        return at("view%dx%d" % (v, k), UNKNOWN)
    if kind == "splice":
        op = rng.choice(["overwrite", "insert", "delete"])
        n = rng.randint(1, max(1, min(64, length - 1)))
        if op == "overwrite":
            src = rng.randrange(0, len(doc.bin) - n)
            chunk = bytes(doc.bin[src : src + n])
            dst = off + rng.randrange(0, length - n + 1)
            doc.bin[dst : dst + n] = chunk
        elif op == "insert":
            where = off + rng.randrange(0, length + 1)
            chunk = bytes(rng.randrange(256) for _ in range(n)) if rng.random() < 0.5 else bytes(doc.bin[:n])
            doc.bin[where:where] = chunk
            e["byteLength"] = length + n
            doc.shift(off, n, v)
        else:
            n = min(n, length - 1)
            where = off + rng.randrange(0, length - n + 1)
            del doc.bin[where : where + n]
            e["byteLength"] = length - n
            doc.shift(off, -n, v)
        return at("view%d:%s%d" % (v, op, n), UNKNOWN)
    if kind in ("stream_cut", "stream_extend"):
        # An attribute stream's length is known from its headers alone: one
        # byte less or more is refused (decoder: ends early, or bytes left
        # over). The index codec reads a table at the end: no verdict.
        if kind == "stream_cut":
            e["byteLength"] = length - min(length - 1, rng.choice([1, 2, 4, 16, length // 2, length - 1]))
        else:
            e["byteLength"] = length + rng.choice([1, 3, 16, 100])
        expect = GARBAGE if e["mode"] == "ATTRIBUTES" else UNKNOWN
        return at("view%d:%d->%d" % (v, length, e["byteLength"]), expect, must=MO_VIEW_RE)
    if kind == "bin_cut":
        # Buffer 0 cut short: its bytes fewer than its byteLength, or the
        # byteLength cut too and a stream past it.
        lower = rng.random() < 0.5
        if lower:
            cut = rng.randrange(4, doc.stream_end())
            doc.j["buffers"][0]["byteLength"] = cut
        else:
            cut = 4 * rng.randrange(0, declared // 4)
        del doc.bin[cut:]
        return at("%d%s" % (cut, ",byteLength" if lower else ""), GARBAGE, must=MO_VIEW_RE if lower else None)
    if kind in ("count_smaller", "count_larger"):
        step = 3 if e["mode"] == "TRIANGLES" else 1
        if kind == "count_smaller":
            e["count"] = max(step, e["count"] - step * rng.choice([1, 2, max(1, e["count"] // (2 * step))]))
        else:
            e["count"] += step * rng.choice([1, 2, 16, 1000])
        doc.fit(v)
        # Fewer elements than the accessors read: refused (by the decoder or
        # the accessor's range); more: no verdict.
        return at("view%d:%d" % (v, e["count"]), GARBAGE if kind == "count_smaller" else UNKNOWN)
    if kind == "count_huge":
        count = rng.choice([2 ** 32, 2 ** 40, 2 ** 50, 2 ** 53 - 1, 2 ** 53, 2 ** 64 - 1, 10 ** 15])
        if e["mode"] == "TRIANGLES":
            count -= count % 3
        e["count"] = count
        doc.fit(v)
        # Counts the rules let through must be refused by the expansion
        # bound or the limit; the others by the rules.
        small = count * e["byteStride"] < 2 ** 53
        return at("view%d:%d" % (v, count), GARBAGE, must=MO_LIMIT_RE if small else MO_VIEW_RE, amplify=True)
    if kind == "length_beyond":
        e["byteLength"] = rng.choice([declared - off + 1, declared - off + 4, declared + 1000, 2 ** 40, 2 ** 53 - 1,
                                      2 ** 64 - 1])
        return at("view%d:%d" % (v, e["byteLength"]), GARBAGE, must=MO_VIEW_RE)
    if kind == "offset_beyond":
        e["byteOffset"] = rng.choice([declared - length + 1, declared, declared + 4, 2 ** 40, 2 ** 53 - 1, 2 ** 64 - 1])
        return at("view%d:%d" % (v, e["byteOffset"]), GARBAGE, must=MO_VIEW_RE)
    if kind == "stride_bad":
        if e["mode"] == "ATTRIBUTES":
            e["byteStride"] = rng.choice([0, 2, 3, 6, 10, 258, 260, 512, 2 ** 32])
        else:
            e["byteStride"] = rng.choice([0, 1, 3, 6, 8, 16])
        doc.fit(v)
        return at("view%d:%s,%d" % (v, e["mode"], e["byteStride"]), GARBAGE, must=MO_VIEW_RE)
    if kind == "mode_bad":
        mode = rng.choice(["LINES", "attributes", "", "TRIANGLE_STRIP", "INDEX", 4, None, True, ["ATTRIBUTES"],
                           "missing"])
        if mode == "missing":
            del e["mode"]
        else:
            e["mode"] = mode
        return at("view%d:%s" % (v, json.dumps(mode)), GARBAGE, must=MO_VIEW_RE)
    if kind == "mode_swap":
        # A stream decoded with another codec, every rule kept: the header
        # byte (0xa?, 0xe?, 0xd?) tells them apart, refused.
        old = e["mode"]
        new = rng.choice([m for m in MO_MODES if m != old])
        if new == "TRIANGLES" and e["count"] % 3:
            new = "INDICES" if old != "INDICES" else "ATTRIBUTES"
        stride = e["byteStride"]
        if new == "ATTRIBUTES":
            stride = 4 if stride in (2, 4) else stride
        else:
            stride = stride if stride in (2, 4) else 4
        e.update(mode=new, byteStride=stride)
        e.pop("filter", None)
        if "byteStride" in view:
            if stride >= 4:
                view["byteStride"] = stride
            else:
                del view["byteStride"]
        doc.fit(v)
        return at("view%d:%s->%s" % (v, old, new), GARBAGE, must=MO_VIEW_RE)
    if kind == "filter_bad":
        stride, mode = e["byteStride"], e["mode"]
        if rng.random() < 0.3:
            f = "COLOR"  # the KHR_ extension's, refused under EXT_
            if mode != "ATTRIBUTES" or stride not in (4, 8):
                v, view, e = rng.choice([x for x in attrs if x[2]["byteStride"] in (4, 8)] or [(v, view, e)])
        elif mode != "ATTRIBUTES":
            f = rng.choice(["OCTAHEDRAL", "QUATERNION", "EXPONENTIAL"])
        else:
            bad = ["LINEAR", "octahedral", "", "NONE ", 0, None, True, ["OCTAHEDRAL"]]
            bad += (["OCTAHEDRAL"] if stride not in (4, 8) else []) + (["QUATERNION"] if stride != 8 else [])
            f = rng.choice(bad)
        e["filter"] = f
        return at("view%d:%s" % (v, json.dumps(f)), GARBAGE, must=MO_VIEW_RE)
    if kind == "filter_other":
        # Another filter the rules allow for the stride: values change, no
        # verdict.
        v, view, e = rng.choice(attrs)
        stride = e["byteStride"]
        options = ["EXPONENTIAL", "NONE"] + (["OCTAHEDRAL", "COLOR"] if stride in (4, 8) else [])
        options += ["QUATERNION"] if stride == 8 else []
        f = rng.choice([o for o in options if o != e.get("filter", "NONE")])
        if f == "COLOR":
            doc.rename(MO_KHR)
            e = doc.j["bufferViews"][v]["extensions"][MO_KHR]
        e["filter"] = f
        return at("view%d:%s" % (v, f), UNKNOWN)
    if kind == "tri_count":
        v, view, e = rng.choice(tris)
        c = e["count"]
        e["count"] = rng.choice([n for n in (c - 1, c + 1, c - 2, c + 2, 1, 2, 4) if n > 0 and n % 3])
        doc.fit(v)
        return at("view%d:%d" % (v, e["count"]), GARBAGE, must=MO_VIEW_RE)
    if kind == "parent_len":
        stride, total = e["byteStride"], e["byteStride"] * e["count"]
        if "byteStride" in view and rng.random() < 0.4:
            view["byteStride"] = rng.choice([s for s in (stride + 4, 2 * stride, 252, 4) if s != stride and s <= 252])
            what = "byteStride%d" % view["byteStride"]
        else:
            view["byteLength"] = rng.choice([total + 1, total - 1, total + stride, total - stride, 2 * total, 1])
            what = "byteLength%d" % view["byteLength"]
        doc.fit_fallback()
        return at("view%d:%s" % (v, what), GARBAGE, must=MO_VIEW_RE)
    if kind == "value_type":
        field = rng.choice(["buffer", "byteOffset", "byteLength", "byteStride", "count", "mode"])
        old = e.get(field, 0)
        if field == "mode":
            values = [0, None, ["TRIANGLES"], {"mode": old}, old.lower(), " " + old]
        else:
            values = [-1, -old - 1, old + 0.5, 2.5, str(old), None, True, [old], {"value": old}, 1e300, 2 ** 64,
                      2 ** 53]
        if field != "byteOffset":
            values.append("missing")
        value = rng.choice(values)
        if value == "missing":
            del e[field]
        else:
            e[field] = value
        return at("view%d.%s=%s" % (v, field, json.dumps(value)), GARBAGE, must=MO_VIEW_RE)
    if kind == "buffer_index":
        # Buffer 1, the fallback, has no data: the primitive is skipped (a
        # note) and the file has no triangles left; a missing buffer or a
        # bad index is refused naming the view.
        b = rng.choice([1, 1, 2, 7, 2 ** 32, 2 ** 53 - 1, 2 ** 53, -1])
        e["buffer"] = b
        return at("view%d:%d" % (v, b), GARBAGE, must=None if b == 1 else MO_VIEW_RE)
    if kind == "fallback_data":
        # The streams read from buffer 1 given data: zeros (every header
        # byte wrong, refused), random bytes (no verdict), or a copy of the
        # BIN chunk, the fallback marker removed (valid).
        fill = rng.choice(["zeros", "random", "copy"])
        fb = doc.j["buffers"][1]
        n = max(fb["byteLength"], len(doc.bin))
        if fill == "copy":
            data = bytes(doc.bin) + bytes(n - len(doc.bin))
            fb.pop("extensions", None)
            for _, _, x in views:
                x["buffer"] = 1
        else:
            data = bytes(n) if fill == "zeros" else rng.getrandbits(8 * n).to_bytes(n, "little")
            e["buffer"] = 1
        fb["byteLength"] = n
        files = {}
        if rng.random() < 0.5:
            import base64
            fb["uri"] = "data:application/octet-stream;base64," + base64.b64encode(data).decode()
        else:
            fb["uri"] = "fallback.bin"
            files["fallback.bin"] = data
        expect = {"zeros": GARBAGE, "random": UNKNOWN, "copy": ACCEPT}[fill]
        return at("%s%s" % (fill, "" if fill == "copy" else ",view%d" % v), expect, must=MO_VIEW_RE, files=files)
    if kind == "fallback_uri":
        # The fallback, which a reader that decodes the views never loads,
        # given a uri that cannot be read: read right, or refused; never a
        # hang (a FIFO) nor a crash.
        uri = rng.choice(["missing.bin", "data:application/octet-stream;base64,!!!", "data:,", "",
                          "../../nonexistent/x.bin", "/nonexistent/x.bin", "%zz.bin", "fifo.bin", "dir.bin",
                          "/dev/zero"])
        doc.j["buffers"][1]["uri"] = uri
        files = {"fifo.bin": ("fifo",)} if uri == "fifo.bin" else {"dir.bin": ("dir",)} if uri == "dir.bin" else {}
        return at(json.dumps(uri), UNKNOWN, files=files)
    if kind == "name_lie":
        lie = rng.choice(["view_misspelled", "required_misspelled", "views_khr", "used_missing"])
        if lie == "view_misspelled":
            # A view whose extension is not one the reader knows is a plain
            # view of the fallback: skipped, no triangles left.
            view["extensions"] = {rng.choice(["EXT_meshopt_compresion", "ext_meshopt_compression",
                                              "EXT_meshopt_compression ", "KHR_meshopt"]): e}
            return at("view%d" % v, GARBAGE)
        if lie == "required_misspelled":
            req = doc.j["extensionsRequired"]
            req[req.index(doc.name)] = "EXT_meshopt_compresion"
            return at("required", GARBAGE)
        if lie == "views_khr":
            # The views under one name, extensionsUsed and Required the
            # other: no verdict.
            used, required = list(doc.j["extensionsUsed"]), list(doc.j["extensionsRequired"])
            if rng.random() < 0.5:
                doc.rename(MO_KHR)
            else:
                used = [MO_KHR if u == MO_EXT else u for u in used]
                required = [MO_KHR if u == MO_EXT else u for u in required]
            doc.j["extensionsUsed"], doc.j["extensionsRequired"] = used, required
            return at("views_%s" % doc.name[:3], UNKNOWN)
        doc.j["extensionsUsed"] = [u for u in doc.j["extensionsUsed"] if u != doc.name]
        doc.j["extensionsRequired"] = [u for u in doc.j["extensionsRequired"] if u != doc.name]
        return at("used_missing", UNKNOWN)
    raise ValueError(kind)


# kind -> weight in the full run (each kind drawn once first); the --quick
# slice walks QUICK_MESHOPT in order over the two small seeds.
MESHOPT_KINDS = {
    "clean": 2, "khr": 2, "gltf_written": 1, "restyled": 2, "int_float": 1, "both_names": 1, "stream_swap": 1,
    "zero_stream": 3, "flip": 6, "splice": 3, "stream_cut": 3, "stream_extend": 2, "bin_cut": 2,
    "count_smaller": 1, "count_larger": 1, "count_huge": 4, "bomb": 2, "length_beyond": 2, "offset_beyond": 2,
    "stride_bad": 3, "mode_bad": 2, "mode_swap": 2, "filter_bad": 3, "filter_other": 1, "tri_count": 2,
    "parent_len": 2, "value_type": 4, "buffer_index": 2, "fallback_data": 2, "fallback_uri": 2, "name_lie": 2,
}
QUICK_MESHOPT = ["clean", "khr", "gltf_written", "count_huge", "flip", "stride_bad", "value_type", "filter_bad",
                 "mode_swap", "tri_count", "parent_len", "length_beyond", "offset_beyond", "buffer_index",
                 "fallback_uri", "name_lie", "zero_stream", "bomb", "stream_cut", "splice", "mode_bad", "restyled",
                 "count_huge", "flip"]
# Written by `mts convert ... --compress` (MESHOPT_SOURCES): a torus with
# properties (index stream, positions, octahedral normals, texture
# coordinates, colours), one without, one of 140k triangles (32-bit
# indices: a stride-4 index stream; full runs only).
MESHOPT_SEEDS = ("torus_props.glb", "torus.glb", "torus_u32.glb")
MESHOPT_QUICK_SEEDS = MESHOPT_SEEDS[:2]
MESHOPT_SOURCES = {"torus_props.glb": ["--generated", "torus:2k", "--properties"],
                   "torus.glb": ["--generated", "torus:2k"], "torus_u32.glb": ["--generated", "torus:140k"]}
_meshopt_expected = {}
_meshopt_lock = threading.Lock()


def meshopt_expected(seeds, name):
    """The triangles of seed `name`'s quantized, uncompressed twin (`mts
    convert --quantize`, to OBJ at seed time), read once on first use."""
    with _meshopt_lock:
        key = (seeds.dir, name)
        if key not in _meshopt_expected:
            pos, tris = read_obj_mesh(seeds.meshopt_obj[name])
            _meshopt_expected[key] = tri_keys(pos, tris)
        return _meshopt_expected[key]


def gen_meshopt(rng, seeds, index, quick=False):
    kinds = sorted(MESHOPT_KINDS)
    if quick:
        kind = QUICK_MESHOPT[index % len(QUICK_MESHOPT)]
        name = MESHOPT_QUICK_SEEDS[index % len(MESHOPT_QUICK_SEEDS)]
    else:
        if index < len(kinds):
            kind = kinds[index]
        else:
            kind = rng.choices(kinds, weights=[MESHOPT_KINDS[k] for k in kinds])[0]
        name = rng.choice(MESHOPT_SEEDS)
    mc = meshopt_case(rng, kind, seeds, name)
    if mc is None:
        # The torus with properties has every kind of view.
        name = MESHOPT_SEEDS[0]
        mc = meshopt_case(rng, kind, seeds, name)
    if mc.raw is not None:
        data, ext = mc.raw, mc.ext
    else:
        data, ext, files = mc.doc.write(mc.style)
        mc.files.update(files)
    case = Case("meshopt", mc.label, ext, data)
    for fname, content in mc.files.items():
        case.files.append((fname, content))
    names = ["{in}"]
    opts = dict(MO_AMPLIFY) if mc.amplify else {}
    # The second run: a reader beside convert. Not build or encode on the
    # 140k-triangle seed (seconds even when valid; minutes once an edit
    # makes its vertices coincide).
    second = [["convert", "{in}", "-o", "{out}.ply"], ["strips", "{in}", "--repeat", "1"]]
    if name in MESHOPT_QUICK_SEEDS:
        second += [["build", "{in}", "-o", "{out}.mts"], ["encode", "{in}", "-o", "{out}.stream"]]
    if mc.expect == ACCEPT:
        post = obj_check(meshopt_expected(seeds, name), "its quantized uncompressed twin reads")
        case.run(["convert", "{in}", "-o", "{out}.obj"] + mc.argv, ACCEPT, names=names, post=post, **opts)
        case.run(rng.choice(second[:3]) + mc.argv, ACCEPT, names=names, **opts)
    else:
        case.run(["convert", "{in}", "-o", "{out}.obj"] + mc.argv, mc.expect, names=names, must=mc.must, **opts)
        case.run(rng.choice(second) + mc.argv, mc.expect, names=names, must=mc.must, **opts)
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
        "torus_v3.mts": ["build", "--generated", "torus:200", "--uncompressed", "-o"],
        "ico_optimal_v3.mts": ["build", "--generated", "icosphere:80", "--optimal", "--uncompressed", "-o"],
        # The reseal family's (issue 31): a single band, and properties.
        "grid_single_v3.mts": ["build", "--generated", "grid:60", "--single-band", "--uncompressed", "-o"],
        "torus_props_v3.mts": ["build", "--generated", "torus:300", "--properties", "--uncompressed", "-o"],
        # The coded family's (issue 34): version 5 (no chunk), and version 6,
        # what `mts build` writes (coarse chunks first).
        "torus_v5.mts": ["build", "--generated", "torus:300", "--prefixes", "none", "-o"],
        "ico_optimal_v5.mts": ["build", "--generated", "icosphere:80", "--optimal", "--level", "3", "-o"],
        "torus_props_v5.mts": ["build", "--generated", "torus:300", "--properties", "--prefixes", "none", "-o"],
        "torus_v6.mts": ["build", "--generated", "torus:1k", "--prefixes", "5,20", "-o"],
        "torus_props_v6.mts": ["build", "--generated", "torus:1k", "--properties", "-o"],
        # The hier family's: version-4 hierarchies.
        "terrain_h.mts": ["build", "--generated", "terrain:2k", "--hierarchy", "--uncompressed", "-o"],
        "torus_props_h.mts": ["build", "--generated", "torus:1k", "--properties", "--hierarchy", "--uncompressed",
                              "-o"],
        # The coded family's hierarchy: version 7, what `mts build --hierarchy` writes.
        "terrain_h7.mts": ["build", "--generated", "terrain:2k", "--hierarchy", "-o"],
        "torus.stream": ["encode", "--generated", "torus:200", "-o"],
        "ico.stream": ["encode", "--generated", "icosphere:80", "-o"],
        "grid.stream": ["encode", "--generated", "grid:32", "-o"],
        "cube.stream": ["encode", cube, "-o"],
    }
    s.mts, s.stream, s.v3, s.v4, s.v5 = {}, {}, {}, {}, {}
    for name, argv in jobs.items():
        out = os.path.join(s.dir, name)
        p = subprocess.run([mts_bin] + argv + [out], stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL,
                           stderr=subprocess.PIPE, timeout=max(60, timeout * 3))
        if p.returncode != 0 or not os.path.exists(out):
            raise RuntimeError("seed %s: `mts %s` failed: %s" % (name, " ".join(argv), p.stderr.decode(errors="replace")[:500]))
        with open(out, "rb") as f:
            data = f.read()
        if name in RESEAL_ONLY:
            s.v3[name] = data
        elif name in HIER_SEEDS:
            s.v4[name] = data
        elif name in CODED_SEEDS:
            s.v5[name] = data
        else:
            (s.mts if name.endswith(".mts") else s.stream)[name] = data
    for name, data in list(s.mts.items()) + list(s.v3.items()):
        if name not in RESEAL_ONLY:
            MtsFile(data)  # the layout is the one this harness knows
        if name.endswith("_v3.mts"):
            try:
                f = V3File(data)
            except (ValueError, struct.error) as e:
                raise RuntimeError("seed %s: the MODL layout is not the one this harness knows: %s" % (name, e))
            if f.to_bytes() != data:
                raise RuntimeError("seed %s: taking the version-3 file apart and back changes it" % name)
        if seal_mts(data) != data:
            raise RuntimeError("seed %s: resealing changes it; the .mts checksum is not the one of its version" % name)
    for name, data in s.v5.items():
        try:
            f = V5File(data)
        except (ValueError, struct.error, IndexError) as e:
            raise RuntimeError("seed %s: the version-5 layout is not the one this harness knows: %s" % (name, e))
        if f.to_bytes() != data:
            raise RuntimeError("seed %s: taking the version-5 file apart and back changes it" % name)
    for name, data in s.v4.items():
        try:
            f = V4File(data)
        except (ValueError, struct.error, IndexError) as e:
            raise RuntimeError("seed %s: the version-4 layout is not the one this harness knows: %s" % (name, e))
        if f.to_bytes() != data:
            raise RuntimeError("seed %s: taking the version-4 file apart and back changes it" % name)
    for name, data in s.stream.items():
        if seal_stream(data) != data:
            raise RuntimeError("seed %s: resealing changes it; the stream checksum is not FNV-1a/32" % name)
    s.stream_path = os.path.join(s.dir, "torus.stream")
    s.mts_path = os.path.join(s.dir, "torus.mts")
    s.mts3_path = os.path.join(s.dir, "torus_v3.mts")
    for name in ("torus_v3.mts", "ico_optimal_v3.mts"):
        s.v3[name] = s.mts[name]
    make_meshopt_seeds(s, mts_bin, timeout)
    return s


def make_meshopt_seeds(s, mts_bin, timeout):
    """The meshopt family's seeds: each of MESHOPT_SOURCES written compressed
    (.glb; the first also as .gltf and .bin) and quantized without
    compression, the latter converted to OBJ (what an accepted case must
    read: meshopt_expected)."""
    s.meshopt, s.meshopt_obj, s.meshopt_gltf = {}, {}, {}

    def mts(argv):
        p = subprocess.run([mts_bin] + argv, stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL,
                           stderr=subprocess.PIPE, timeout=max(60, timeout * 3))
        if p.returncode != 0 or not os.path.exists(argv[-1]):
            raise RuntimeError("seed %s: `mts %s` failed: %s" % (os.path.basename(argv[-1]), " ".join(argv),
                                                                 p.stderr.decode(errors="replace")[:500]))

    for name, source in MESHOPT_SOURCES.items():
        base = os.path.join(s.dir, name[:-4])
        mts(["convert"] + source + ["--compress", "-o", base + ".glb"])
        mts(["convert"] + source + ["--quantize", "-o", base + "_q.glb"])
        mts(["convert", base + "_q.glb", "-o", base + "_q.obj"])
        with open(base + ".glb", "rb") as f:
            data = f.read()
        try:
            MeshoptDoc(data)
        except (ValueError, KeyError, TypeError, IndexError, struct.error) as e:
            raise RuntimeError("seed %s: the compressed glTF layout is not the one this harness knows: %s" % (name, e))
        s.meshopt[name] = data
        s.meshopt_obj[name] = base + "_q.obj"
    name = MESHOPT_SEEDS[0]
    base = os.path.join(s.dir, name[:-4])
    mts(["convert"] + MESHOPT_SOURCES[name] + ["--compress", "-o", base + ".gltf"])
    with open(base + ".gltf", "rb") as f:
        text = f.read()
    uri = json.loads(text)["buffers"][0].get("uri", "")
    if not re.match(r"^[A-Za-z0-9_.-]+$", uri) or not os.path.isfile(os.path.join(s.dir, uri)):
        raise RuntimeError("seed %s: the .gltf's buffer 0 is %r, not a .bin beside it" % (name, uri))
    with open(os.path.join(s.dir, uri), "rb") as f:
        s.meshopt_gltf[name] = (text, uri, f.read())


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
    if family == "extreme":
        return gen_extreme(rng, seeds, family_index, quick)
    gen = {"gltf": gen_gltf, "amplify": gen_amplify, "fifo": gen_fifo, "output": gen_output, "view": gen_view,
           "props": gen_props, "reseal": gen_reseal, "hier": gen_hier, "coded": gen_coded,
           "meshopt": gen_meshopt}[family]
    return gen(rng, seeds, family_index, quick)


OOM_MARKS = ("memory allocation of", "capacity overflow", "out of memory", "cannot allocate memory",
             "os error 12", "allocation failed")
PANIC_MARKS = ("panicked at", "has overflowed its stack", "fatal runtime error")


def execute(argv, cwd, timeout, mem_bytes, stdout="null", fsize=None):
    """Runs argv; stdout: "null" (/dev/null), "full" (/dev/full: every write
    fails with ENOSPC) or "closed" (a pipe whose read end is closed before
    the start: every write fails with EPIPE, or SIGPIPE); fsize: a cap on
    the bytes a written file may reach (RLIMIT_FSIZE, SIGXFSZ ignored, so
    that a write past it fails with EFBIG half-way through an output)."""
    def limits():
        resource.setrlimit(resource.RLIMIT_AS, (mem_bytes, mem_bytes))
        resource.setrlimit(resource.RLIMIT_CORE, (0, 0))
        cap = fsize if fsize is not None else 4 << 30
        resource.setrlimit(resource.RLIMIT_FSIZE, (cap, cap))
        if fsize is not None:
            signal.signal(signal.SIGXFSZ, signal.SIG_IGN)

    # No display: `mts view` can never open a window here, so an argument
    # it should refuse first shows as another error ("wrong message").
    env = dict(os.environ, RUST_BACKTRACE="0", LC_ALL="C", NO_COLOR="1")
    for k in ("DISPLAY", "WAYLAND_DISPLAY", "WAYLAND_SOCKET"):
        env.pop(k, None)
    out_fd, close_fd = subprocess.DEVNULL, None
    if stdout == "full":
        out_fd = close_fd = os.open("/dev/full", os.O_WRONLY)
    elif stdout == "closed":
        r, w = os.pipe()
        os.close(r)
        out_fd = close_fd = w
    with tempfile.TemporaryFile(dir=cwd) as err:
        t0 = time.monotonic()
        try:
            p = subprocess.Popen(argv, cwd=cwd, stdin=subprocess.DEVNULL, stdout=out_fd, stderr=err,
                                 preexec_fn=limits, start_new_session=True, env=env)
        finally:
            if close_fd is not None:
                os.close(close_fd)
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


def classify(rc, timed_out, stderr, expect, target, opts=None):
    """target: a path, or a list of names one of which the error must give.
    opts: must (a regex the refusal must match), stdout ("closed": the
    command must end quietly, exit 0, 141 or SIGPIPE, no error text),
    skip_re (an environment failure, e.g. no GPU adapter: "skipped")."""
    opts = opts or {}
    low = stderr.lower()
    if timed_out:
        return "hang"
    if any(m in low for m in OOM_MARKS) or rc == -signal.SIGKILL:
        return "oom"
    quiet = opts.get("stdout") == "closed"
    if quiet and rc in (141, -signal.SIGPIPE):
        rc = 0
    if any(m in low for m in PANIC_MARKS) or rc < 0:
        return "panic"
    if opts.get("skip_re") and rc != 0 and re.search(opts["skip_re"], stderr):
        return "skipped"
    if quiet and expect != UNKNOWN:
        if rc != 0:
            return "valid refused"
        if re.search(r"(?im)^error|broken pipe|os error 32", stderr):
            return "wrong message"
        return "ok"
    if rc == 0:
        return "garbage accepted" if expect == GARBAGE else "trusted lie" if expect == TRUSTED else "ok"
    if expect == ACCEPT:
        return "valid refused"
    if expect == GARBAGE and opts.get("one_line") and len(re.findall(r"(?m)^error", stderr)) != 1:
        return "wrong message"
    if expect == GARBAGE and opts.get("must"):
        # clap's own refusals (an unknown option, its usage) do not count
        said = "\n".join(l for l in stderr.splitlines()
                         if not re.search(r"unexpected argument|^\s*tip:|^Usage:|For more information", l))
        if not re.search(opts["must"], said):
            return "wrong message"
    names = target if isinstance(target, list) else [target] if target else []
    if names and not any(n in stderr or os.path.basename(n.rstrip("/")) in stderr for n in names):
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
    if cls == "wrong result":
        return (cls, cmd, "%s/%s: %s" % (family, kind.split("/")[0].split(":")[0], re.sub(r"\d+", "N", stderr)[:200]))
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


def make_files(case, cdir, state):
    """Makes the case's extra files in `cdir` (see Case.files); records in
    `state` which read-only folders could be made so ("rodir" False where
    even root could still write there) and which need undoing."""
    for name, spec in case.files:
        path = os.path.join(cdir, name)
        if isinstance(spec, (bytes, bytearray)):
            with open(path, "wb") as f:
                f.write(spec)
        elif spec[0] == "fifo":
            os.mkfifo(path)
        elif spec[0] == "dir":
            os.makedirs(path, exist_ok=True)
        elif spec[0] == "rodir":
            os.makedirs(path, exist_ok=True)
            state.setdefault("undo", []).append(path)
            state["rodir"] = make_readonly(path)
        elif spec[0] == "symlink":
            os.symlink(spec[1].replace("{dir}", cdir), path)
        elif spec[0] == "hardlink":
            os.link(os.path.join(cdir, spec[1]), path)
        else:
            raise ValueError(spec)


class PostEnv:
    """What a post check sees: the run's exit status, its case directory and
    output prefix, the state the pre hooks recorded, and `mts(argv)` to run
    the binary again (exit status, stderr)."""

    def __init__(self, ctx, cdir, out, rc, state):
        self.cdir, self.out, self.rc, self.state = cdir, out, rc, state
        self._ctx = ctx

    def mts(self, argv):
        rc, timed_out, _, stderr = execute([self._ctx.mts] + argv, self.cdir, self._ctx.timeout, self._ctx.mem_bytes)
        return (rc if not timed_out else -1), stderr


def run_case(case_spec, ctx):
    index, family, family_index = case_spec
    case = build_case(ctx.seed, index, family, ctx.seeds, family_index, ctx.render_budget, ctx.quick)
    cdir = os.path.join(ctx.root, "c%05d" % index)
    os.makedirs(cdir)
    state = {}
    results = []
    pre_failed = None
    try:
        try:
            make_files(case, cdir, state)
        except OSError as e:
            pre_failed = "cannot make the case's files: %s" % e
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

        def subst(a, out):
            a = a.replace("{in}", target or "").replace("{out}", out).replace("{dir}", cdir)
            a = re.sub(r"\{out(\d+)\}", lambda m: os.path.join(cdir, "out" + m.group(1)), a)
            a = a.replace("{seed:obj}", ctx.seeds.obj_path).replace("{seed:stream}", ctx.seeds.stream_path)
            return a.replace("{seed:mts3}", ctx.seeds.mts3_path).replace("{seed:mts}", ctx.seeds.mts_path)

        for k, (argv, expect, names_target, opts) in enumerate(case.runs):
            out = os.path.join(cdir, "out%d" % k)
            real = [subst(a, out) for a in argv]
            dependent = callable(expect)
            if dependent:
                expect = expect(results)
            if pre_failed or (opts.get("needs") and not state.get(opts["needs"])) or (dependent and expect is None):
                why = pre_failed or ("the run it depends on failed" if dependent and expect is None else
                                     "the environment cannot make this case (%s)" % opts.get("needs"))
                results.append(dict(index=index, family=case.family, kind=case.kind, cls="skipped", rc=None,
                                    seconds=0, expect=expect, argv=real, input_bytes=size, stderr=[why],
                                    file_error=False, place=None, post=None,
                                    sig=["skipped", argv[0], why[:120]]))
                continue
            for path in opts.get("hash", ()):
                state["hash:" + path] = sha(path.replace("{dir}", cdir))
            for d in opts.get("list", ()):
                state["list:" + d] = listing(d.replace("{dir}", cdir))
            timeout = min(ctx.timeout, opts["timeout"]) if opts.get("timeout") else ctx.timeout
            mem = min(ctx.mem_bytes, opts["mem"]) if opts.get("mem") else ctx.mem_bytes
            rc, timed_out, elapsed, stderr = execute([ctx.mts] + real, cdir, timeout, mem,
                                                     stdout=opts.get("stdout", "null"), fsize=opts.get("fsize"))
            has_file = names_target and case.family != "args"
            names = None
            if opts.get("names"):
                names = [subst(n, out) for n in opts["names"]]
            elif has_file:
                names = target
            cls = classify(rc, timed_out, stderr, expect, names, opts)
            post_msg = None
            if opts.get("post") and cls in ("ok", "clean error", "unnamed error"):
                post_msg = opts["post"](PostEnv(ctx, cdir, out, rc, state))
                if post_msg:
                    cls = "wrong result"
            file_run = bool(names) and names_target and case.family != "args"
            r = dict(index=index, family=case.family, kind=case.kind, cls=cls, rc=rc, seconds=round(elapsed, 3),
                     expect=expect, argv=real, input_bytes=size, stderr=first_lines(stderr), post=post_msg,
                     stdout=opts.get("stdout", "null"), fsize=opts.get("fsize"),
                     file_error=file_run and cls in ("clean error", "unnamed error"),
                     place=names_place(stderr) if file_run and cls in ("clean error", "unnamed error") else None,
                     sig=list(signature(cls, (argv[0] + " " + argv[1]) if argv[0] == "bench" else argv[0],
                                        post_msg if cls == "wrong result" else stderr,
                                        case.family, case.kind if case.family != "args" else " ".join(argv))))
            if post_msg:
                r["stderr"] = ["post check: " + post_msg] + r["stderr"][:2]
            results.append(r)
    finally:
        for d in state.get("undo", ()):
            undo_readonly(d)
    bad = [r for r in results if r["cls"] not in ("clean error", "ok", "skipped")]
    kept = None
    if case.path is not None and not case.path.startswith("{dir}"):
        kept = case.path
    elif bad and ctx.keep and (case.files or (case.path or "").startswith("{dir}")):
        # A scene of several files (a FIFO, a .bin beside a .gltf, ...):
        # made again from its description in a folder of its own.
        name = "%05d-%s-%s" % (index, case.family, re.sub(r"[^A-Za-z0-9_.-]+", "_", case.kind))
        kdir = os.path.join(os.path.abspath(ctx.keep), name)
        shutil.rmtree(kdir, ignore_errors=True)
        os.makedirs(kdir)
        make_files(case, kdir, {})
        for d in [os.path.join(kdir, n) for n, spec in case.files if not isinstance(spec, bytes) and spec[0] == "rodir"]:
            undo_readonly(d)
        if case.data is not None and target is not None:
            shutil.copyfile(target, os.path.join(kdir, os.path.basename(target)))
        kept = kdir
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
            if kept and a == target and not os.path.isdir(kept):
                a = kept
            a = a.replace(ctx.seeds.dir, ctx.seed_shown)
            if kept and os.path.isdir(kept):
                a = a.replace(cdir, kept)
            a = a.replace(cdir + "/", "").replace(cdir, ".")
            shown.append(a)
        r["argv"] = shown
        r["stderr"] = [l.replace(cdir + "/", "").replace(ctx.seeds.dir, ctx.seed_shown) for l in r["stderr"]]
    shutil.rmtree(cdir, ignore_errors=True)
    return results


def plan(count, families, seed, quick=False):
    """(index, family, index within family) for every input: counts by
    weight over the chosen families, interleaved by a seeded shuffle. With
    --quick, the issue-19 families share QUICK_COUNT inputs that way (the
    slice CI ran before issue 31, unchanged), and each issue-31 family
    adds its QUICK_SLICE after them."""
    if quick:
        old = [f for f in families if f in OLD_FAMILIES]
        out = plan(QUICK_COUNT, old, seed) if old else []
        for f in families:
            if f in NEW_FAMILIES:
                out += [(len(out) + k, f, k) for k in range(QUICK_SLICE[f])]
        return out
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
            ("valid refused", "valid-ref"), ("wrong message", "wrong-msg"), ("wrong result", "wrong-res"),
            ("unnamed error", "unnamed"), ("skipped", "skip"), ("trusted lie", "trusted")]
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


CLOSED_PIPE = ("python3 -c 'import os,subprocess,sys; r,w=os.pipe(); os.close(r); "
               "sys.exit(subprocess.call(sys.argv[1:], stdout=w))' ")


def shown_command(r):
    """The run as a shell command line, with its stdout and file-size
    conditions."""
    cmd = shell_join(["mts"] + r["argv"])
    if r.get("stdout") == "full":
        cmd += " > /dev/full"
    elif r.get("stdout") == "closed":
        cmd = CLOSED_PIPE + cmd
    if r.get("fsize"):
        cmd = "(trap '' XFSZ; ulimit -f %d; %s)" % (max(1, r["fsize"] // 1024), cmd)
    return cmd


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
    if a.quick and not any(f in OLD_FAMILIES for f in families):
        count = 0
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
        specs = plan(count, families, seed, a.quick)
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
    bad = [r for r in results if r["cls"] not in ("clean error", "ok", "trusted lie")]
    failing = [r for r in bad if r["cls"] in FAILING]
    causes = collections.OrderedDict()
    for r in sorted(bad, key=lambda r: (r["input_bytes"], r["index"])):
        key = tuple(r["sig"])
        if key not in causes:
            causes[key] = dict(cls=r["cls"], command=shown_command(r), family=r["family"],
                               kind=r["kind"], input_bytes=r["input_bytes"], stderr=r["stderr"][:1], runs=0,
                               kept=r.get("kept"))
        causes[key]["runs"] += 1
    if bad:
        print("\nnon-clean runs (%d; %d panic/hang/oom/garbage accepted):" % (len(bad), len(failing)), file=out)
        shown = bad if not a.list_limit else bad[: a.list_limit]
        for r in sorted(shown, key=lambda r: (FAILING + ("unnamed error", "skipped")).index(r["cls"]) * 10 ** 6 + r["index"]):
            print("  [%s] %s/%s  (%s s, exit %s)" % (r["cls"], r["family"], r["kind"], r["seconds"], r["rc"]), file=out)
            print("    %s" % shown_command(r), file=out)
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
