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

pub use adjacency::{TriangleAdjacency, NO_NEIGHBOUR};
pub use clean::{clean, CleanOptions, CleanReport, RawMesh};

use crate::error::{Error, Result};
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

/// Whether a triangle repeats a vertex index (draws nothing). The one test
/// used by loaders, cleaning, validation and strip decoding.
#[must_use]
#[inline]
pub fn is_degenerate(t: [u32; 3]) -> bool {
    t[0] == t[1] || t[1] == t[2] || t[0] == t[2]
}

/// An indexed triangle mesh.
///
/// Invariants (checked by [`Mesh::validate`]): every index is below
/// `positions.len()`, every coordinate is finite, no triangle repeats a
/// vertex index, and every vertex is referenced by some triangle.
/// Triangles are counter-clockwise when seen from the front.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Mesh {
    /// Vertex positions.
    pub positions: Vec<Vec3>,
    /// Triangles as three indices into `positions`.
    pub triangles: Vec<[u32; 3]>,
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

    /// Axis-aligned bounds `(min, max)`; `None` for a mesh without vertices.
    #[must_use]
    pub fn bounds(&self) -> Option<(Vec3, Vec3)> {
        bounds_of(&self.positions)
    }

    /// Length of the bounding-box diagonal (0 for an empty mesh); errors are
    /// reported relative to it.
    #[must_use]
    pub fn diagonal(&self) -> f32 {
        self.bounds().map_or(0.0, |(lo, hi)| (hi - lo).length())
    }

    /// Checks the invariants listed on [`Mesh`].
    ///
    /// # Errors
    /// [`Error::InvalidMesh`] naming the first offending vertex or triangle.
    pub fn validate(&self) -> Result<()> {
        let bad = |message: String| Error::InvalidMesh {
            source_name: "mesh".into(),
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
        }
        if let Some(v) = referenced.iter().position(|r| !r) {
            return Err(bad(format!("vertex {v} is not referenced")));
        }
        Ok(())
    }
}
