//! A view-dependent hierarchy of multiresolution strips: a DAG of cluster
//! groups after meshoptimizer's cluster LoD (`demo/clusterlod.h`, itself
//! after Karis, "Nanite: A Deep Dive", SIGGRAPH 2021), where each group's
//! simplification is a recorded contraction sequence carrying its strips as
//! an [`MtsModel`], so a group changes its detail continuously, not in
//! discrete steps.
//!
//! - **Clusters** (`partition.rs`): the input's triangles, and later each
//!   group's output, cut into connected pieces of about
//!   [`HierarchyOptions::cluster_triangles`].
//! - **Groups** (`grouping.rs`): about [`HierarchyOptions::group_clusters`]
//!   adjacent clusters of one level. A group's *input* is its clusters'
//!   triangles; its *children* are the groups that produced them.
//! - **Build** (`build.rs`): each group's input becomes a submesh (input
//!   vertices and properties, seams kept) simplified toward half with its
//!   *outer border* locked ([`crate::simplify::simplify_locked`]): every
//!   point that a triangle of another group of the same level also uses;
//!   and every boundary point whose fan is not a consistently oriented
//!   half-disc (a non-manifold input's: `build.rs`, `loose_border_points`).
//!   The sequence, stopped there, and the submesh's strips make the group's
//!   [`MtsModel`]; its last LoD, its *output*, is cut into the next level's
//!   clusters. Levels repeat until one group is left or a level keeps more
//!   than [`STUCK_RATIO`] of its triangles.
//! - **Errors**, in model units: LoD `k` of group `g` has
//!   `max(floor(g), relative_error(k) × diagonal of g's submesh)` where
//!   `floor(g)` is the largest output error of its children (0 at level
//!   0). So a group's errors never decrease with `k` and are at least its
//!   children's: monotone up the DAG.
//! - **Selection** (`select.rs`): a [`Cut`] for a camera, see there for the
//!   rule and why what it draws has no crack.

mod build;
mod cracks;
pub mod format;
mod grouping;
mod partition;
mod runtime;
mod select;
mod strips;

pub use build::{build, build_with_progress, BuildProgress};
pub use cracks::cracks;
pub use runtime::{FrameUpdate, Frustum, View, ViewDependent};
pub use select::{select, select_exhaustive, select_into, Cut, Selection};

use crate::error::ensure;
use crate::model::MtsModel;
use glam::Vec3;

/// A level whose groups keep more than this share of their input
/// triangles ends the hierarchy (meshoptimizer's `simplify_threshold` is
/// 0.85 per cluster; here per level: groups left stuck by their locked
/// border are grouped again with others on the next level).
pub const STUCK_RATIO: f64 = 0.85;

/// The band slack of the groups' models (the per-object model's is
/// [`crate::model::DEFAULT_BAND_SLACK`], 0.1).
///
/// **Decision: 0.5, half the memory for 8% more indices.** A group halves
/// its triangles, so its bands are few and short-lived, and at 0.1 they
/// made the hierarchy 8.25 × the raw mesh on `terrain:100k` for 1.43
/// indices a triangle over 30 frames of the bench's flight at 1 px; at 0.5
/// it is 5.0 × for 1.54; at 1.0 4.5 × for 1.61; one band 3.9 × for 1.61
/// (`docs/experiments/hierarchy.md`, "Bands").
pub const BAND_SLACK: f64 = 0.5;

/// "No group" in [`Cluster::producer`] and [`Cluster::consumer`].
pub const NO_GROUP: u32 = u32::MAX;

/// Settings of [`build`].
#[derive(Debug, Clone)]
pub struct HierarchyOptions {
    /// Triangles per cluster, at most (meshoptimizer's default raster
    /// configuration uses 128).
    pub cluster_triangles: usize,
    /// Clusters per group, at most (meshoptimizer's `partition_size`
    /// targets 16 for clusters of 128; 4 halves a group's triangles into
    /// about two clusters of the next level).
    pub group_clusters: usize,
    /// Each group's strips, their bands and the contraction sequence's
    /// settings (its `stop_at_triangles` is set per group, to half its
    /// input; the default band slack is [`BAND_SLACK`]).
    pub pipeline: crate::model::PipelineOptions,
}

