//! The cluster tree after Schmalstieg and Schaufler, "Incremental encoding
//! of polygonal models" (HICSS 1997), sections 4
//! to 7: hierarchical vertex clustering (`build.rs`), the update and
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
//! compare them. Variable resolution by projected cluster size (section 7,
//! "Variable resolution within one object") is [`ClusterTree::view_dependent`]:
//! a cut of the tree chosen per node, drawn through its own pc-rep array,
//! outside the shared LoD numbering.
//!
//! Properties: the tree clusters vertices, not points, so on a mesh with
//! seams the vertices of one point (at distance 0) join first and one
//! side's values stand for the other's from there on, as the paper's
//! clustering of a split mesh would. Each vertex's values ride with it in
//! the runtime and the stream.

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
    /// Input triangles in level numbering (the view-dependent cut reads
    /// them through its own representatives).
    triangles: Vec<[u32; 3]>,
    /// For each join, the later join that folds the cluster it made into
    /// a larger one (`u32::MAX` for the root's).
    parent_join: Vec<u32>,
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
        // Distances are squared in f32: far-flung or tiny coordinates are
        // clustered in a frame scaled by a power of two (exact; 1 for every
        // ordinary model), and sizes scaled back.
        let scale = crate::mesh::power_of_two_scale(&mesh.positions);
        let joins = if scale == 1.0 {
            build::cluster(&mesh.positions)
        } else {
            build::cluster(&crate::mesh::scaled_positions(&mesh.positions, scale))
        };
        let diagonal = mesh.diagonal_f64() * scale;
        let steps: Vec<_> = joins
            .iter()
            .map(|(c, size)| crate::simplify::Collapse {
                error: if diagonal > 0.0 {
                    (f64::from(*size) / diagonal) as f32
                } else {
                    0.0
                },
                ..*c
            })
            .collect();
        let sizes = joins
            .iter()
            .map(|(_, s)| ((f64::from(*s) / scale) as f32).min(f32::MAX))
            .collect();
        let counts = crate::model::format::replay_counts(mesh, &steps, false, &[]);
        let collapses = Collapses::new(mesh.vertex_count(), steps, counts, Vec::new());
        let levels = Levels::new(mesh, &collapses)?;
        let runtime = ProgressiveMesh::from_levels(mesh, &levels);
        // The cluster join `i` makes is represented by its kept vertex; the
        // next join that involves that vertex folds it further.
        let n = mesh.vertex_count();
        let mut last_seen = vec![u32::MAX; n];
        let max_lod = runtime.max_lod();
        let mut parent_join = vec![u32::MAX; max_lod];
        for i in (0..max_lod).rev() {
            let (k, r) = (runtime.parent_of(n - 1 - i) as usize, n - 1 - i);
            parent_join[i] = last_seen[k];
            last_seen[k] = i as u32;
            last_seen[r] = i as u32;
        }
        Ok(ClusterTree {
            sizes,
            collapses,
            runtime,
            triangles: levels.triangles,
            parent_join,
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

    /// Variable resolution (section 7): the triangles of the cut where a
    /// node is unfolded when its projected size, cluster size over the
    /// distance from `eye` to its representative, is at least `threshold`
    /// (radians, roughly) and the node above it is unfolded too. Indices
    /// refer to [`LodSource::positions`]; nearer parts come out finer.
    /// `threshold = 0` gives the full mesh. O(V + T); allocates the result
    /// and two working arrays.
    #[must_use]
    pub fn view_dependent(&self, eye: Vec3, threshold: f32) -> Vec<[u32; 3]> {
        // The clustering moves one vertex per join: join `i` removes
        // vertex `n - 1 - i`.
        let positions = &self.runtime.positions;
        let n = positions.len();
        let joins = self.runtime.max_lod();
        let kept = |i: usize| self.runtime.parent_of(n - 1 - i) as usize;
        let mut unfolded = vec![false; joins];
        for i in (0..joins).rev() {
            let above = self.parent_join[i];
            let open = above == u32::MAX || unfolded[above as usize];
            let distance = positions[kept(i)].distance(eye);
            unfolded[i] = open && self.sizes[i] >= threshold * distance;
        }
        let roots = n - joins;
        let mut pc: Vec<u32> = (0..n as u32).collect();
        for v in roots..n {
            let i = n - 1 - v;
            if !unfolded[i] {
                pc[v] = pc[kept(i)];
            }
        }
        self.triangles
            .iter()
            .map(|t| t.map(|v| pc[v as usize]))
            .filter(|&t| !crate::mesh::is_degenerate(t))
            .collect()
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

    fn properties(&self) -> &crate::mesh::Properties {
        self.runtime.properties()
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
