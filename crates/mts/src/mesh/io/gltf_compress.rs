//! The compressed glTF a `--compress` writes: attributes quantized
//! (`KHR_mesh_quantization`) at gltfpack's default precision, each buffer
//! view then coded with meshoptimizer's codecs (`EXT_meshopt_compression`).
//! The reader's side is [`super::gltf_meshopt`].
//!
//! | attribute | stored as | filter | error |
//! |---|---|---|---|
//! | `POSITION` | u16 × 3 (+2 pad), 14 bits on a grid shared by the three axes; the node's `translation` and uniform `scale` map it back | none | ≤ half a grid step: extent / 32,766 |
//! | `NORMAL` | i8 × 3 (+1), normalized, octahedral | `OCTAHEDRAL`, 8 bits | about 1° |
//! | `TEXCOORD_0` | i16 × 2 normalized on a 12-bit grid when every coordinate is in `[-1, 1]`, else f32 | none | 4 / 32,767 (about 1/8,192) |
//! | `COLOR_0` | u8 × 4 normalized | none | 1 / 510 |
//! | indices | u16 or u32 | `TRIANGLES` codec | exact |
//!
//! Why these: they are gltfpack's defaults (`-vp 14 -vt 12 -vn 8 -vc 8`),
//! so its `-cc` output of the same level is the fair size to compare with.
//! gltfpack maps texture coordinates' own range onto its 12 bits and
//! places them back with a `KHR_texture_transform` on the material's
//! texture; without a texture (coordinates a file carries for later) it
//! has nowhere to put that transform and writes integers no reader can
//! place. This writer keeps 12 bits of a fixed range, `[-1, 1]` as a
//! normalized short, which needs no transform, and floats beyond it. One
//! grid for the three axes keeps the node's scale uniform, so normals need
//! no correction. Vertices whose stored attributes are identical are
//! merged ([`quantize`]).
//!
//! The codecs: attributes in version 0 of the vertex codec (the one
//! `EXT_meshopt_compression` specifies; version 1 is only for the
//! `KHR_` successor), triangles in version 1 of the index codec. Before
//! coding, the triangles are put in the strip-like vertex-cache order the
//! index codec does best with ([`codec_order`]) and the vertices in order
//! of first use.

use crate::mesh::Mesh;
use glam::{Vec2, Vec3, Vec4};
use std::collections::HashMap;

/// A level's vertex streams as stored, and its triangles: what
/// [`quantize`] gives the writer.
pub(super) struct Quantized {
    pub triangles: Vec<[u32; 3]>,
    pub vertex_count: usize,
    /// u16 × 4 per vertex, and the least and greatest coordinates.
    pub positions: Vec<u8>,
    pub lo: [u16; 3],
    pub hi: [u16; 3],
    /// i8 × 4 per vertex: octahedral (for the filter) or plain xyz.
    pub normals: Option<Vec<u8>>,
    /// Per vertex: i16 × 2 normalized (`true`) or f32 × 2.
    pub uvs: Option<(Vec<u8>, bool)>,
    /// u8 × 4 per vertex.
    pub colors: Option<Vec<u8>>,
}