impl Default for HierarchyOptions {
    fn default() -> HierarchyOptions {
        HierarchyOptions {
            cluster_triangles: 128,
            group_clusters: 4,
            pipeline: crate::model::PipelineOptions {
                build: crate::model::BuildOptions {
                    band_slack: BAND_SLACK,
                    ..crate::model::BuildOptions::default()
                },
                ..crate::model::PipelineOptions::default()
            },
        }
    }
}

/// A connected piece of the surface at one level: of the input (level 0)
/// or of one group's output.
#[derive(Debug, Clone, PartialEq)]
pub struct Cluster {
    /// Its triangles' numbers: clusters number their triangles one after
    /// the other, so `triangles.len()` is its triangle count (the
    /// triangles themselves are its strips', [`Hierarchy::cluster_triangles`]).
    pub triangles: std::ops::Range<u32>,
    /// The group whose output it is; [`NO_GROUP`] for a cluster of the
    /// input.
    pub producer: u32,
    /// The group whose input it is; [`NO_GROUP`] for a root's output.
    pub consumer: u32,
    /// Its strips: a range of the hierarchy's flat strip array (read them
    /// with [`Hierarchy::cluster_strip`]).
    pub strip: std::ops::Range<u32>,
}

/// A group of adjacent clusters of one level, simplified with its outer
/// border locked.
#[derive(Debug, Clone, PartialEq)]
pub struct Group {
    /// 0 for groups of input clusters, one more per simplification.
    pub level: u32,
    /// Its input clusters, in the order their triangles are the model's
    /// LoD 0.
    pub inputs: Vec<u32>,
    /// The clusters its output was cut into.
    pub outputs: Vec<u32>,
    /// The groups that produced its inputs, ascending (none at level 0).
    pub children: Vec<u32>,
    /// Model vertex `i` is input vertex `vertices[i]`.
    pub vertices: Vec<u32>,
    /// Its strips over its contraction sequence, in model vertex numbers.
    pub model: MtsModel,
    /// The largest output error of its children, in model units: every
    /// LoD's error is at least this.
    pub floor: f32,
    /// Bounding-box diagonal of its submesh, the unit of its sequence's
    /// relative errors.
    pub diagonal: f32,
    /// A sphere holding its triangles and its children's spheres.
    pub centre: Vec3,
    /// See [`Group::centre`].
    pub radius: f32,
}

impl Group {
    /// The error of LoD `lod` in model units: at least [`Group::floor`],
    /// non-decreasing in `lod` (see the module documentation).
    #[must_use]
    pub fn error(&self, lod: usize) -> f32 {
        let own = f64::from(self.model.collapses().error(lod)) * f64::from(self.diagonal);
        self.floor.max(own as f32)
    }

    /// The error of its output (its last LoD), in model units.
    #[must_use]
    pub fn output_error(&self) -> f32 {
        self.error(self.model.max_lod())
    }

    /// Its triangles at `lod` (the replay of its sequence), in input vertex
    /// numbers. O(submesh).
    #[must_use]
    pub fn triangles_at(&self, lod: usize) -> Vec<[u32; 3]> {
        let local = self.model.collapses().triangles_at(&self.model.mesh(), lod);
        local
            .into_iter()
            .map(|t| t.map(|v| self.vertices[v as usize]))
            .collect()
    }
}

/// The DAG of groups of a mesh, built by [`build`].
///
/// Invariants (checked by [`Hierarchy::validate`]): each cluster is the
/// input of at most one group and the output of at most one; a group's
/// inputs are clusters of its level (the input's at level 0, its children's
/// outputs above), its children are their producers and lie one level
/// below; a group's floor is its children's largest output error; its
/// sphere holds its children's; each model is valid and maps into the
/// input's vertices.
#[derive(Debug, Clone, PartialEq)]
pub struct Hierarchy {
    pub(crate) clusters: Vec<Cluster>,
    pub(crate) groups: Vec<Group>,
    /// The input's vertices: what every cut indexes (one vertex buffer).
    pub(crate) positions: Vec<Vec3>,
    pub(crate) properties: crate::mesh::Properties,
    /// Every cluster's strips, runs separated by [`crate::strip::encode::RESTART_U32`],
    /// in input vertex numbers.
    pub(crate) cluster_strips: Vec<u32>,
    pub(crate) vertex_count: usize,
    pub(crate) triangle_count: usize,
}

