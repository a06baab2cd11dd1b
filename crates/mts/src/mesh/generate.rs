//! Built-in meshes, so that nothing needs files: a noise-displaced geodesic
//! icosphere, a torus grid and a flat grid, each sized by a triangle count
//! that reaches millions.
//!
//! All generators are deterministic for a given size and seed, produce
//! closed (sphere, torus) or open (grid) manifold meshes with
//! counter-clockwise outward triangles, and go through the same
//! [`Mesh::validate`] invariants as loaded files.

use super::Mesh;
use crate::error::{Error, Result};
use glam::{Vec2, Vec3, Vec4};
use std::collections::HashMap;
use std::f32::consts::TAU;
use std::fmt;
use std::str::FromStr;

/// Geodesic icosphere: every icosahedron edge cut into `segments` pieces,
/// `20 · segments²` triangles, `10 · segments² + 2` vertices, then each
/// vertex displaced along its radius by `amplitude` times a smooth fractal
/// value noise (4 octaves, seeded by `seed`). Radius 1.
///
/// # Panics
/// If `segments` is 0 or the vertex count would exceed `u32`.
///
/// Cost: O(segments²) time and memory.
#[must_use]
pub fn icosphere(segments: u32, amplitude: f32, seed: u64) -> Mesh {
    assert!(
        segments > 0,
        "icosphere needs at least one segment per edge"
    );
    assert!(
        10 * u64::from(segments).pow(2) + 2 < u64::from(u32::MAX),
        "icosphere too large for u32 indices"
    );
    let t = (1.0 + 5f32.sqrt()) / 2.0;
    let corners = [
        [-1.0, t, 0.0],
        [1.0, t, 0.0],
        [-1.0, -t, 0.0],
        [1.0, -t, 0.0],
        [0.0, -1.0, t],
        [0.0, 1.0, t],
        [0.0, -1.0, -t],
        [0.0, 1.0, -t],
        [t, 0.0, -1.0],
        [t, 0.0, 1.0],
        [-t, 0.0, -1.0],
        [-t, 0.0, 1.0],
    ]
    .map(|c| Vec3::from(c).normalize());
    let faces: [[u32; 3]; 20] = [
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    let n = segments;
    let noise = Noise::new(seed);
    let mut positions: Vec<Vec3> = corners.to_vec();
    let mut edge_points: HashMap<(u32, u32, u32), u32> = HashMap::new();
    let mut triangles = Vec::with_capacity(20 * (n as usize).pow(2));
    let mut grid = Vec::new();
    for [a, b, c] in faces {
        // Vertex ids of the barycentric grid points (i, j), i + j <= n.
        grid.clear();
        for i in 0..=n {
            for j in 0..=n - i {
                let id = if (i, j) == (0, 0) {
                    a
                } else if (i, j) == (n, 0) {
                    b
                } else if (i, j) == (0, n) {
                    c
                } else {
                    let on_edge = if j == 0 {
                        Some((a, b, i))
                    } else if i == 0 {
                        Some((a, c, j))
                    } else if i + j == n {
                        Some((b, c, j))
                    } else {
                        None
                    };
                    let p = corners[a as usize]
                        + (corners[b as usize] - corners[a as usize]) * (i as f32 / n as f32)
                        + (corners[c as usize] - corners[a as usize]) * (j as f32 / n as f32);
                    let mut fresh = || {
                        positions.push(p.normalize());
                        positions.len() as u32 - 1
                    };
                    match on_edge {
                        // Key the point by its edge, measured from the lower corner id.
                        Some((u, v, k)) => {
                            let key = if u < v { (u, v, k) } else { (v, u, n - k) };
                            *edge_points.entry(key).or_insert_with(fresh)
                        }
                        None => fresh(),
                    }
                };
                grid.push(id);
            }
        }
        let row = |i: u32| -> usize {
            // Start of row i in `grid`: sum of (n + 1 - r) for r < i.
            (i * (n + 1) - i * i.saturating_sub(1) / 2) as usize
        };
        let at = |i: u32, j: u32| grid[row(i) + j as usize];
        for i in 0..n {
            for j in 0..n - i {
                triangles.push([at(i, j), at(i + 1, j), at(i, j + 1)]);
                if i + j + 1 < n {
                    triangles.push([at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)]);
                }
            }
        }
    }
    for p in &mut positions {
        *p *= 1.0 + amplitude * noise.fractal(*p * 2.5);
    }
    Mesh {
        positions,
        triangles,
        properties: Default::default(),
    }
}

