//! Built-in meshes, so that nothing needs files: a noise-displaced geodesic
//! icosphere, a torus grid, a flat grid and a fractal terrain, each sized by
//! a triangle count that reaches millions.
//!
//! All generators are deterministic for a given size and seed, produce
//! closed (sphere, torus) or open (grid, terrain) manifold meshes with
//! counter-clockwise outward triangles, and go through the same
//! [`Mesh::validate`] invariants as loaded files.
//!
//! The terrain's heights are Musgrave's ridged multifractal over a broad
//! fractional Brownian motion (F. K. Musgrave, "Procedural Fractal
//! Terrains", in Ebert et al., *Texturing and Modeling: A Procedural
//! Approach*, 3rd ed., 2003, ch. 16), both summed from 2D gradient noise
//! with quintic fade (K. Perlin, "Improving Noise", SIGGRAPH 2002).

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
    let positions = (0..=rows)
        .flat_map(|y| (0..=columns).map(move |x| Vec3::new(x as f32, y as f32, 0.0)))
        .collect();
    Mesh {
        positions,
        triangles: quad_triangles(columns, rows),
        properties: Default::default(),
    }
}

/// The triangles of a `columns × rows` grid of quads over vertices laid
/// out row by row (`columns + 1` a row): each quad split along the same
/// diagonal, counter-clockwise seen from the side the rows advance to the
/// left of the columns (what `grid` and the terrain share).
fn quad_triangles(columns: u32, rows: u32) -> Vec<[u32; 3]> {
    let w = columns + 1;
    let mut triangles = Vec::with_capacity(2 * columns as usize * rows as usize);
    for y in 0..rows {
        for x in 0..columns {
            let a = y * w + x;
            triangles.push([a, a + 1, a + w + 1]);
            triangles.push([a, a + w + 1, a + w]);
        }
    }
    triangles
}

/// Relief of [`terrain`]: its heights span exactly `0..=TERRAIN_RELIEF`,
/// 15% of its 2-unit extent, about the relief of a mountain range
/// seen at the scale of its valleys.
pub const TERRAIN_RELIEF: f32 = 0.3;

/// Square fractal heightfield over `[-1, 1]²` in the x–z plane, +y up (the
/// renderer's camera convention): `side × side` quads, each split along
/// the same diagonal, `2 · side²` triangles and `(side + 1)²` vertices,
/// counter-clockwise seen from above, with an open boundary. Vertex
/// `j · (side + 1) + i` is column `i` (along +x) of row `j` (along −z, so
/// that rows run up a map seen from above).
///
/// Heights are a ridged multifractal over a broad fBm (module header), ten
/// octaves down to features about two cells wide at 16M triangles, seeded
/// by `seed`, then rescaled to span exactly `0..=`[`TERRAIN_RELIEF`].
/// The surface is a function of `(x, z)`: every size samples the same
/// landscape, up to that rescaling.
///
/// # Panics
/// If `side` is 0 or the vertex count would exceed `u32`.
///
/// Cost: O(side²) time, the noise spread over the available cores; no
/// memory beyond the mesh's own.
#[must_use]
pub fn terrain(side: u32, seed: u64) -> Mesh {
    assert!(side > 0, "terrain needs at least one quad");
    // 65 535² is the largest square number of vertices below u32::MAX.
    assert!(side < 65_535, "terrain too large for u32 indices");
    let w = side as usize + 1;
    let noise = Noise::new(seed);
    let coordinate = |k: usize| (2.0 * k as f32 - side as f32) / side as f32;
    let mut positions = vec![Vec3::ZERO; w * w];
    let threads = std::thread::available_parallelism().map_or(1, |n| n.get());
    let rows_per_band = w.div_ceil(threads);
    std::thread::scope(|scope| {
        for (band, chunk) in positions.chunks_mut(rows_per_band * w).enumerate() {
            let noise = &noise;
            scope.spawn(move || {
                for (k, p) in chunk.iter_mut().enumerate() {
                    let (i, j) = (k % w, band * rows_per_band + k / w);
                    let (x, z) = (coordinate(i), coordinate(side as usize - j));
                    *p = Vec3::new(x, noise.terrain_height(x, z), z);
                }
            });
        }
    });
    let (lo, hi) = positions
        .iter()
        .fold((f32::INFINITY, f32::NEG_INFINITY), |(lo, hi), p| {
            (lo.min(p.y), hi.max(p.y))
        });
    let scale = if hi > lo {
        TERRAIN_RELIEF / (hi - lo)
    } else {
        0.0
    };
    for p in &mut positions {
        p.y = ((p.y - lo) * scale).min(TERRAIN_RELIEF);
    }
    Mesh {
        positions,
        triangles: quad_triangles(side, side),
        properties: Default::default(),
    }
}

