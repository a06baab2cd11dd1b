//! Indexed triangle meshes: the input of every stage.
//!
//! A [`Mesh`] holds positions and counter-clockwise triangles with `u32`
//! indices. Loaders and generators produce a [`RawMesh`] (whatever the source
//! said, after its own checks) and [`clean`] turns it into a [`Mesh`]:
//! optional weld of identical positions, degenerate triangles dropped and
//! counted, unreferenced vertices dropped.

pub mod adjacency;
mod clean;
pub mod generate;
pub mod io;
mod properties;

pub use adjacency::{TriangleAdjacency, NO_NEIGHBOUR};
pub use clean::{clean, CleanOptions, CleanReport, RawMesh};
pub use properties::{Properties, Texture};

use glam::Vec3;

/// Axis-aligned bounds `(min, max)` of `positions`; `None` when empty.
/// O(n).
#[must_use]
pub fn bounds_of(positions: &[Vec3]) -> Option<(Vec3, Vec3)> {
    let first = *positions.first()?;
    Some(
        positions
            .iter()
            .fold((first, first), |(lo, hi), &p| (lo.min(p), hi.max(p))),
    )
}

pub use crate::encoding::is_degenerate;

/// `triangles` renumbered from 0 in order of first use: the vertices used
/// (`vertices[i]` is local vertex `i`) and the local triangles. `remap` is
/// all `u32::MAX` on entry and on return (one per vertex `triangles`
/// may index), so a caller cutting many parts allocates it once. O(len).
#[must_use]
pub fn renumber(triangles: &[[u32; 3]], remap: &mut [u32]) -> (Vec<u32>, Vec<[u32; 3]>) {
    let mut vertices: Vec<u32> = Vec::new();
    let local: Vec<[u32; 3]> = triangles
        .iter()
        .map(|t| {
            t.map(|v| {
                let r = &mut remap[v as usize];
                if *r == u32::MAX {
                    *r = vertices.len() as u32;
                    vertices.push(v);
                }
                *r
            })
        })
        .collect();
    for &v in &vertices {
        remap[v as usize] = u32::MAX;
    }
    (vertices, local)
}

/// An indexed triangle mesh.
///
/// Invariants (checked by [`Mesh::validate`]): every index is below
/// `positions.len()`, every coordinate is finite, no triangle repeats a
/// vertex index or a point ([`Properties::position_id`]), every vertex is
/// referenced by some triangle, and the properties keep theirs
/// ([`Properties::validate`]).
/// Triangles are counter-clockwise when seen from the front.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Mesh {
    /// Vertex positions.
    pub positions: Vec<Vec3>,
    /// Triangles as three indices into `positions`.
    pub triangles: Vec<[u32; 3]>,
    /// Normals, texture coordinates, colours and the points split vertices
    /// share ([`Properties`]); empty for a mesh of positions only.
    pub properties: Properties,
}

impl Mesh {
    /// Number of vertices.
    #[must_use]
    pub fn vertex_count(&self) -> usize {
        self.positions.len()
    }

    /// Number of triangles.
    #[must_use]
    pub fn triangle_count(&self) -> usize {
        self.triangles.len()
    }

    /// A mesh of `positions` and `properties` (of the same vertices) with
    /// only the vertices `triangles` use, renumbered in their order: what
    /// a level of detail is when it is exported (a LoD of a model names
    /// its vertices by the full mesh's numbers, most of them unused at a
    /// coarse level). Position ids are renumbered densely
    /// ([`Properties::gather`]).
    ///
    /// # Panics
    /// If a triangle names a vertex past `positions`, or a property stream
    /// has another length than `positions`.
    ///
    /// Cost: O(vertices + triangles).
    #[must_use]
    pub fn level(positions: &[Vec3], triangles: &[[u32; 3]], properties: &Properties) -> Mesh {
        const UNUSED: u32 = u32::MAX;
        let mut remap = vec![UNUSED; positions.len()];
        let mut order = Vec::new();
        let triangles = triangles
            .iter()
            .map(|t| {
                t.map(|v| {
                    let r = &mut remap[v as usize];
                    if *r == UNUSED {
                        *r = order.len() as u32;
                        order.push(v);
                    }
                    *r
                })
            })
            .collect();
        Mesh {
            positions: order.iter().map(|&v| positions[v as usize]).collect(),
            triangles,
            properties: properties.gather(&order),
        }
    }

    /// The triangles as a flat `u32` index list (3 per triangle).
    #[must_use]
    pub fn index_list(&self) -> Vec<u32> {
        self.triangles.iter().flatten().copied().collect()
    }

    /// Bytes of this mesh stored raw with 16-bit indices: 12 per vertex
    /// (three `f32`) and 6 per triangle, the reference of the cluster-tree
    /// paper's Table 2 (see also [`crate::MtsModel::raw_bytes`]).
    #[must_use]
    pub fn raw_bytes_u16(&self) -> usize {
        12 * self.vertex_count() + 6 * self.triangle_count()
    }

