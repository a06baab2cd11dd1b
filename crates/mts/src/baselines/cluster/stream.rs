//! The cluster tree's packet stream, sections 5 ("Linearization") and 6
//! ("Transmission protocol") of the cluster-tree paper, and its incremental
//! decoder (section 7, "Model reconstruction").
//!
//! Layout (bits packed least significant first, see `baselines/bits.rs`):
//!
//! ```text
//! header   magic "MTSCT\0\0\x01", vertices, triangles, roots, base
//!          triangles (u32 each), FNV-1a/32 checksum of the body (u32)
//! body     root positions (3 × f32 each), base triangles (3 indices of
//!          width_for(roots) bits each), then packets in refinement order:
//!   new_vertex    tag 0 | parent (width_for(v) bits) | x y z (f32) |
//!                 update list: one bit per triangle holding the parent's
//!                 representative, in triangle order
//!   new_triangle  tag 1 | third vertex (width_for(v) bits) | orientation
//! ```
//!
//! `v` is the number of vertices decoded before the new one, so index
//! widths grow with the mesh instead of being fixed at 16 bits (the paper's
//! Table 1 uses 16; "sized to the model" taken per packet). A new triangle
//! is `(new, parent, third)` with orientation 1 and `(parent, new, third)`
//! with 0. Decoding stops when the header's counts are reached.
//!
//! Any prefix at least as long as the header decodes to a valid mesh: a
//! packet is read whole before it is applied, and one cut short is dropped.
//!
//! A mesh with properties, or a hierarchy whose steps move several
//! vertices (a simplification sequence on a mesh with seams), is written
//! in the second format (magic `MTSCT\0\0\x02`): the header adds a flags
//! word before the checksum (bits 0 to 2 the property streams of
//! `baselines/props.rs`, bit 3 companions); every position, root or new
//! vertex, is followed by its property values; with companions a step's
//! new vertices come first and then its triangles, each naming its new
//! vertex by its distance back from the newest (Elias gamma). In both
//! formats a triangle's third vertex is written with the new vertex
//! skipped (`width_for(v - 1)` bits), which for the first format is the
//! width above. Streams of meshes with neither stay byte for byte in the
//! first format.

use super::super::bits::{width_for, BitReader, BitWriter};
use super::super::pm::ProgressiveMesh;
use super::super::props;
use crate::error::{Error, Place, Result};
use crate::mesh::{is_degenerate, Mesh, Properties};
use glam::Vec3;
use std::path::PathBuf;

/// Magic bytes of the packet stream.
pub const MAGIC: &[u8; 8] = b"MTSCT\0\0\x01";
/// Bytes before the body: magic, four counts and the checksum.
pub const HEADER_BYTES: usize = 8 + 5 * 4;
/// Magic bytes of the second format (properties or companions).
pub const MAGIC_V2: &[u8; 8] = b"MTSCT\0\0\x02";
/// Bytes before the body in the second format: the flags word added.
pub const HEADER_BYTES_V2: usize = HEADER_BYTES + 4;
/// Flag bit of the second format: triangles name their new vertex.
const COMPANIONS: u64 = 8;