/// Quantizes `mesh` (whose zero normals, if any, are already filled, in
/// `normals`) on `grid`, then merges the vertices whose stored bytes are
/// identical in every stream and renumbers them in order of first use. A
/// glTF vertex is its stored attributes: two vertices that quantize alike
/// draw alike (mts keeps bit-identical duplicates apart, its vertices
/// being the input file's; gltfpack merges them too, so sizes compare the
/// same vertices). When `compressed`, normals are octahedral (for the
/// filter) and the merged triangles are put in [`codec_order`] (chosen on
/// the merged vertices, the connectivity the file has: teapot 21,712
/// bytes when the order was chosen before merging); else the triangles
/// keep `mesh`'s order.
///
/// Cost: O(V + T), one hash map of V entries.
pub(super) fn quantize(
    mesh: &Mesh,
    normals: Option<&[Vec3]>,
    grid: &Grid,
    compressed: bool,
) -> Quantized {
    let octahedral = compressed;
    let p = &mesh.properties;
    let all_positions = positions(&mesh.positions, grid);
    let all_normals = normals.map(|n| {
        if octahedral {
            octahedral_normals(n)
        } else {
            plain_normals(n)
        }
    });
    let all_uvs = p.uvs.as_ref().map(|t| {
        let flipped: Vec<Vec2> = t.iter().map(|t| Vec2::new(t.x, 1.0 - t.y)).collect();
        uvs(&flipped)
    });
    let all_colors = p.colors.as_ref().map(|c| colors(c));
    let uv_size = all_uvs
        .as_ref()
        .map_or(0, |(_, unit)| if *unit { 4 } else { 8 });
    let record = |v: usize| -> Vec<u8> {
        let mut key = all_positions[v * 8..v * 8 + 6].to_vec();
        if let Some(n) = &all_normals {
            key.extend_from_slice(&n[v * 4..v * 4 + 4]);
        }
        if let Some((t, _)) = &all_uvs {
            key.extend_from_slice(&t[v * uv_size..(v + 1) * uv_size]);
        }
        if let Some(c) = &all_colors {
            key.extend_from_slice(&c[v * 4..v * 4 + 4]);
        }
        key
    };
    let mut first: HashMap<Vec<u8>, u32> = HashMap::with_capacity(mesh.positions.len());
    let same: Vec<u32> = (0..mesh.positions.len())
        .map(|v| *first.entry(record(v)).or_insert(v as u32))
        .collect();
    let merged: Vec<[u32; 3]> = mesh
        .triangles
        .iter()
        .map(|t| t.map(|v| same[v as usize]))
        .collect();
    // The order is chosen on the merged vertices: the cache and the codec
    // see the connectivity the file has.
    let merged = if compressed {
        codec_order(&merged, mesh.positions.len())
    } else {
        merged
    };
    // Renumber in order of first use (what the vertex codec and the GPU's
    // vertex fetch do best with).
    const UNUSED: u32 = u32::MAX;
    let mut number = vec![UNUSED; mesh.positions.len()];
    let mut order = Vec::new();
    let triangles: Vec<[u32; 3]> = merged
        .iter()
        .map(|t| {
            t.map(|v| {
                let v = v as usize;
                if number[v] == UNUSED {
                    number[v] = order.len() as u32;
                    order.push(v);
                }
                number[v]
            })
        })
        .collect();
    let gather = |bytes: &[u8], size: usize| -> Vec<u8> {
        order
            .iter()
            .flat_map(|&v| &bytes[v * size..(v + 1) * size])
            .copied()
            .collect()
    };
    let positions = gather(&all_positions, 8);
    let mut lo = [u16::MAX; 3];
    let mut hi = [0u16; 3];
    for q in positions.chunks_exact(8) {
        for k in 0..3 {
            let x = u16::from_le_bytes([q[2 * k], q[2 * k + 1]]);
            lo[k] = lo[k].min(x);
            hi[k] = hi[k].max(x);
        }
    }
    Quantized {
        vertex_count: order.len(),
        triangles,
        positions,
        lo,
        hi,
        normals: all_normals.map(|n| gather(&n, 4)),
        uvs: all_uvs.map(|(t, unit)| (gather(&t, uv_size), unit)),
        colors: all_colors.map(|c| gather(&c, 4)),
    }
}

/// `triangles` in the order the index codec compresses best:
/// meshoptimizer's strip-like vertex-cache order
/// (`meshopt_optimizeVertexCacheStrip`), the order gltfpack `-cc` writes.
/// Measured against the vertex-cache order mts writes levels in
/// ([`super::order_for_cache`], Forsyth's): the bunny's compressed file
/// 210,088 bytes against 226,788 (armadillo 269,148 against 278,512), the
/// triangles' order alone making the difference; the vertex cache's
/// misses rise a little (meshoptimizer's documentation), which a
/// compressed download trades for 7% fewer bytes.
pub(super) fn codec_order(triangles: &[[u32; 3]], vertex_count: usize) -> Vec<[u32; 3]> {
    let flat: Vec<u32> = triangles.iter().flatten().copied().collect();
    meshopt::optimize_vertex_cache_strip(&flat, vertex_count)
        .chunks_exact(3)
        .map(|t| [t[0], t[1], t[2]])
        .collect()
}

/// The quantization grid of positions: `origin + q × step` for `q` in
/// `0..=16383` on each axis.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Grid {
    /// The corner of the box the grid covers (the node's `translation`).
    pub origin: Vec3,
    /// The distance between grid lines (the node's uniform `scale`).
    pub step: f32,
}

/// The largest quantized coordinate (14 bits).
const POSITION_MAX: f32 = 16383.0;