impl Hierarchy {
    /// [`crate::model::verify`] of every group's model (its strips against
    /// its replayed triangles) at the LoDs `lods(max_lod)` gives for it
    /// (ascending), the groups on every core; the reports in group order.
    ///
    /// Cost: the groups' verifications, spread over the cores.
    #[must_use]
    pub fn verify_groups(
        &self,
        lods: impl Fn(usize) -> Vec<usize> + Sync,
    ) -> Vec<crate::model::VerifyReport> {
        crate::parallel::map_indexed(
            self.groups.len(),
            || (),
            |(), g| {
                let model = &self.groups[g].model;
                crate::model::verify(model, &model.mesh(), &lods(model.max_lod()))
            },
        )
    }

    /// The groups, children before parents (by level).
    #[must_use]
    pub fn groups(&self) -> &[Group] {
        &self.groups
    }

    /// The clusters of every level.
    #[must_use]
    pub fn clusters(&self) -> &[Cluster] {
        &self.clusters
    }

    /// The triangles of cluster `c`, in input vertex numbers, decoded from
    /// its strips (only the strips are kept). O(its strips).
    #[must_use]
    pub fn cluster_triangles(&self, c: usize) -> Vec<[u32; 3]> {
        strips::triangles_of(self.cluster_strip(c))
    }

    /// The number of triangles of cluster `c`. O(1).
    #[must_use]
    pub fn cluster_triangle_count(&self, c: usize) -> usize {
        self.clusters[c].triangles.len()
    }

    /// Triangles of every cluster of every level.
    #[must_use]
    pub fn cluster_triangle_total(&self) -> usize {
        self.clusters.last().map_or(0, |c| c.triangles.end as usize)
    }

    /// The strips of cluster `c`: runs in input vertex numbers separated by
    /// [`crate::strip::encode::RESTART_U32`], drawing exactly
    /// [`Hierarchy::cluster_triangles`].
    #[must_use]
    pub fn cluster_strip(&self, c: usize) -> &[u32] {
        let r = &self.clusters[c].strip;
        &self.cluster_strips[r.start as usize..r.end as usize]
    }

    /// The input's vertex positions, which every cut indexes.
    #[must_use]
    pub fn positions(&self) -> &[Vec3] {
        &self.positions
    }

    /// The input's vertex properties (normals, UVs, colours, texture,
    /// position ids), for [`Hierarchy::positions`].
    #[must_use]
    pub fn properties(&self) -> &crate::mesh::Properties {
        &self.properties
    }

    /// Levels of groups (the highest level plus one; 0 for an empty mesh).
    #[must_use]
    pub fn level_count(&self) -> usize {
        self.groups.last().map_or(0, |g| g.level as usize + 1)
    }

    /// Vertices of the input mesh.
    #[must_use]
    pub fn vertex_count(&self) -> usize {
        self.vertex_count
    }

    /// Triangles of the input mesh.
    #[must_use]
    pub fn triangle_count(&self) -> usize {
        self.triangle_count
    }

    /// Bytes in memory: every group's model ([`crate::model::ModelStats`]),
    /// its vertex map and lists, and the clusters' triangles.
    #[must_use]
    pub fn memory_bytes(&self) -> usize {
        let groups: usize = self
            .groups
            .iter()
            .map(|g| {
                g.model.stats().memory_bytes
                    + 4 * (g.vertices.len() + g.inputs.len() + g.outputs.len() + g.children.len())
                    + std::mem::size_of::<Group>()
            })
            .sum();
        groups
            + 4 * self.cluster_strips.len()
            + std::mem::size_of::<Cluster>() * self.clusters.len()
            + (12 + self.properties.bytes_per_vertex()) * self.positions.len()
            + 4 * self.properties.position_ids.len()
    }