/// Linearizes a vertex-split hierarchy (the cluster tree's, or any
/// [`ProgressiveMesh`]) into the packet stream. The update lists are
/// computed by running the decoder's own bookkeeping beside the splits.
/// O(size of the stream + triangles).
#[must_use]
pub fn encode(pm: &ProgressiveMesh) -> Vec<u8> {
    let n = pm.positions.len();
    let max_lod = pm.alive.len() - 1;
    let roots = pm.roots();
    let base = pm.alive[max_lod] as usize;
    let flags = props::flags(&pm.properties) | if pm.present.is_empty() { 0 } else { COMPANIONS };
    let mut w = BitWriter::default();
    for (v, p) in pm.positions[..roots].iter().enumerate() {
        for x in p.to_array() {
            w.f32(x);
        }
        props::write(&mut w, &pm.properties, v);
    }
    let mut holders: Vec<Vec<u32>> = vec![Vec::new(); n];
    for (j, f) in pm.faces[..base].iter().enumerate() {
        for &v in f {
            w.put(u64::from(v), width_for(roots as u64));
            holders[v as usize].push(j as u32);
        }
    }
    // The decoder's triangles replayed coarse to fine, and which step
    // moves each corner.
    let mut list: Vec<u32> = pm.faces.iter().flatten().copied().collect();
    let mut mark = vec![u32::MAX; list.len()];
    for i in (0..max_lod).rev() {
        let vs = pm.step_vertices(i);
        for c in pm.corners_of(i) {
            mark[pm.corners[c] as usize] = i as u32;
        }
        for r in vs.clone() {
            let k = pm.parent_of(r);
            w.bit(false);
            w.put(u64::from(k), width_for(r as u64));
            for x in pm.positions[r].to_array() {
                w.f32(x);
            }
            props::write(&mut w, &pm.properties, r);
            for j in std::mem::take(&mut holders[k as usize]) {
                let at = 3 * j as usize;
                let c = list[at..at + 3].iter().position(|&x| x == k).unwrap_or(0);
                let moves = mark[at + c] == i as u32;
                w.bit(moves);
                if moves {
                    list[at + c] = r as u32;
                }
                holders[if moves { r } else { k as usize }].push(j);
            }
        }
        let (after, before) = (pm.alive[i + 1] as usize, pm.alive[i] as usize);
        for (j, f) in pm.faces.iter().enumerate().take(before).skip(after) {
            let r = vs
                .clone()
                .find(|&r| f.contains(&(r as u32)) && f.contains(&pm.parent_of(r)))
                .expect("a face of step i holds a vertex of the step and its target")
                as u32;
            let k = pm.parent_of(r as usize);
            let at = f.iter().position(|&v| v == r).unwrap_or(0);
            let new_first = f[(at + 1) % 3] == k;
            let third = if new_first {
                f[(at + 2) % 3]
            } else {
                f[(at + 1) % 3]
            };
            w.bit(true);
            if flags & COMPANIONS != 0 {
                w.gamma((vs.end - 1) as u64 - u64::from(r));
            }
            w.put(
                u64::from(third - u32::from(third > r)),
                width_for((vs.end - 1) as u64),
            );
            w.bit(new_first);
            for v in [r, k, third] {
                holders[v as usize].push(j as u32);
            }
        }
    }
    let body = w.finish();
    let v2 = flags != 0;
    let mut out = Vec::with_capacity(HEADER_BYTES_V2 + body.len());
    out.extend_from_slice(if v2 { MAGIC_V2 } else { MAGIC });
    for v in [n, pm.faces.len(), roots, base] {
        out.extend_from_slice(&(v as u32).to_le_bytes());
    }
    if v2 {
        out.extend_from_slice(&(flags as u32).to_le_bytes());
    }
    out.extend_from_slice(&crate::checksum::fnv1a32(&body).to_le_bytes());
    out.extend_from_slice(&body);
    out
}

/// What a (possibly partial) stream decoded to.
#[derive(Debug, Clone, PartialEq)]
pub struct Decoded {
    /// Vertices decoded so far, in stream order.
    pub positions: Vec<Vec3>,
    /// Their property streams (those the stream carries; no position ids).
    pub properties: Properties,
    /// Triangles decoded so far (indices into `positions`), never
    /// degenerate.
    pub triangles: Vec<[u32; 3]>,
    /// The header's counts: the whole stream's vertices and triangles.
    pub total_vertices: usize,
    /// See `total_vertices`.
    pub total_triangles: usize,
    /// Bytes of the input whose packets were applied (header included).
    pub bytes_used: usize,
}

impl Decoded {
    /// Whether every vertex and triangle of the stream arrived.
    #[must_use]
    pub fn is_complete(&self) -> bool {
        self.positions.len() == self.total_vertices && self.triangles.len() == self.total_triangles
    }

    /// The decoded mesh with vertices no triangle uses yet dropped
    /// (renumbered in first use, [`Mesh::level`]), with their properties,
    /// so that it passes [`Mesh::validate`].
    /// O(V + T).
    #[must_use]
    pub fn mesh(&self) -> Mesh {
        Mesh::level(&self.positions, &self.triangles, &self.properties)
    }
}

/// Decodes a whole stream.
///
/// # Errors
/// [`Error::Parse`] with the byte offset and packet: wrong magic, truncated
/// header or body, checksum mismatch, an index out of range, a degenerate
/// triangle, a non-finite coordinate, counts that disagree with the
/// header, trailing bytes.
pub fn decode(bytes: &[u8], file: &str) -> Result<Decoded> {
    decode_with(bytes, file, true)
}