impl Grid {
    /// The grid over the box of every point in `points`: its lowest corner,
    /// and its longest side over 16,383 steps, 14 bits (1 for a point or
    /// an empty set, so that the step is never zero).
    pub fn covering<'a>(points: impl IntoIterator<Item = &'a Vec3>) -> Grid {
        let mut lo = Vec3::splat(f32::INFINITY);
        let mut hi = Vec3::splat(f32::NEG_INFINITY);
        for p in points {
            lo = lo.min(*p);
            hi = hi.max(*p);
        }
        if !lo.is_finite() {
            return Grid {
                origin: Vec3::ZERO,
                step: 1.0,
            };
        }
        let extent = (hi - lo).max_element();
        let step = if extent > 0.0 {
            extent / POSITION_MAX
        } else {
            1.0
        };
        Grid { origin: lo, step }
    }

    /// `p` on the grid (clamped to it).
    fn quantize(&self, p: Vec3) -> [u16; 3] {
        let q = ((p - self.origin) / self.step).round();
        q.to_array().map(|x| x.clamp(0.0, POSITION_MAX) as u16)
    }
}

/// Positions as u16 × 4 (the fourth 0): 8 bytes each.
fn positions(points: &[Vec3], grid: &Grid) -> Vec<u8> {
    let mut out = Vec::with_capacity(points.len() * 8);
    for p in points {
        for q in grid.quantize(*p) {
            out.extend_from_slice(&q.to_le_bytes());
        }
        out.extend_from_slice(&[0, 0]);
    }
    out
}

/// Unit normals as normalized i8 × 3 (and a zero byte).
fn plain_normals(normals: &[Vec3]) -> Vec<u8> {
    normals
        .iter()
        .flat_map(|v| {
            let q = (v.normalize_or(Vec3::Z) * 127.0).round();
            [q.x as i8 as u8, q.y as i8 as u8, q.z as i8 as u8, 0]
        })
        .collect()
}

/// Unit normals in the octahedral filter's 8-bit form (i8 × 4): what
/// `meshopt_decodeFilterOct` turns back into normalized i8 × 3.
fn octahedral_normals(normals: &[Vec3]) -> Vec<u8> {
    let data: Vec<[f32; 4]> = normals
        .iter()
        .map(|n| {
            let n = n.try_normalize().unwrap_or(Vec3::Z);
            [n.x, n.y, n.z, 0.0]
        })
        .collect();
    let coded: Vec<[i8; 4]> = meshopt::encode_filter_oct(&data, 8);
    coded.iter().flat_map(|c| c.map(|x| x as u8)).collect()
}

/// The grid of texture coordinates: 12 bits per unit (gltfpack's default
/// `-vt 12`), stored as multiples of 8 of a normalized i16.
const UV_STEP: f32 = 8.0;

/// Texture coordinates (already in glTF's `v`-down convention): normalized
/// i16 × 2 on a 12-bit grid when every coordinate lies in `[-1, 1]`
/// (`KHR_mesh_quantization` allows signed shorts), with `true`; else f32
/// × 2 and `false`. The grid's step is 8 / 32,767 (about 1/4,096: half a
/// texel of a 4,096-wide image at most off).
fn uvs(uvs: &[Vec2]) -> (Vec<u8>, bool) {
    let unit = uvs.iter().all(|t| t.x.abs() <= 1.0 && t.y.abs() <= 1.0);
    if unit {
        let bytes = uvs
            .iter()
            .flat_map(|t| [t.x, t.y])
            .flat_map(|x| {
                let q = (x * 32767.0 / UV_STEP).round() * UV_STEP;
                (q.clamp(-32767.0, 32767.0) as i16).to_le_bytes()
            })
            .collect();
        (bytes, true)
    } else {
        let bytes = uvs
            .iter()
            .flat_map(|t| [t.x, t.y])
            .flat_map(f32::to_le_bytes)
            .collect();
        (bytes, false)
    }
}

/// Colours as u8 × 4 normalized.
fn colors(colors: &[Vec4]) -> Vec<u8> {
    colors
        .iter()
        .flat_map(|c| c.to_array())
        .map(|x| (x.clamp(0.0, 1.0) * 255.0).round() as u8)
        .collect()
}

/// `data` (`count` elements of `stride` bytes, stride a multiple of 4 up
/// to 256) in version 0 of the attribute codec (the one
/// `EXT_meshopt_compression` specifies).
pub(super) fn encode_attributes(data: &[u8], stride: usize) -> Vec<u8> {
    encode_attributes_as(data, stride, 2, 0)
}