    /// Checks the invariants listed on [`Hierarchy`].
    ///
    /// # Errors
    /// The first broken one.
    pub fn validate(&self) -> std::result::Result<(), crate::Invalid> {
        const S: &str = "Hierarchy";
        let (nc, ng) = (self.clusters.len(), self.groups.len() as u32);
        let nv = self.positions.len();
        ensure!(
            S,
            nv == self.vertex_count,
            "{nv} positions for {} vertices",
            self.vertex_count
        );
        let mut next_triangle = 0u32;
        for (i, c) in self.clusters.iter().enumerate() {
            ensure!(
                S,
                c.triangles.start == next_triangle && c.triangles.start <= c.triangles.end,
                "cluster {i}: triangles {:?} do not follow the previous cluster's",
                c.triangles
            );
            next_triangle = c.triangles.end;
            let ok =
                c.strip.start <= c.strip.end && c.strip.end as usize <= self.cluster_strips.len();
            ensure!(S, ok, "cluster {i}: strips out of range");
            let strip = self.cluster_strip(i);
            let in_range = strip
                .iter()
                .all(|&v| v == crate::strip::encode::RESTART_U32 || (v as usize) < nv);
            ensure!(S, in_range, "cluster {i}: a strip vertex out of range");
            let drawn = strips::triangles_of(strip);
            ensure!(
                S,
                drawn.len() == c.triangles.len(),
                "cluster {i}: its strips draw {} triangles, it has {}",
                drawn.len(),
                c.triangles.len()
            );
            for (end, name) in [(c.producer, "producer"), (c.consumer, "consumer")] {
                ensure!(
                    S,
                    end == NO_GROUP || end < ng,
                    "cluster {i}: {name} {end} of {ng} groups"
                );
            }
            let consumed = c.consumer == NO_GROUP
                || self.groups[c.consumer as usize]
                    .inputs
                    .contains(&(i as u32));
            ensure!(S, consumed, "cluster {i}: not an input of its consumer");
            let produced = c.producer == NO_GROUP
                || self.groups[c.producer as usize]
                    .outputs
                    .contains(&(i as u32));
            ensure!(S, produced, "cluster {i}: not an output of its producer");
        }
        for (gi, g) in self.groups.iter().enumerate() {
            let mut children: Vec<u32> = Vec::new();
            let mut floor = 0f32;
            for &c in &g.inputs {
                ensure!(
                    S,
                    (c as usize) < nc,
                    "group {gi}: input {c} of {nc} clusters"
                );
                let cluster = &self.clusters[c as usize];
                ensure!(
                    S,
                    cluster.consumer == gi as u32,
                    "group {gi}: input {c} consumed elsewhere"
                );
                if cluster.producer == NO_GROUP {
                    ensure!(
                        S,
                        g.level == 0,
                        "group {gi}: an input cluster above level 0"
                    );
                    continue;
                }
                let h = &self.groups[cluster.producer as usize];
                ensure!(
                    S,
                    h.level + 1 == g.level,
                    "group {gi}: a child not one level below"
                );
                let reach = h.centre.distance(g.centre) + h.radius;
                let holds = reach <= g.radius * (1.0 + 1e-5) + 1e-6;
                ensure!(
                    S,
                    holds,
                    "group {gi}: its sphere misses child {}",
                    cluster.producer
                );
                children.push(cluster.producer);
                floor = floor.max(h.output_error());
            }
            children.sort_unstable();
            children.dedup();
            ensure!(
                S,
                children == g.children,
                "group {gi}: children {:?}, inputs say {children:?}",
                g.children
            );
            ensure!(
                S,
                floor == g.floor,
                "group {gi}: floor {} for children's {floor}",
                g.floor
            );
            let mapped = g.vertices.len() == g.model.collapses().vertex_count()
                && g.vertices.iter().all(|&v| (v as usize) < self.vertex_count);
            ensure!(S, mapped, "group {gi}: vertex map out of range");
            if let Err(e) = g.model.validate() {
                ensure!(S, false, "group {gi}: {e}");
            }
            let inputs: usize = g
                .inputs
                .iter()
                .map(|&c| self.cluster_triangle_count(c as usize))
                .sum();
            let lod0 = g.model.triangle_count(0);
            ensure!(
                S,
                lod0 == inputs,
                "group {gi}: {lod0} triangles at LoD 0, {inputs} in its inputs"
            );
        }
        Ok(())
    }
}