    /// The part of the mesh drawn by `triangles` (over its vertices) as a
    /// mesh of its own: the vertices they use, renumbered in order of first
    /// use, with their properties (no texture: the whole mesh's serves),
    /// and which vertex each local one is. A valid mesh: every vertex is
    /// referenced. `remap` as [`renumber`]'s. O(len).
    #[must_use]
    pub fn submesh(&self, triangles: &[[u32; 3]], remap: &mut [u32]) -> (Mesh, Vec<u32>) {
        let (vertices, local) = renumber(triangles, remap);
        let properties = if self.properties.is_empty() {
            Properties::default()
        } else {
            Properties {
                texture: None,
                ..self.properties.gather(&vertices)
            }
        };
        let mesh = Mesh {
            positions: vertices
                .iter()
                .map(|&v| self.positions[v as usize])
                .collect(),
            triangles: local,
            properties,
        };
        (mesh, vertices)
    }

    /// Axis-aligned bounds `(min, max)`; `None` for a mesh without vertices.
    #[must_use]
    pub fn bounds(&self) -> Option<(Vec3, Vec3)> {
        bounds_of(&self.positions)
    }

    /// Length of the bounding-box diagonal (0 for an empty mesh); errors are
    /// reported relative to it. Saturates at `f32::MAX` for boxes whose
    /// diagonal `f32` cannot hold (coordinates near ±3.4e38); see
    /// [`Mesh::diagonal_f64`].
    #[must_use]
    pub fn diagonal(&self) -> f32 {
        (self.diagonal_f64() as f32).min(f32::MAX)
    }

    /// Length of the bounding-box diagonal in `f64`, exact for any finite
    /// coordinates: the `f32` length where its squares neither overflow nor
    /// become subnormal (every extent from 1e-18 to 1e18, so ordinary models
    /// keep the value they always had, bit for bit), else the length
    /// computed in `f64`, where the squares of any two finite `f32` fit.
    ///
    /// Cost: O(vertices).
    #[must_use]
    pub fn diagonal_f64(&self) -> f64 {
        self.bounds().map_or(0.0, |(lo, hi)| diagonal_of(lo, hi))
    }
}

/// A power of two that brings `positions` into a frame where `f32`
/// squared distances neither overflow nor go subnormal: 1 when the largest
/// coordinate magnitude lies in 2^-40..2^40 (every ordinary model: its
/// arithmetic is untouched), else 2^-e for that magnitude's exponent e, so
/// the scaled magnitudes are near 1. Scaling by a power of two is exact, so
/// distances in the frame are the true ones times the scale, rounding
/// included. Returns 1 for an empty or all-zero input. O(n).
#[must_use]
pub fn power_of_two_scale(positions: &[Vec3]) -> f64 {
    let largest = positions
        .iter()
        .fold(0.0f32, |m, p| m.max(p.abs().max_element()));
    if largest == 0.0 || !largest.is_finite() || (2f32.powi(-40)..=2f32.powi(40)).contains(&largest)
    {
        return 1.0;
    }
    // In f64: the scale of a subnormal magnitude (2^149) is beyond f32.
    2f64.powi(-f64::from(largest).log2().floor() as i32)
}

/// `positions` times `scale` (a power of two from [`power_of_two_scale`]:
/// exact, computed in `f64` so a factor beyond `f32`'s range still works).
/// O(n).
#[must_use]
pub fn scaled_positions(positions: &[Vec3], scale: f64) -> Vec<Vec3> {
    positions
        .iter()
        .map(|p| (p.as_dvec3() * scale).as_vec3())
        .collect()
}

/// Length of the box `lo..hi` as [`Mesh::diagonal_f64`] defines it.
#[must_use]
pub fn diagonal_of(lo: Vec3, hi: Vec3) -> f64 {
    let extent = hi - lo;
    let largest = extent.max_element();
    if extent.is_finite() && (1e-18..=1e18).contains(&largest) {
        return f64::from(extent.length());
    }
    let (lo, hi) = (lo.as_dvec3(), hi.as_dvec3());
    (hi - lo).length()
}

impl Mesh {
    /// Checks the invariants listed on [`Mesh`].
    ///
    /// # Errors
    /// [`crate::Invalid`] naming the first offending vertex or triangle.
    pub fn validate(&self) -> std::result::Result<(), crate::Invalid> {
        let bad = |message: String| crate::Invalid {
            structure: "Mesh",
            message,
        };
        if let Some(i) = self.positions.iter().position(|p| !p.is_finite()) {
            return Err(bad(format!("vertex {i} has a non-finite coordinate")));
        }
        let n = self.positions.len();
        let mut referenced = vec![false; n];
        for (t, tri) in self.triangles.iter().enumerate() {
            for &v in tri {
                let v = v as usize;
                if v >= n {
                    return Err(bad(format!("triangle {t} uses vertex {v} of {n} vertices")));
                }
                referenced[v] = true;
            }
            if is_degenerate(*tri) {
                return Err(bad(format!("triangle {t} is degenerate: {tri:?}")));
            }
            if !self.properties.position_ids.is_empty()
                && is_degenerate(tri.map(|v| self.properties.position_id(v)))
            {
                return Err(bad(format!("triangle {t} repeats a point: {tri:?}")));
            }
        }
        self.properties.validate(&self.positions).map_err(bad)?;
        if let Some(v) = referenced.iter().position(|r| !r) {
            return Err(bad(format!("vertex {v} is not referenced")));
        }
        Ok(())
    }
}
