//! The cluster tree after "Incremental encoding of polygonal models"
//! (`../shared/papers/cluster-tree-incremental-encoding.txt`), sections 4
//! to 7: hierarchical vertex clustering ([`build`]), the update and
//! collapsed lists of each node, LoD selection by a cluster-size threshold,
//! refinement and simplification between LoDs, and the linearized packet
//! stream with its incremental decoder ([`stream`]).
//!
//! A join of two clusters is a contraction whose removed vertex is the
//! representative that loses, so the clustering is a contraction sequence
//! of its own (it joins vertices that share no edge, and ends with one
//! cluster). Each node's *update list* (triangles whose vertex changes to
//! the new representative) and *collapsed list* (triangles that collapse)
//! are exactly a vertex split's redirected corners and new faces, so the
//! runtime is the [`ProgressiveMesh`] machinery over the clustering's
//! sequence: refinement unfolds nodes one by one and simplification folds
//! them, both on a maintained triangle list.
//!
//! LoD numbering: LoD `k` is the mesh after the first `k` joins (LoD 0 the
//! input); its own sequence, so LoD `k` of the cluster tree and of MTS
//! differ. Budgets ([`ClusterTree::lod_for_size`] or a triangle count)
//! compare them. Variable resolution by projected cluster size (section 7)
//! is not implemented.

mod build;
pub mod stream;

use super::levels::Levels;
use super::pm::ProgressiveMesh;
use crate::error::{Error, Result};
use crate::lod::{LodSource, Topology};
use crate::mesh::Mesh;
use crate::simplify::Collapses;
use glam::Vec3;
use std::ops::Range;

/// A cluster tree with its runtime triangle list.
#[derive(Debug, Clone)]
pub struct ClusterTree {
    /// Cluster size of each join (node), non-decreasing, mesh units.
    sizes: Vec<f32>,
    /// The joins as a contraction sequence (errors: size / diagonal).
    collapses: Collapses,
    runtime: ProgressiveMesh,
}

impl ClusterTree {
    /// Clusters `mesh`'s vertices and records every node's update and
    /// collapsed lists. O(V log V) for the clustering (kd-tree nearest
    /// neighbours) plus a replay of the joins.
    ///
    /// # Errors
    /// [`Error::InvalidMesh`] for a mesh without vertices.
    pub fn new(mesh: &Mesh) -> Result<ClusterTree> {
        if mesh.vertex_count() == 0 {
            return Err(Error::InvalidMesh {
                source_name: "cluster tree".into(),
                message: "no vertices".into(),
            });
        }
        let joins = build::cluster(&mesh.positions);
        let diagonal = mesh.diagonal();
        let steps: Vec<_> = joins
            .iter()
            .map(|(c, size)| crate::simplify::Collapse {
                error: if diagonal > 0.0 { size / diagonal } else { 0.0 },
                ..*c
            })
            .collect();
        let sizes = joins.iter().map(|(_, s)| *s).collect();
        let counts = crate::model::format::replay_counts(mesh, &steps, false);
        let collapses = Collapses::new(mesh.vertex_count(), steps, counts, Vec::new());
        let levels = Levels::new(mesh, &collapses)?;
        let runtime = ProgressiveMesh::from_levels(mesh, &levels);
        Ok(ClusterTree {
            sizes,
            collapses,
            runtime,
        })
    }

    /// The joins as a contraction sequence over the input mesh (the replay
    /// oracle of the tests reads it).
    #[must_use]
    pub fn collapses(&self) -> &Collapses {
        &self.collapses
    }

    /// Cluster size of join `i` (distance of the two representatives).
    #[must_use]
    pub fn size(&self, i: usize) -> f32 {
        self.sizes[i]
    }

    /// The LoD of threshold `size` (section 5, "Selection of a LOD"):
    /// refinement continues while an active node is at least `size`, so the
    /// joins kept are those smaller than it. O(log V).
    #[must_use]
    pub fn lod_for_size(&self, size: f32) -> usize {
        self.sizes.partition_point(|&s| s < size)
    }

    /// The packet stream of section 6 ([`stream::encode`]).
    #[must_use]
    pub fn to_stream(&self) -> Vec<u8> {
        stream::encode(&self.runtime)
    }

    /// Input vertex of each stream vertex (the stream numbers vertices in
    /// the order they arrive).
    #[must_use]
    pub fn stream_order(&self) -> &[u32] {
        &self.runtime.order
    }
}

impl LodSource for ClusterTree {
    fn name(&self) -> &'static str {
        "cluster"
    }

    fn max_lod(&self) -> usize {
        self.runtime.max_lod()
    }

    fn triangle_count(&self, lod: usize) -> usize {
        self.runtime.triangle_count(lod)
    }

    fn positions(&self) -> &[Vec3] {
        self.runtime.positions()
    }

    fn topology(&self) -> Topology {
        Topology::TriangleList
    }

    /// Refines (unfolds nodes) or simplifies (folds them) one node at a time
    /// from the current LoD: O(lists of the nodes crossed).
    fn set_lod(&mut self, lod: usize) -> usize {
        self.runtime.set_lod(lod)
    }

    fn lod(&self) -> Option<usize> {
        self.runtime.lod()
    }

    fn indices(&self) -> &[u32] {
        self.runtime.indices()
    }

    fn dirty_ranges(&self) -> &[Range<usize>] {
        self.runtime.dirty_ranges()
    }

    fn memory_bytes(&self) -> usize {
        self.runtime.memory_bytes() + 4 * self.sizes.len()
    }

    /// The packet stream's length (encodes it: O(stream)).
    fn file_bytes(&self) -> usize {
        self.to_stream().len()
    }

    fn triangles(&self) -> Vec<[u32; 3]> {
        self.runtime.triangles()
    }
}