/// [`encode_attributes`] at encoder `level` (0–3, used by version 1 only)
/// and codec `version` (0 or 1).
pub(super) fn encode_attributes_as(
    data: &[u8],
    stride: usize,
    level: i32,
    version: i32,
) -> Vec<u8> {
    assert!(stride % 4 == 0 && stride <= 256 && data.len() % stride == 0);
    assert!((0..=1).contains(&version) && (0..=3).contains(&level));
    let count = data.len() / stride;
    // SAFETY: `data` holds `count × stride` bytes; the output is sized by
    // the encoder's own bound; stride, level and version satisfy the
    // encoder's asserts.
    unsafe {
        let bound = meshopt::ffi::meshopt_encodeVertexBufferBound(count, stride);
        let mut out = vec![0u8; bound];
        let n = meshopt::ffi::meshopt_encodeVertexBufferLevel(
            out.as_mut_ptr(),
            out.len(),
            data.as_ptr().cast(),
            count,
            stride,
            level,
            version,
        );
        assert!(n > 0, "the attribute encoder's bound holds its output");
        out.truncate(n);
        out
    }
}

/// Triangle-list indices in the index codec.
pub(super) fn encode_triangles(indices: &[u32], vertex_count: usize) -> Vec<u8> {
    meshopt::encode_index_buffer(indices, vertex_count)
        .expect("the index encoder takes any triangle list")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn positions_come_back_within_half_a_step() {
        let points = [
            Vec3::new(-1.0, 2.0, 0.5),
            Vec3::new(3.0, 2.5, 0.25),
            Vec3::new(0.1, -0.2, 0.3),
        ];
        let grid = Grid::covering(&points);
        assert_eq!(grid.origin, Vec3::new(-1.0, -0.2, 0.25));
        assert!((grid.step - 4.0 / 16383.0).abs() < 1e-9);
        let bytes = positions(&points, &grid);
        assert_eq!(bytes.len(), 24);
        let coordinate = |k: usize, i: usize| {
            u16::from_le_bytes([bytes[k * 8 + 2 * i], bytes[k * 8 + 2 * i + 1]])
        };
        let lo: Vec<u16> = (0..3)
            .map(|i| (0..3).map(|k| coordinate(k, i)).min().unwrap())
            .collect();
        let hi0 = (0..3).map(|k| coordinate(k, 0)).max().unwrap();
        assert_eq!((lo, hi0), (vec![0, 0, 0], 16383));
        for (k, p) in points.iter().enumerate() {
            let q: Vec<f32> = (0..3).map(|i| f32::from(coordinate(k, i))).collect();
            let back = grid.origin + Vec3::from_slice(&q) * grid.step;
            assert!(
                (back - *p).abs().max_element() <= grid.step / 2.0 + 1e-6,
                "{back} {p}"
            );
        }
        // A single point or none still has a step.
        assert_eq!(Grid::covering(&[Vec3::ONE]).step, 1.0);
        assert_eq!(Grid::covering(&[]).origin, Vec3::ZERO);
    }

    #[test]
    fn vertices_stored_alike_are_merged_and_different_ones_kept() {
        let positions = vec![Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::X, Vec3::ONE];
        let mut mesh = Mesh {
            positions,
            triangles: vec![[0, 1, 2], [3, 4, 2]],
            properties: Default::default(),
        };
        let grid = Grid::covering(&mesh.positions);
        let q = quantize(&mesh, None, &grid, false);
        assert_eq!(q.vertex_count, 4);
        assert_eq!(q.triangles, [[0, 1, 2], [1, 3, 2]]);
        assert_eq!(q.positions.len(), 32);
        assert_eq!((q.lo, q.hi), ([0; 3], [16383; 3]));
        // The same position with another normal stays two vertices.
        let normals = [Vec3::Z, Vec3::Z, Vec3::Z, Vec3::X, Vec3::Z];
        mesh.properties.normals = Some(normals.to_vec());
        let q = quantize(&mesh, Some(&normals), &grid, true);
        assert_eq!(q.vertex_count, 5);
        assert_eq!(q.normals.unwrap().len(), 20);
    }

    #[test]
    fn texture_coordinates_outside_the_unit_square_stay_floats() {
        // 0.5 is 16,383.5 / 8 steps of 8 (rounded to 2,048 × 8 = 16,384);
        // -1.0 is -32,767 (clamped).
        let (bytes, unit) = uvs(&[Vec2::new(0.5, -1.0)]);
        assert!(unit);
        assert_eq!(bytes, [0x00, 0x40, 0x01, 0x80]);
        let (bytes, unit) = uvs(&[Vec2::new(1.5, 0.0)]);
        assert!(!unit);
        assert_eq!(bytes.len(), 8);
    }
}