/// Torus grid: `major × minor` quads, each split along the same diagonal,
/// `2 · major · minor` triangles; major radius 1, minor radius 0.35.
///
/// # Panics
/// If either count is below 3.
///
/// Cost: O(major · minor).
#[must_use]
pub fn torus(major: u32, minor: u32) -> Mesh {
    assert!(
        major >= 3 && minor >= 3,
        "torus needs at least 3 × 3 segments"
    );
    let (big, small) = (1.0f32, 0.35f32);
    let mut positions = Vec::with_capacity((major * minor) as usize);
    for i in 0..major {
        let u = TAU * i as f32 / major as f32;
        for j in 0..minor {
            let v = TAU * j as f32 / minor as f32;
            let r = big + small * v.cos();
            positions.push(Vec3::new(r * u.cos(), r * u.sin(), small * v.sin()));
        }
    }
    let id = |i: u32, j: u32| (i % major) * minor + (j % minor);
    let mut triangles = Vec::with_capacity(2 * (major * minor) as usize);
    for i in 0..major {
        for j in 0..minor {
            let (a, b, c, d) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
            triangles.push([a, b, c]);
            triangles.push([a, c, d]);
        }
    }
    Mesh {
        positions,
        triangles,
        properties: Default::default(),
    }
}

/// Flat open grid in the z = 0 plane: `columns × rows` unit quads, each split
/// along the same diagonal, facing +z.
///
/// # Panics
/// If either count is 0.
#[must_use]
pub fn grid(columns: u32, rows: u32) -> Mesh {
    assert!(columns > 0 && rows > 0, "grid needs at least one quad");
    let w = columns + 1;
    let positions = (0..=rows)
        .flat_map(|y| (0..=columns).map(move |x| Vec3::new(x as f32, y as f32, 0.0)))
        .collect();
    let mut triangles = Vec::with_capacity(2 * (columns * rows) as usize);
    for y in 0..rows {
        for x in 0..columns {
            let a = y * w + x;
            triangles.push([a, a + 1, a + w + 1]);
            triangles.push([a, a + w + 1, a + w]);
        }
    }
    Mesh {
        positions,
        triangles,
        properties: Default::default(),
    }
}

/// A named generated mesh and its approximate triangle count, as written on
/// the command line: `icosphere:100k`, `torus:1M`, `grid:5000`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Generated {
    /// Which generator.
    pub kind: GeneratedKind,
    /// Requested triangle count; the mesh has the nearest count the
    /// generator can make.
    pub triangles: u64,
}

/// The generators [`Generated`] can name.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum GeneratedKind {
    /// [`icosphere`] with amplitude 0.08 and seed 1.
    Icosphere,
    /// [`torus`] with twice as many major as minor segments.
    Torus,
    /// [`grid`], square.
    Grid,
}

/// Largest triangle count a [`Generated`] accepts: 2^24, about 16.8
/// million. The mesh alone is then about 300 MB and its model several GB;
/// 2^30 was accepted before and ran out of memory in the generator.
pub const MAX_GENERATED_TRIANGLES: u64 = 1 << 24;

impl Generated {
    /// The default built-in mesh: a 100K-triangle noisy icosphere.
    pub const DEFAULT: Generated = Generated {
        kind: GeneratedKind::Icosphere,
        triangles: 100_000,
    };

    /// Builds the mesh.
    ///
    /// Cost: O(triangles).
    #[must_use]
    pub fn build(self) -> Mesh {
        let t = self.triangles.max(1) as f64;
        match self.kind {
            GeneratedKind::Icosphere => {
                icosphere(((t / 20.0).sqrt().round() as u32).max(1), 0.08, 1)
            }
            GeneratedKind::Torus => {
                let minor = ((t / 4.0).sqrt().round() as u32).max(3);
                torus(2 * minor, minor)
            }
            GeneratedKind::Grid => {
                let side = ((t / 2.0).sqrt().round() as u32).max(1);
                grid(side, side)
            }
        }
    }
}