/// The grid's UVs `(i / side, j / side)`, normals from central differences
/// of the heights (one-sided on the border) and colours by height (green
/// valleys, brown slopes, white peaks) for a mesh [`terrain`] made.
fn add_terrain_properties(mesh: &mut Mesh, side: u32) {
    let w = side as usize + 1;
    let positions = &mesh.positions;
    let uvs = (0..w * w)
        .map(|v| Vec2::new((v % w) as f32, (v / w) as f32) / side as f32)
        .collect();
    let normals = (0..w * w)
        .map(|v| {
            let (i, j) = (v % w, v / w);
            let slope = |a: usize, b: usize, along: fn(Vec3) -> f32| {
                let (a, b) = (positions[a], positions[b]);
                (b.y - a.y) / (along(b) - along(a))
            };
            let dx = slope(
                j * w + i.saturating_sub(1),
                j * w + (i + 1).min(w - 1),
                |p| p.x,
            );
            let dz = slope(
                j.saturating_sub(1) * w + i,
                (j + 1).min(w - 1) * w + i,
                |p| p.z,
            );
            stable_unit(Vec3::new(-dx, 1.0, -dz))
        })
        .collect();
    let ramp = [
        Vec4::new(0.22, 0.42, 0.18, 1.0),
        Vec4::new(0.48, 0.40, 0.30, 1.0),
        Vec4::new(0.95, 0.95, 0.97, 1.0),
    ];
    let colors = positions
        .iter()
        .map(|p| {
            let t = 2.0 * p.y / TERRAIN_RELIEF;
            if t < 1.0 {
                ramp[0].lerp(ramp[1], t)
            } else {
                ramp[1].lerp(ramp[2], t - 1.0)
            }
            .clamp(Vec4::ZERO, Vec4::ONE)
        })
        .collect();
    let p = &mut mesh.properties;
    p.uvs = Some(uvs);
    p.normals = Some(normals);
    p.colors = Some(colors);
}

/// `v` normalised to a vector that normalising leaves bit-identical, so
/// that [`super::clean`] (which normalises every normal) keeps it.
///
/// Iterating `normalize` does not get there: about a third of terrain
/// normals flip between two neighbours forever. The unit vector rounded
/// from f64 is within two ulps of its largest component of one whose
/// squared length rounds close enough to 1 that `length_recip` is exactly
/// 1: a step of one ulp there moves the squared length by at most 2⁻²³,
/// less than the width of that window.
fn stable_unit(v: Vec3) -> Vec3 {
    let n = v.as_dvec3().normalize_or_zero().as_vec3();
    let axis = n.abs().max_position();
    for step in [0, 1, -1, 2, -2] {
        let mut m = n;
        m[axis] = f32::from_bits(m[axis].to_bits().wrapping_add_signed(step));
        if m.normalize_or_zero() == m {
            return m;
        }
    }
    n.normalize_or_zero()
}

/// A named generated mesh and its approximate triangle count, as written on
/// the command line: `icosphere:100k`, `torus:1M`, `grid:5000`,
/// `terrain:4M`.
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
    /// [`terrain`] with seed 1.
    Terrain,
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
            GeneratedKind::Grid => grid(self.side(), self.side()),
            GeneratedKind::Terrain => terrain(self.side(), 1),
        }
    }

    /// Quads per side of a square [`grid`] or [`terrain`] with about
    /// `triangles` triangles (two a quad).
    fn side(self) -> u32 {
        ((self.triangles.max(1) as f64 / 2.0).sqrt().round() as u32).max(1)
    }
}

impl Generated {
    /// [`Generated::build`] with procedural properties, for measuring them
    /// on any size: a torus gets texture coordinates `(i / major, j /
    /// minor)` with real seams (the parameter lines where they wrap from 1
    /// to 0 split their vertices), analytic normals and colours from its
    /// UVs; a grid gets UVs and colours over its extent and +z normals; an
    /// icosphere gets radial normals and colours from its positions (no
    /// UVs: a sphere has no seamless parameterisation to give); a terrain
    /// gets its grid's UVs, normals from its heights and colours by height.
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
            GeneratedKind::Terrain => {
                let mut mesh = self.build();
                add_terrain_properties(&mut mesh, self.side());
                mesh
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
            GeneratedKind::Terrain => "terrain",
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
            "terrain" => GeneratedKind::Terrain,
            _ => return Err(bad("unknown name (use icosphere, torus, grid or terrain)")),
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
        (self.hash(x, y, z) >> 40) as f32 / (1u64 << 24) as f32 * 2.0 - 1.0
    }

