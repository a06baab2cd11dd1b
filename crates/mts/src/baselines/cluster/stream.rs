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

use super::super::bits::{width_for, BitReader, BitWriter};
use super::super::pm::ProgressiveMesh;
use crate::error::{Error, Place, Result};
use crate::mesh::{is_degenerate, Mesh};
use glam::Vec3;
use std::path::PathBuf;

/// Magic bytes of the packet stream.
pub const MAGIC: &[u8; 8] = b"MTSCT\0\0\x01";
/// Bytes before the body: magic, four counts and the checksum.
pub const HEADER_BYTES: usize = 8 + 5 * 4;

/// Linearizes a vertex-split hierarchy (the cluster tree's, or any
/// [`ProgressiveMesh`]) into the packet stream. The update lists are
/// computed by running the decoder's own bookkeeping beside the splits.
/// O(size of the stream + triangles).
#[must_use]
pub fn encode(pm: &ProgressiveMesh) -> Vec<u8> {
    let n = pm.positions.len();
    let max_lod = pm.kept.len();
    let roots = n - max_lod;
    let base = pm.alive[max_lod] as usize;
    let mut w = BitWriter::default();
    for p in &pm.positions[..roots] {
        for x in p.to_array() {
            w.f32(x);
        }
    }
    let mut holders: Vec<Vec<u32>> = vec![Vec::new(); n];
    for (j, f) in pm.faces[..base].iter().enumerate() {
        for &v in f {
            w.put(u64::from(v), width_for(roots as u64));
            holders[v as usize].push(j as u32);
        }
    }
    let mut mark = vec![u32::MAX; pm.faces.len()];
    for i in (0..max_lod).rev() {
        let r = (n - 1 - i) as u32;
        let k = pm.kept[i];
        for c in pm.corners_of(i) {
            mark[pm.corners[c] as usize / 3] = i as u32;
        }
        w.bit(false);
        w.put(u64::from(k), width_for(u64::from(r)));
        for x in pm.positions[r as usize].to_array() {
            w.f32(x);
        }
        let list = std::mem::take(&mut holders[k as usize]);
        for &j in &list {
            let moves = mark[j as usize] == i as u32;
            w.bit(moves);
            holders[if moves { r } else { k } as usize].push(j);
        }
        let (after, before) = (pm.alive[i + 1] as usize, pm.alive[i] as usize);
        for (j, f) in pm.faces.iter().enumerate().take(before).skip(after) {
            let at = f.iter().position(|&v| v == r).unwrap_or(0);
            let new_first = f[(at + 1) % 3] == k;
            let third = if new_first {
                f[(at + 2) % 3]
            } else {
                f[(at + 1) % 3]
            };
            w.bit(true);
            w.put(u64::from(third), width_for(u64::from(r)));
            w.bit(new_first);
            for v in [r, k, third] {
                holders[v as usize].push(j as u32);
            }
        }
    }
    let body = w.finish();
    let mut out = Vec::with_capacity(HEADER_BYTES + body.len());
    out.extend_from_slice(MAGIC);
    for v in [n, pm.faces.len(), roots, base] {
        out.extend_from_slice(&(v as u32).to_le_bytes());
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

    /// The decoded mesh with vertices no triangle uses yet dropped (order
    /// kept), so that it passes [`Mesh::validate`]. O(V + T).
    #[must_use]
    pub fn mesh(&self) -> Mesh {
        let mut map = vec![u32::MAX; self.positions.len()];
        let mut positions = Vec::new();
        let triangles = self
            .triangles
            .iter()
            .map(|t| {
                t.map(|v| {
                    let slot = &mut map[v as usize];
                    if *slot == u32::MAX {
                        *slot = positions.len() as u32;
                        positions.push(self.positions[v as usize]);
                    }
                    *slot
                })
            })
            .collect();
        Mesh {
            positions,
            triangles,
            properties: Default::default(),
        }
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
    if &bytes[..8] != MAGIC {
        return Err(header_error(
            file,
            0,
            "not a cluster-tree stream (bad magic)",
        ));
    }
    let word = |i: usize| {
        let at = 8 + 4 * i;
        u32::from_le_bytes([bytes[at], bytes[at + 1], bytes[at + 2], bytes[at + 3]]) as usize
    };
    let (n, t, roots, base, checksum) = (word(0), word(1), word(2), word(3), word(4) as u32);
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
    let body = &bytes[HEADER_BYTES..];
    if strict && crate::checksum::fnv1a32(body) != checksum {
        return Err(header_error(
            file,
            24,
            "checksum mismatch: the body is corrupt",
        ));
    }
    let mut d = Decoded {
        positions: Vec::new(),
        triangles: Vec::new(),
        total_vertices: n,
        total_triangles: t,
        bytes_used: HEADER_BYTES,
    };
    let mut r = BitReader::new(body, file);
    let mut holders: Vec<Vec<u32>> = Vec::new();
    let mut update = Vec::new();
    match decode_body(&mut r, &mut d, &mut holders, &mut update, roots, base) {
        Ok(()) => {}
        Err(_) if !strict && r.ran_out => {}
        Err(e) => return Err(shift(e)),
    }
    if strict {
        if !d.is_complete() {
            return Err(shift(r.error(
                "end",
                format!(
                    "{} vertices and {} triangles decoded, the header says {n} and {t}",
                    d.positions.len(),
                    d.triangles.len()
                ),
            )));
        }
        r.finish("end").map_err(shift)?;
    }
    Ok(d)
}

/// Body offsets to file offsets.
fn shift(e: Error) -> Error {
    match e {
        Error::Parse {
            file,
            mut place,
            message,
        } => {
            place.byte = place.byte.map(|b| b + HEADER_BYTES as u64);
            Error::Parse {
                file,
                place,
                message,
            }
        }
        e => e,
    }
}

/// Decodes units (a root, a base triangle, a packet) until the counts are
/// reached; each unit is read whole before it changes `d`.
fn decode_body(
    r: &mut BitReader<'_>,
    d: &mut Decoded,
    holders: &mut Vec<Vec<u32>>,
    update: &mut Vec<bool>,
    roots: usize,
    base: usize,
) -> Result<()> {
    let commit = |r: &BitReader<'_>, d: &mut Decoded| {
        d.bytes_used = HEADER_BYTES + r.position().div_ceil(8) as usize;
    };
    for _ in 0..roots {
        let p = [
            r.finite_f32("root")?,
            r.finite_f32("root")?,
            r.finite_f32("root")?,
        ];
        d.positions.push(Vec3::from_array(p));
        holders.push(Vec::new());
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
        push_triangle(d, holders, f);
        commit(r, d);
    }
    // The newest vertex and its parent, which new triangles join.
    let mut last: Option<(u32, u32)> = None;
    while !d.is_complete() {
        let is_triangle = r.bit("packet tag")?;
        let v = d.positions.len() as u32;
        if is_triangle {
            let Some((new, parent)) = last else {
                return Err(r.error("new_triangle", "a triangle before any new vertex"));
            };
            let third = r.get(width_for(u64::from(new)), "new_triangle")? as u32;
            let new_first = r.bit("new_triangle")?;
            if third >= new || third == parent {
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
            push_triangle(d, holders, f);
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
            update.clear();
            for _ in 0..holders[parent as usize].len() {
                update.push(r.bit("new_vertex update list")?);
            }
            d.positions.push(Vec3::from_array(p));
            let list = std::mem::take(&mut holders[parent as usize]);
            let (mut stay, mut moved) = (Vec::with_capacity(list.len()), Vec::new());
            for (&j, &m) in list.iter().zip(update.iter()) {
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
            holders[parent as usize] = stay;
            holders.push(moved);
            last = Some((v, parent));
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