/// Decodes the longest prefix of packets that `bytes` holds completely:
/// what a receiver draws while the stream is still arriving. The checksum
/// is not checked (it covers the whole body).
///
/// # Errors
/// A header shorter than [`HEADER_BYTES`] or not a stream's, and any
/// corruption [`decode`] reports inside the complete packets.
pub fn decode_prefix(bytes: &[u8], file: &str) -> Result<Decoded> {
    decode_with(bytes, file, false)
}

fn header_error(file: &str, byte: usize, message: impl Into<String>) -> Error {
    Error::Parse {
        file: PathBuf::from(file),
        place: Place {
            element: Some("header".into()),
            ..Place::default()
        }
        .at_byte(byte as u64),
        message: message.into(),
    }
}

fn decode_with(bytes: &[u8], file: &str, strict: bool) -> Result<Decoded> {
    if bytes.len() < HEADER_BYTES {
        return Err(header_error(
            file,
            bytes.len(),
            format!(
                "truncated: {} bytes, the header has {HEADER_BYTES}",
                bytes.len()
            ),
        ));
    }
    let v2 = &bytes[..8] == MAGIC_V2;
    if &bytes[..8] != MAGIC && !v2 {
        return Err(header_error(
            file,
            0,
            "not a cluster-tree stream (bad magic)",
        ));
    }
    let header = if v2 { HEADER_BYTES_V2 } else { HEADER_BYTES };
    if bytes.len() < header {
        return Err(header_error(
            file,
            bytes.len(),
            format!("truncated: {} bytes, the header has {header}", bytes.len()),
        ));
    }
    let word = |i: usize| {
        let at = 8 + 4 * i;
        u32::from_le_bytes([bytes[at], bytes[at + 1], bytes[at + 2], bytes[at + 3]]) as usize
    };
    let (n, t, roots, base) = (word(0), word(1), word(2), word(3));
    let (flags, checksum) = if v2 {
        (word(4) as u64, word(5) as u32)
    } else {
        (0, word(4) as u32)
    };
    if flags & !(props::KNOWN_FLAGS | COMPANIONS) != 0 {
        return Err(header_error(
            file,
            24,
            format!("flags {flags:#x}: unknown bits"),
        ));
    }
    if n < 3 || t == 0 {
        return Err(header_error(
            file,
            8,
            format!(
                "{n} vertices and {t} triangles: a stream encodes a mesh of at least one \
                 triangle"
            ),
        ));
    }
    if roots > n || roots == 0 || base > t {
        return Err(header_error(
            file,
            8,
            format!("inconsistent counts: {n} vertices, {roots} roots, {t} triangles, {base} base"),
        ));
    }
    let body = &bytes[header..];
    if strict && crate::checksum::fnv1a32(body) != checksum {
        return Err(header_error(
            file,
            header - 4,
            "checksum mismatch: the body is corrupt",
        ));
    }
    let mut d = Decoded {
        positions: Vec::new(),
        properties: props::empty(flags),
        triangles: Vec::new(),
        total_vertices: n,
        total_triangles: t,
        bytes_used: header,
    };
    let mut r = BitReader::new(body, file);
    let mut state = State {
        header,
        flags,
        holders: Vec::new(),
        parents: Vec::new(),
        update: Vec::new(),
    };
    match decode_body(&mut r, &mut d, &mut state, roots, base) {
        Ok(()) => {}
        Err(_) if !strict && r.ran_out => {}
        Err(e) => return Err(shift(e, header)),
    }
    if strict {
        if !d.is_complete() {
            return Err(shift(
                r.error(
                    "end",
                    format!(
                        "{} vertices and {} triangles decoded, the header says {n} and {t}",
                        d.positions.len(),
                        d.triangles.len()
                    ),
                ),
                header,
            ));
        }
        r.finish("end").map_err(|e| shift(e, header))?;
    }
    Ok(d)
}

/// Body offsets to file offsets (`header` bytes before the body).
fn shift(e: Error, header: usize) -> Error {
    match e {
        Error::Parse {
            file,
            mut place,
            message,
        } => {
            place.byte = place.byte.map(|b| b + header as u64);
            Error::Parse {
                file,
                place,
                message,
            }
        }
        e => e,
    }
}

/// The decoder's bookkeeping besides what it decoded.
struct State {
    /// Bytes before the body.
    header: usize,
    /// The header's flags (property streams, companions).
    flags: u64,
    /// Triangles holding each vertex.
    holders: Vec<Vec<u32>>,
    /// Parent of each decoded vertex (`u32::MAX` for roots).
    parents: Vec<u32>,
    /// Scratch for a packet's update list.
    update: Vec<bool>,
}