impl Generated {
    /// [`Generated::build`] with procedural properties, for measuring them
    /// on any size: a torus gets texture coordinates `(i / major, j /
    /// minor)` with real seams (the parameter lines where they wrap from 1
    /// to 0 split their vertices), analytic normals and colours from its
    /// UVs; a grid gets UVs and colours over its extent and +z normals; an
    /// icosphere gets radial normals and colours from its positions (no
    /// UVs: a sphere has no seamless parameterisation to give).
    ///
    /// Cost: O(triangles).
    #[must_use]
    pub fn build_with_properties(self) -> Mesh {
        let colour = |u: f32, v: f32| Vec4::new(u, v, 1.0 - 0.5 * (u + v), 1.0);
        match self.kind {
            GeneratedKind::Torus => {
                let minor = ((self.triangles.max(1) as f64 / 4.0).sqrt().round() as u32).max(3);
                seamed_torus(2 * minor, minor)
            }
            GeneratedKind::Grid | GeneratedKind::Icosphere => {
                let mut mesh = self.build();
                let (lo, hi) = super::bounds_of(&mesh.positions).unwrap_or_default();
                let size = (hi - lo).max(Vec3::splat(f32::MIN_POSITIVE));
                let unit: Vec<Vec3> = mesh.positions.iter().map(|&p| (p - lo) / size).collect();
                let p = &mut mesh.properties;
                p.colors = Some(unit.iter().map(|t| colour(t.x, t.y)).collect());
                if self.kind == GeneratedKind::Grid {
                    p.uvs = Some(unit.iter().map(|t| Vec2::new(t.x, t.y)).collect());
                    p.normals = Some(vec![Vec3::Z; unit.len()]);
                } else {
                    let centre = 0.5 * (lo + hi);
                    p.normals = Some(
                        mesh.positions
                            .iter()
                            .map(|&q| (q - centre).normalize_or_zero())
                            .collect(),
                    );
                }
                mesh
            }
        }
    }
}

/// [`torus`] with texture coordinates, normals and colours: a vertex per
/// `(i, j)` for `i` in `0..=major` and `j` in `0..=minor`, those at
/// `i = major` or `j = minor` sharing the point of `i = 0` or `j = 0`.
fn seamed_torus(major: u32, minor: u32) -> Mesh {
    let (big, small) = (1.0f32, 0.35f32);
    let (w, h) = (major + 1, minor + 1);
    let mut positions = Vec::with_capacity((w * h) as usize);
    let (mut uvs, mut normals, mut colors, mut ids) =
        (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    for i in 0..w {
        let u = TAU * (i % major) as f32 / major as f32;
        for j in 0..h {
            let v = TAU * (j % minor) as f32 / minor as f32;
            let r = big + small * v.cos();
            positions.push(Vec3::new(r * u.cos(), r * u.sin(), small * v.sin()));
            normals.push(Vec3::new(v.cos() * u.cos(), v.cos() * u.sin(), v.sin()));
            let t = Vec2::new(i as f32 / major as f32, j as f32 / minor as f32);
            uvs.push(t);
            colors.push(Vec4::new(t.x, t.y, 1.0 - 0.5 * (t.x + t.y), 1.0));
            ids.push((i % major) * minor + (j % minor));
        }
    }
    let id = |i: u32, j: u32| i * h + j;
    let mut triangles = Vec::with_capacity(2 * (major * minor) as usize);
    for i in 0..major {
        for j in 0..minor {
            let (a, b, c, d) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
            triangles.push([a, b, c]);
            triangles.push([a, c, d]);
        }
    }
    let raw = super::RawMesh {
        positions,
        triangles,
        degenerate_in_source: 0,
        properties: super::Properties {
            normals: Some(normals),
            uvs: Some(uvs),
            colors: Some(colors),
            position_ids: ids,
            texture: None,
        },
    };
    super::clean(raw, super::CleanOptions::default(), "torus")
        .expect("a torus has triangles")
        .0
}

impl fmt::Display for Generated {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let name = match self.kind {
            GeneratedKind::Icosphere => "icosphere",
            GeneratedKind::Torus => "torus",
            GeneratedKind::Grid => "grid",
        };
        write!(f, "{name}:{}", self.triangles)
    }
}

impl FromStr for Generated {
    type Err = Error;