    /// SplitMix64 finaliser over the packed coordinates.
    fn hash(&self, x: i32, y: i32, z: i32) -> u64 {
        let mut h = self.seed
            ^ (x as u32 as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15)
            ^ (y as u32 as u64).wrapping_mul(0xC2B2_AE3D_27D4_EB4F)
            ^ (z as u32 as u64).wrapping_mul(0x1656_67B1_9E37_79F9);
        h = (h ^ (h >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        h = (h ^ (h >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        h ^ (h >> 31)
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

    /// 2D gradient noise at `(x, y)` on the lattice of layer `layer` (each
    /// layer an independent field), in about [-1, 1]: Perlin's improved
    /// noise with one of eight unit gradients per lattice point.
    fn gradient(&self, x: f32, y: f32, layer: i32) -> f32 {
        // Eight directions 45° apart, none along an axis: with Perlin's
        // axis gradients, an edge whose two ends both got one across it is
        // zero along its whole length, and the ridged sum turns that into a
        // straight crease one cell long (seen on hill-shaded renders).
        const C: f32 = 0.923_879_5; // cos 22.5°
        const S: f32 = 0.382_683_43; // sin 22.5°
        const GRADIENTS: [Vec2; 8] = [
            Vec2::new(C, S),
            Vec2::new(S, C),
            Vec2::new(-S, C),
            Vec2::new(-C, S),
            Vec2::new(-C, -S),
            Vec2::new(-S, -C),
            Vec2::new(S, -C),
            Vec2::new(C, -S),
        ];
        // `as` truncates towards zero: step down below zero (`f32::floor`
        // is a libm call without SSE4.1, and made this 30% slower).
        let floor = |v: f32| {
            let i = v as i32;
            i - i32::from((i as f32) > v)
        };
        let (ix, iy) = (floor(x), floor(y));
        let (fx, fy) = (ix as f32, iy as f32);
        let (tx, ty) = (x - fx, y - fy);
        let corner = |dx: i32, dy: i32| {
            let g = GRADIENTS[(self.hash(ix + dx, iy + dy, layer) >> 61) as usize];
            g.x * (tx - dx as f32) + g.y * (ty - dy as f32)
        };
        let fade = |t: f32| t * t * t * (t * (t * 6.0 - 15.0) + 10.0);
        let (sx, sy) = (fade(tx), fade(ty));
        let lerp = |a: f32, b: f32, t: f32| a + (b - a) * t;
        let bottom = lerp(corner(0, 0), corner(1, 0), sx);
        let top = lerp(corner(0, 1), corner(1, 1), sx);
        // Unit gradients reach about √½ in 2D; scale to about [-1, 1].
        std::f32::consts::SQRT_2 * lerp(bottom, top, sy)
    }

    /// Unscaled height of [`terrain`] at `(x, z)` in `[-1, 1]²`: a ridged
    /// multifractal (Musgrave's `RidgedMultifractal` with H = 1, offset 1,
    /// gain 2) of ten octaves from 1.25 cycles a unit, whose ridges are
    /// damped where the octave below is low, scaled by a two-octave fBm at
    /// 0.5 cycles a unit that raises ranges in some regions and leaves
    /// rolling lowland in others. Each octave's plane is turned by about
    /// 37° from the last so that no lattice axis lines up across octaves.
    /// The weights were chosen by eye on hill-shaded renders; the tenth
    /// octave's features are about two cells wide at 16M triangles.
    fn terrain_height(&self, x: f32, z: f32) -> f32 {
        const OCTAVES: i32 = 10;
        let turn = |p: Vec2| Vec2::new(0.8 * p.x - 0.6 * p.y, 0.6 * p.x + 0.8 * p.y);
        let mut p = Vec2::new(x, z) * 1.25;
        let mut ridged = 0.0;
        let (mut weight, mut amplitude) = (1.0f32, 1.0f32);
        for octave in 0..OCTAVES {
            let crest = 1.0 - self.gradient(p.x, p.y, octave).abs();
            let signal = crest * crest * weight;
            ridged += signal * amplitude;
            weight = (2.0 * signal).clamp(0.0, 1.0);
            amplitude *= 0.5;
            p = turn(p) * 2.0;
        }
        let q = Vec2::new(x, z) * 0.5;
        let broad = self.gradient(q.x, q.y, OCTAVES)
            + 0.5 * self.gradient(2.0 * q.x, 2.0 * q.y, OCTAVES + 1);
        ridged * (1.0 + 0.5 * broad) + 0.3 * broad
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
        let r: Generated = "terrain:4M".parse().unwrap();
        assert_eq!(r.kind, GeneratedKind::Terrain);
        assert_eq!(r.to_string(), "terrain:4000000");
        assert_eq!(r.to_string().parse::<Generated>().unwrap(), r);
    }

    #[test]
    fn stable_unit_is_kept_by_normalize() {
        let noise = Noise::new(7);
        for k in 0..200_000 {
            let h = |axis: i32| noise.lattice(k, axis, 0) * 3.0;
            let v = Vec3::new(h(0), h(1), h(2));
            let n = stable_unit(v);
            assert_eq!(n.normalize_or_zero(), n, "{v}");
            assert!((n - v.normalize()).length() < 1e-6, "{v}");
        }
        assert_eq!(stable_unit(Vec3::ZERO), Vec3::ZERO);
    }

    #[test]
    fn terrain_counts_and_orientation() {
        for side in [1, 2, 5, 16] {
            let m = terrain(side, 1);
            m.validate().unwrap();
            assert_eq!(m.triangle_count(), 2 * (side * side) as usize);
            assert_eq!(m.vertex_count(), ((side + 1) * (side + 1)) as usize);
            // Counter-clockwise seen from above: every face normal has +y.
            assert!(m.triangles.iter().all(|t| {
                let [a, b, c] = t.map(|v| m.positions[v as usize]);
                (b - a).cross(c - a).y > 0.0
            }));
        }
    }
}