/// Decodes units (a root, a base triangle, a packet) until the counts are
/// reached; each unit is read whole before it changes `d`.
fn decode_body(
    r: &mut BitReader<'_>,
    d: &mut Decoded,
    s: &mut State,
    roots: usize,
    base: usize,
) -> Result<()> {
    let header = s.header;
    let commit = |r: &BitReader<'_>, d: &mut Decoded| {
        d.bytes_used = header + r.position().div_ceil(8) as usize;
    };
    for _ in 0..roots {
        let p = [
            r.finite_f32("root")?,
            r.finite_f32("root")?,
            r.finite_f32("root")?,
        ];
        let values = props::read(r, s.flags, "root properties")?;
        d.positions.push(Vec3::from_array(p));
        values.push(&mut d.properties);
        s.holders.push(Vec::new());
        s.parents.push(u32::MAX);
        commit(r, d);
    }
    for _ in 0..base {
        let w = width_for(roots as u64);
        let mut f = [0u32; 3];
        for x in &mut f {
            *x = r.get(w, "base triangle")? as u32;
        }
        if f.iter().any(|&v| v as usize >= roots) || is_degenerate(f) {
            return Err(r.error(
                "base triangle",
                format!("bad triangle {f:?} over {roots} roots"),
            ));
        }
        push_triangle(d, &mut s.holders, f);
        commit(r, d);
    }
    while !d.is_complete() {
        let is_triangle = r.bit("packet tag")?;
        let v = d.positions.len() as u32;
        if is_triangle {
            // The new vertex the triangle joins: the newest, or with
            // companions the one its distance back names.
            let back = if s.flags & COMPANIONS != 0 {
                r.gamma("new_triangle vertex")?
            } else {
                0
            };
            let new = if back < u64::from(v) - roots as u64 {
                v - 1 - back as u32
            } else {
                u32::MAX
            };
            if new == u32::MAX || s.parents[new as usize] == u32::MAX {
                return Err(r.error("new_triangle", "a triangle before any new vertex"));
            }
            let parent = s.parents[new as usize];
            let third = r.get(width_for(u64::from(v - 1)), "new_triangle")? as u32;
            let third = third + u32::from(third >= new);
            let new_first = r.bit("new_triangle")?;
            if third >= v || third == parent {
                return Err(r.error(
                    "new_triangle",
                    format!("third vertex {third} with new {new} and parent {parent}"),
                ));
            }
            if d.triangles.len() == d.total_triangles {
                return Err(r.error("new_triangle", "more triangles than the header says"));
            }
            let f = if new_first {
                [new, parent, third]
            } else {
                [parent, new, third]
            };
            push_triangle(d, &mut s.holders, f);
        } else {
            if v as usize == d.total_vertices {
                return Err(r.error("new_vertex", "more vertices than the header says"));
            }
            let parent = r.get(width_for(u64::from(v)), "new_vertex parent")? as u32;
            if parent >= v {
                return Err(r.error(
                    "new_vertex parent",
                    format!("parent {parent} of {v} vertices"),
                ));
            }
            let p = [
                r.finite_f32("new_vertex")?,
                r.finite_f32("new_vertex")?,
                r.finite_f32("new_vertex")?,
            ];
            let values = props::read(r, s.flags, "new_vertex properties")?;
            s.update.clear();
            for _ in 0..s.holders[parent as usize].len() {
                s.update.push(r.bit("new_vertex update list")?);
            }
            d.positions.push(Vec3::from_array(p));
            values.push(&mut d.properties);
            let list = std::mem::take(&mut s.holders[parent as usize]);
            let (mut stay, mut moved) = (Vec::with_capacity(list.len()), Vec::new());
            for (&j, &m) in list.iter().zip(s.update.iter()) {
                if m {
                    for x in &mut d.triangles[j as usize] {
                        if *x == parent {
                            *x = v;
                        }
                    }
                    moved.push(j);
                } else {
                    stay.push(j);
                }
            }
            s.holders[parent as usize] = stay;
            s.holders.push(moved);
            s.parents.push(parent);
        }
        commit(r, d);
    }
    Ok(())
}

fn push_triangle(d: &mut Decoded, holders: &mut [Vec<u32>], f: [u32; 3]) {
    let j = d.triangles.len() as u32;
    for v in f {
        holders[v as usize].push(j);
    }
    d.triangles.push(f);
}