    /// Parses `NAME:SIZE` where SIZE may end in `k` or `M` (`icosphere:250k`).
    fn from_str(s: &str) -> Result<Generated> {
        let bad = |why: &str| Error::InvalidArgument(format!("generated mesh `{s}`: {why}"));
        let (name, size) = s.split_once(':').unwrap_or((s, "100k"));
        let kind = match name {
            "icosphere" | "sphere" => GeneratedKind::Icosphere,
            "torus" => GeneratedKind::Torus,
            "grid" => GeneratedKind::Grid,
            _ => return Err(bad("unknown name (use icosphere, torus or grid)")),
        };
        let (digits, scale) = match size.as_bytes().last() {
            Some(b'k' | b'K') => (&size[..size.len() - 1], 1_000.0),
            Some(b'm' | b'M') => (&size[..size.len() - 1], 1_000_000.0),
            _ => (size, 1.0),
        };
        let value: f64 = digits.parse().map_err(|_| bad("size is not a number"))?;
        let triangles = value * scale;
        if !(1.0..=MAX_GENERATED_TRIANGLES as f64).contains(&triangles) {
            return Err(bad(&format!(
                "size must be between 1 and {MAX_GENERATED_TRIANGLES} (16.8M) triangles"
            )));
        }
        Ok(Generated {
            kind,
            triangles: triangles as u64,
        })
    }
}

/// Smooth 3D value noise on an integer lattice with a hashed value per
/// lattice point, used only to make generated surfaces irregular.
struct Noise {
    seed: u64,
}

impl Noise {
    fn new(seed: u64) -> Noise {
        Noise { seed }
    }

    fn lattice(&self, x: i32, y: i32, z: i32) -> f32 {
        // SplitMix64 finaliser over the packed coordinates.
        let mut h = self.seed
            ^ (x as u32 as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15)
            ^ (y as u32 as u64).wrapping_mul(0xC2B2_AE3D_27D4_EB4F)
            ^ (z as u32 as u64).wrapping_mul(0x1656_67B1_9E37_79F9);
        h = (h ^ (h >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        h = (h ^ (h >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        h ^= h >> 31;
        (h >> 40) as f32 / (1u64 << 24) as f32 * 2.0 - 1.0
    }

    fn value(&self, p: Vec3) -> f32 {
        let f = p.floor();
        let (x, y, z) = (f.x as i32, f.y as i32, f.z as i32);
        let t = p - f;
        let s = t * t * (Vec3::splat(3.0) - 2.0 * t);
        let lerp = |a: f32, b: f32, t: f32| a + (b - a) * t;
        let mut c = [0.0f32; 8];
        for (k, v) in c.iter_mut().enumerate() {
            *v = self.lattice(
                x + (k & 1) as i32,
                y + ((k >> 1) & 1) as i32,
                z + (k >> 2) as i32,
            );
        }
        let x0 = lerp(lerp(c[0], c[1], s.x), lerp(c[2], c[3], s.x), s.y);
        let x1 = lerp(lerp(c[4], c[5], s.x), lerp(c[6], c[7], s.x), s.y);
        lerp(x0, x1, s.z)
    }

    /// Four octaves, amplitude halving, in about [-1, 1].
    fn fractal(&self, p: Vec3) -> f32 {
        (0..4)
            .map(|o| self.value(p * (1 << o) as f32) / (1 << o) as f32)
            .sum::<f32>()
            / 1.875
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Six times the signed volume: positive for closed outward-facing meshes.
    fn volume6(mesh: &Mesh) -> f32 {
        mesh.triangles
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|v| mesh.positions[v as usize]);
                a.dot(b.cross(c))
            })
            .sum()
    }

    #[test]
    fn icosphere_counts_and_orientation() {
        for n in [1, 2, 5, 16] {
            let m = icosphere(n, 0.08, 1);
            m.validate().unwrap();
            assert_eq!(m.triangle_count(), 20 * (n * n) as usize);
            assert_eq!(m.vertex_count(), 10 * (n * n) as usize + 2);
            assert!(volume6(&m) > 0.0);
        }
    }

    #[test]
    fn torus_counts_and_orientation() {
        let m = torus(12, 6);
        m.validate().unwrap();
        assert_eq!(m.triangle_count(), 144);
        assert_eq!(m.vertex_count(), 72);
        assert!(volume6(&m) > 0.0);
    }

    #[test]
    fn generated_names_parse_and_reach_their_size() {
        let g: Generated = "icosphere:100k".parse().unwrap();
        assert_eq!(g, Generated::DEFAULT);
        assert_eq!(g.build().triangle_count(), 20 * 71 * 71);
        let t: Generated = "torus:1M".parse().unwrap();
        assert_eq!(t.triangles, 1_000_000);
        assert_eq!(t.build().triangle_count(), 2 * 1000 * 500);
        assert!("cube:10".parse::<Generated>().is_err());
        assert!("torus:0".parse::<Generated>().is_err());
        assert!("torus:1e12".parse::<Generated>().is_err());
    }
}
