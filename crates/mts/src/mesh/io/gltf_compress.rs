//! The compressed glTF a `--compress` writes: attributes quantized
//! (`KHR_mesh_quantization`) at gltfpack's default precision, each buffer
//! view then coded with meshoptimizer's codecs (`EXT_meshopt_compression`).
//! The reader's side is [`super::gltf_meshopt`].
//!
//! | attribute | stored as | filter | error |
//! |---|---|---|---|
//! | `POSITION` | u16 × 3 (+2 pad), 14 bits on a grid shared by the three axes; the node's `translation` and uniform `scale` map it back | none | ≤ half a grid step: extent / 32,766 |
//! | `NORMAL` | i8 × 3 (+1), normalized, octahedral | `OCTAHEDRAL`, 8 bits | about 1° |
//! | `TEXCOORD_0` | u16 × 2 normalized when every coordinate is in `[0, 1]`, else f32 | none | 1 / 131,070 |
//! | `COLOR_0` | u8 × 4 normalized | none | 1 / 510 |
//! | indices | u16 or u32 | `TRIANGLES` codec | exact |
//!
//! Why these: they are gltfpack's defaults (`-vp 14 -vn 8 -vc 8`), so its
//! `-cc` output of the same level is the fair size to compare with; the
//! texture coordinates keep 16 bits instead of gltfpack's 12 because
//! gltfpack's range remap needs a `KHR_texture_transform` on a texture
//! this writer may not have (coordinates without a texture are kept too),
//! and 16 bits over `[0, 1]` needs none. One grid for the three axes keeps
//! the node's scale uniform, so normals need no correction.
//!
//! The codecs: attributes in version 0 of the vertex codec (the one
//! `EXT_meshopt_compression` specifies; version 1 is only for the
//! `KHR_` successor), triangles in version 1 of the index codec. The
//! triangles should be in vertex-cache order and the vertices in order of
//! first use ([`super::order_for_cache`]) for the codecs to do well; the
//! callers write levels in that order.

use glam::{Vec2, Vec3, Vec4};

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
    /// and its longest side over [`POSITION_MAX`] steps (1 for a point or
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

/// Positions as u16 × 4 (the fourth 0): 8 bytes each, and the least and
/// greatest quantized coordinates (the accessor's `min` and `max`).
pub(super) fn positions(points: &[Vec3], grid: &Grid) -> (Vec<u8>, [u16; 3], [u16; 3]) {
    let mut lo = [u16::MAX; 3];
    let mut hi = [0u16; 3];
    let mut out = Vec::with_capacity(points.len() * 8);
    for p in points {
        let q = grid.quantize(*p);
        for k in 0..3 {
            lo[k] = lo[k].min(q[k]);
            hi[k] = hi[k].max(q[k]);
            out.extend_from_slice(&q[k].to_le_bytes());
        }
        out.extend_from_slice(&[0, 0]);
    }
    (out, lo, hi)
}

/// Unit normals in the octahedral filter's 8-bit form (i8 × 4): what
/// `meshopt_decodeFilterOct` turns back into normalized i8 × 3.
pub(super) fn normals(normals: &[Vec3]) -> Vec<u8> {
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

/// Texture coordinates (already in glTF's `v`-down convention): u16 × 2
/// normalized when all lie in `[0, 1]`, with `true`; else f32 × 2 and
/// `false`.
pub(super) fn uvs(uvs: &[Vec2]) -> (Vec<u8>, bool) {
    let unit = uvs
        .iter()
        .all(|t| (0.0..=1.0).contains(&t.x) && (0.0..=1.0).contains(&t.y));
    if unit {
        let bytes = uvs
            .iter()
            .flat_map(|t| [t.x, t.y])
            .flat_map(|x| ((x * 65535.0).round() as u16).to_le_bytes())
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
pub(super) fn colors(colors: &[Vec4]) -> Vec<u8> {
    colors
        .iter()
        .flat_map(|c| c.to_array())
        .map(|x| (x.clamp(0.0, 1.0) * 255.0).round() as u8)
        .collect()
}

/// `data` (`count` elements of `stride` bytes, stride a multiple of 4 up
/// to 256) in version 0 of the attribute codec.
pub(super) fn encode_attributes(data: &[u8], stride: usize) -> Vec<u8> {
    assert!(stride % 4 == 0 && stride <= 256 && data.len() % stride == 0);
    let count = data.len() / stride;
    // SAFETY: `data` holds `count × stride` bytes; the output is sized by
    // the encoder's own bound; stride satisfies the encoder's asserts.
    unsafe {
        let bound = meshopt::ffi::meshopt_encodeVertexBufferBound(count, stride);
        let mut out = vec![0u8; bound];
        let n = meshopt::ffi::meshopt_encodeVertexBufferLevel(
            out.as_mut_ptr(),
            out.len(),
            data.as_ptr().cast(),
            count,
            stride,
            2,
            0,
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
        let (bytes, lo, hi) = positions(&points, &grid);
        assert_eq!(bytes.len(), 24);
        assert_eq!((lo, hi[0]), ([0, 0, 0], 16383));
        for (k, p) in points.iter().enumerate() {
            let q: Vec<f32> = (0..3)
                .map(|i| {
                    u16::from_le_bytes([bytes[k * 8 + 2 * i], bytes[k * 8 + 2 * i + 1]]) as f32
                })
                .collect();
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
    fn texture_coordinates_outside_the_unit_square_stay_floats() {
        // 0.5 is 32,767.5 steps, rounded to 32,768; 1.0 is 65,535.
        assert_eq!(uvs(&[Vec2::new(0.5, 1.0)]).0, [0x00, 0x80, 0xff, 0xff]);
        assert!(uvs(&[Vec2::new(0.5, 1.0)]).1);
        let (bytes, unit) = uvs(&[Vec2::new(1.5, 0.0)]);
        assert!(!unit);
        assert_eq!(bytes.len(), 8);
    }
}
