//! meshoptimizer's cluster level of detail (`clusterlod.h`, through
//! `meshopt::clod_build`), the view-dependent peer: its DAG of cluster
//! groups for a [`Mesh`], and the DAG's cut for one viewpoint.
//!
//! Follows Karis, "Nanite: A Deep Dive" (SIGGRAPH 2021 Advances course),
//! its "Cluster DAG" and "LOD selection" parts, in the form meshoptimizer
//! gives it (`demo/clusterlod.h`; the cut is `demo/nanite.cpp`'s), after
//! Cignoni et al., "Batched Multi Triangulation" (IEEE Visualization
//! 2005). The mesh is cut into clusters of at most [`MAX_TRIANGLES`];
//! clusters are partitioned into groups of about 16 neighbours; every
//! group is merged, simplified to half its triangles with the vertices it
//! shares with other groups locked, and cut into new clusters, which are
//! grouped again at the next depth. A group whose simplification keeps
//! more than 85% of its triangles is terminal: its clusters are the
//! coarsest of their region. Locked group borders make every cut that
//! respects the DAG crack-free. What `tests/clusterlod.rs` found: no open
//! edge in any cut of a closed icosphere or a seamed torus, but one
//! cluster of `icosphere:20k`'s DAG (depth 6) holds a triangle both ways
//! round, a fold of zero area that leaves the surface closed but not
//! manifold where a cut draws it.
//!
//! **Errors.** meshoptimizer's error is absolute, a distance in the mesh's
//! units (`meshopt_SimplifyErrorAbsolute`): the simplifier's error of the
//! group, combined up the DAG as `max(children's, own)` so that it never
//! decreases toward the root, amplified ×2 where the sloppy fallback ran,
//! with the normals' error clamped to the positions' scale. The core's
//! errors ([`crate::Collapses::error`]) are relative to the mesh's
//! bounding-box diagonal: [`Bounds::relative_error`] converts. The cut
//! compares the absolute error with the pixel threshold directly, which is
//! the core's `relative × diagonal` at scale 1.
//!
//! **The cut** ([`ClusterLod::cut`]) is the demo's: a cluster is drawn when
//! the group that produced it (or none: full detail) projects within the
//! threshold and the group it belongs to (whose simplification would
//! replace it) does not. "Projects within" is the core's rule
//! ([`crate::lod_for_screen_error`]): error × [`Projection::pixels_per_unit`]
//! at the nearest point of the group's bounding sphere ≤ threshold. The demo
//! instead clamps that distance at a near plane (`znear`) where the core
//! lets an eye inside the sphere ask for full detail; it is otherwise the
//! same projection (`error / distance × cot(fov/2) / 2 × viewport height`).
//! A group's sphere contains its children's and its error is at least
//! theirs, so the test is monotone up the DAG and the cut is consistent.

use crate::error::{ensure, Error, Invalid, Result};
use crate::mesh::Mesh;
use crate::screen_error::{nearest_distance, Projection};
use glam::Vec3;
use std::ops::Range;

/// Triangles (and vertices) per cluster: meshoptimizer's demo
/// (`demo/nanite.cpp`) calls `clodDefaultConfig(128)`.
pub const MAX_TRIANGLES: usize = 128;

/// Weight of each normal component in the simplifier's error, as
/// meshoptimizer's demo gives it (`attribute_weights = {0.5, 0.5, 0.5}`).
pub const NORMAL_WEIGHT: f32 = 0.5;

// The positions go to meshoptimizer as they lie in `Mesh::positions`:
// three packed `f32` a vertex (`glam::Vec3` is `repr(C)`).
const _: () = assert!(std::mem::size_of::<Vec3>() == 12);

/// meshoptimizer's default configuration for rasterisation,
/// `clodDefaultConfig(MAX_TRIANGLES)`, unchanged: clusters of at most 128
/// vertices and 128 triangles (at least 42, `meshopt_buildMeshletsFlex`
/// with split factor 2, not spatial), their triangles optimised for
/// locality (level 1); groups of about 16 clusters (up to a third more),
/// partitioned spatially, unsorted; each group simplified toward half its
/// triangles (ratio 0.5), terminal above 85% (threshold 0.85), with
/// permissive simplification, clamped attribute error and the sloppy
/// fallback (its error ×2) where the regular one gets stuck; errors merged
/// as `max(previous × 1, own) + own × 0`; no edge-length limit, no
/// regularisation, no fold preservation, no border dilation; cluster
/// bounds left as the group's (not recomputed).
#[must_use]
pub fn config() -> meshopt::ClodConfig {
    meshopt::clod_default_config(MAX_TRIANGLES)
}

/// A bounding sphere with an error, as meshoptimizer's `clodBounds`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Bounds {
    /// Centre of the sphere, in mesh coordinates.
    pub centre: Vec3,
    /// Radius of the sphere, in mesh units.
    pub radius: f32,
    /// Simplification error in mesh units (absolute, not relative to the
    /// diagonal: see the module docs); 0 for the input's own clusters,
    /// `f32::MAX` for a terminal group ([`Bounds::is_terminal`]).
    pub error: f32,
}

impl Bounds {
    /// Whether these are a terminal group's bounds: meshoptimizer could not
    /// simplify the group, so nothing coarser replaces its clusters.
    #[must_use]
    pub fn is_terminal(&self) -> bool {
        self.error == f32::MAX
    }

    /// The error relative to the bounding-box `diagonal`, the core's unit
    /// ([`crate::Collapses::error`]): infinite for a terminal group, 0 for a
    /// zero error whatever the diagonal.
    #[must_use]
    pub fn relative_error(&self, diagonal: f32) -> f32 {
        if self.is_terminal() {
            f32::INFINITY
        } else if self.error == 0.0 {
            0.0
        } else {
            self.error / diagonal
        }
    }

    /// Whether the error, seen from `eye` (mesh coordinates) through
    /// `projection`, covers at most `pixel_threshold` pixels at the
    /// sphere's nearest point: the rule of [`crate::lod_for_screen_error`]
    /// at scale 1. An eye inside the sphere sees only a zero error within
    /// any threshold. Never for a terminal group, nor for a threshold that
    /// is not a finite number above 0 (full detail, as in the core); always
    /// for a finite error when the projection shows nothing (0 pixels per
    /// unit). O(1), allocation-free.
    #[must_use]
    pub fn projects_within(&self, eye: Vec3, projection: Projection, pixel_threshold: f32) -> bool {
        let sane_threshold = pixel_threshold.is_finite() && pixel_threshold > 0.0;
        if !sane_threshold || self.is_terminal() || self.error.is_nan() {
            return false;
        }
        let pixels_per_unit =
            projection.pixels_per_unit(nearest_distance(eye, self.centre, self.radius));
        if pixels_per_unit.is_nan() {
            return false;
        }
        let limit = if pixels_per_unit == 0.0 {
            f64::INFINITY
        } else {
            f64::from(pixel_threshold) / f64::from(pixels_per_unit)
        };
        f64::from(self.error) <= limit
    }
}

/// One cluster of the DAG.
#[derive(Debug, Clone, PartialEq)]
pub struct Cluster {
    /// The group the cluster belongs to (an index into
    /// [`ClusterLod::groups`]): the cluster is an input of that group's
    /// simplification, whose bounds ([`Group::simplified`]) say when the
    /// cluster is too fine to draw.
    pub group: u32,
    /// The group whose simplification produced the cluster, always one
    /// output before [`Cluster::group`]; `None` for the input's own
    /// triangles. Its [`Group::simplified`] says when the cluster is fine
    /// enough to draw.
    pub refined: Option<u32>,
    /// The bounds meshoptimizer gives the cluster, for culling: the input's
    /// clusters have their own sphere and error 0, the others their
    /// producing group's merged sphere and error.
    pub bounds: Bounds,
    /// The cluster's triangles, a range of [`ClusterLod::triangles`]:
    /// 1 to [`MAX_TRIANGLES`].
    pub triangles: Range<u32>,
    /// Distinct vertices the triangles use, at most [`MAX_TRIANGLES`].
    pub vertex_count: u32,
}

/// One group of clusters: simplified together, their shared border with
/// other groups locked.
#[derive(Debug, Clone, PartialEq)]
pub struct Group {
    /// DAG depth at which the group was formed: 0 for groups of the input's
    /// clusters. Groups are stored by non-decreasing depth.
    pub depth: u32,
    /// Bounds of the group's simplification: a sphere containing its
    /// clusters' spheres and the error of its simplified triangles (at
    /// least its clusters' errors); `f32::MAX` error for a terminal group.
    pub simplified: Bounds,
    /// The group's clusters, a range of [`ClusterLod::clusters`].
    pub clusters: Range<u32>,
}

/// meshoptimizer's cluster LoD DAG of a mesh: every cluster at every depth,
/// with triangles that index the mesh's own vertices (no vertex is moved or
/// created; [`ClusterLod::positions`] is the vertex buffer).
///
/// Invariants (checked by [`ClusterLod::validate`]): groups are stored by
/// non-decreasing depth and hold contiguous, consecutive ranges of the
/// clusters, which name them back; every cluster has 1 to
/// [`MAX_TRIANGLES`] triangles, with indices below the vertex count; a
/// cluster's producing group comes before its own group, at a smaller depth,
/// is not terminal and has an error no larger; every non-terminal group
/// produced at least one cluster; no error is NaN or negative.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ClusterLod {
    positions: Vec<Vec3>,
    triangles: Vec<[u32; 3]>,
    clusters: Vec<Cluster>,
    groups: Vec<Group>,
    diagonal: f32,
}

/// The clusters a viewpoint draws and their triangles, from
/// [`ClusterLod::cut`]; reusable through [`ClusterLod::cut_into`].
#[derive(Debug, Clone, Default)]
pub struct Cut {
    /// Drawn clusters, indices into [`ClusterLod::clusters`], ascending.
    pub clusters: Vec<u32>,
    /// Their triangles, indices into [`ClusterLod::positions`], cluster
    /// after cluster.
    pub triangles: Vec<[u32; 3]>,
    /// Per group: does its simplification project within the threshold.
    accepted: Vec<bool>,
}

impl Cut {
    /// Number of drawn clusters.
    #[must_use]
    pub fn cluster_count(&self) -> usize {
        self.clusters.len()
    }

    /// Number of drawn triangles.
    #[must_use]
    pub fn triangle_count(&self) -> usize {
        self.triangles.len()
    }
}

impl ClusterLod {
    /// Builds meshoptimizer's DAG of `mesh` with [`config`]. The mesh's
    /// normals, when it has them, weigh in the simplifier's error with
    /// [`NORMAL_WEIGHT`] and its texture seams are protected
    /// (`attribute_protect_mask`), as in meshoptimizer's demo; colours are
    /// not given. A mesh without triangles gives an empty DAG.
    ///
    /// meshoptimizer's time grows with the square of a vertex's valence:
    /// callers check [`super::meshopt::refusal`] first.
    ///
    /// # Errors
    /// [`Error::InvalidMesh`] when the mesh is not one meshoptimizer may be
    /// given (an index past the vertices, a coordinate or property that is
    /// not finite, a property stream of another length, more than `u32`
    /// indices); [`Error::Invalid`] if meshoptimizer's output breaks an
    /// invariant listed on [`ClusterLod`].
    ///
    /// Cost: meshoptimizer's, about O(T log T) for T triangles; the DAG
    /// holds about twice the input's triangles.
    pub fn build(mesh: &Mesh) -> Result<ClusterLod> {
        check(mesh)?;
        let mut lod = ClusterLod {
            positions: mesh.positions.clone(),
            diagonal: mesh.diagonal(),
            ..ClusterLod::default()
        };
        if mesh.triangles.is_empty() {
            return Ok(lod);
        }
        let indices = mesh.index_list();
        let vertices = meshopt::VertexDataAdapter::new(
            meshopt::typed_to_bytes(&mesh.positions),
            std::mem::size_of::<Vec3>(),
            0,
        )
        .map_err(|e| invalid_mesh(format!("meshoptimizer refused the positions: {e}")))?;
        let stream = AttributeStream::of(mesh);
        let clod_mesh = meshopt::ClodMesh {
            vertex_attributes: &stream.values,
            vertex_attributes_stride: stream.stride_floats * std::mem::size_of::<f32>(),
            attribute_weights: &stream.weights,
            attribute_protect_mask: stream.protect_mask,
            ..meshopt::ClodMesh::new(&indices, &vertices)
        };
        // The callback runs inside C++: it must not panic (an unwind there
        // aborts), so it only pushes, and `validate` judges afterwards.
        meshopt::clod_build(config(), &clod_mesh, |group, clusters| {
            lod.push_group(group, clusters)
        });
        lod.validate()?;
        Ok(lod)
    }

    /// Records one group and its clusters as meshoptimizer emits them, and
    /// returns the group's index (meshoptimizer stores it in the `refined`
    /// of the clusters simplified from this group).
    fn push_group(
        &mut self,
        group: meshopt::ClodGroup,
        clusters: &[meshopt::ClodCluster<'_>],
    ) -> i32 {
        let id = self.groups.len();
        let first_cluster = self.clusters.len() as u32;
        for c in clusters {
            let first = self.triangles.len() as u32;
            self.triangles
                .extend(c.indices.chunks_exact(3).map(|t| [t[0], t[1], t[2]]));
            self.clusters.push(Cluster {
                group: id as u32,
                refined: u32::try_from(c.refined).ok(),
                bounds: bounds_of(c.bounds),
                triangles: first..self.triangles.len() as u32,
                vertex_count: c.vertex_count as u32,
            });
        }
        self.groups.push(Group {
            depth: u32::try_from(group.depth).unwrap_or(u32::MAX),
            simplified: bounds_of(group.simplified),
            clusters: first_cluster..self.clusters.len() as u32,
        });
        i32::try_from(id).unwrap_or(-1)
    }

    /// The vertex buffer every triangle indexes: the mesh's positions.
    #[must_use]
    pub fn positions(&self) -> &[Vec3] {
        &self.positions
    }

    /// Every cluster's triangles, cluster after cluster (a cluster's are
    /// [`Cluster::triangles`]), indices into [`ClusterLod::positions`];
    /// counter-clockwise as the input's.
    #[must_use]
    pub fn triangles(&self) -> &[[u32; 3]] {
        &self.triangles
    }

    /// The clusters, group after group.
    #[must_use]
    pub fn clusters(&self) -> &[Cluster] {
        &self.clusters
    }

    /// The groups, in meshoptimizer's output order (by depth).
    #[must_use]
    pub fn groups(&self) -> &[Group] {
        &self.groups
    }

    /// The triangles of cluster `cluster`.
    ///
    /// # Panics
    /// If `cluster` is not below `clusters().len()`.
    #[must_use]
    pub fn cluster_triangles(&self, cluster: usize) -> &[[u32; 3]] {
        let r = &self.clusters[cluster].triangles;
        &self.triangles[r.start as usize..r.end as usize]
    }

    /// Bytes in memory: positions, every depth's triangles, the clusters
    /// and groups (what a renderer keeps to cut the DAG; all of it is
    /// resident, as in meshoptimizer's demo).
    #[must_use]
    pub fn memory_bytes(&self) -> usize {
        12 * self.positions.len()
            + 12 * self.triangles.len()
            + std::mem::size_of::<Cluster>() * self.clusters.len()
            + std::mem::size_of::<Group>() * self.groups.len()
    }

    /// Number of DAG depths (the deepest group's depth + 1); 0 when empty.
    #[must_use]
    pub fn level_count(&self) -> usize {
        self.groups.last().map_or(0, |g| g.depth as usize + 1)
    }

    /// Triangles of full detail: those of the input's own clusters, the
    /// cut at threshold 0.
    #[must_use]
    pub fn triangle_count(&self) -> usize {
        self.clusters
            .iter()
            .filter(|c| c.refined.is_none())
            .map(|c| c.triangles.len())
            .sum()
    }

    /// The mesh's bounding-box diagonal, the unit of the core's errors
    /// ([`Bounds::relative_error`]).
    #[must_use]
    pub fn diagonal(&self) -> f32 {
        self.diagonal
    }

    /// The cut for a viewpoint: the clusters meshoptimizer's demo draws
    /// from `eye` (mesh coordinates) through `projection` at
    /// `pixel_threshold`, and their triangles (see the module docs for the
    /// rule). A threshold that is not a finite number above 0 draws full
    /// detail; an empty DAG draws nothing.
    ///
    /// Cost: O(groups + clusters + drawn triangles); allocates the result
    /// ([`ClusterLod::cut_into`] reuses one).
    #[must_use]
    pub fn cut(&self, eye: Vec3, projection: Projection, pixel_threshold: f32) -> Cut {
        let mut cut = Cut::default();
        self.cut_into(eye, projection, pixel_threshold, &mut cut);
        cut
    }

    /// [`ClusterLod::cut`] into `cut`, whose buffers are cleared and reused:
    /// allocation-free once they have grown to the largest cut.
    pub fn cut_into(&self, eye: Vec3, projection: Projection, pixel_threshold: f32, cut: &mut Cut) {
        cut.clusters.clear();
        cut.triangles.clear();
        cut.accepted.clear();
        cut.accepted.extend(self.groups.iter().map(|g| {
            g.simplified
                .projects_within(eye, projection, pixel_threshold)
        }));
        for (i, c) in self.clusters.iter().enumerate() {
            let fine_enough = c.refined.is_none_or(|r| cut.accepted[r as usize]);
            if fine_enough && !cut.accepted[c.group as usize] {
                cut.clusters.push(i as u32);
                cut.triangles.extend_from_slice(self.cluster_triangles(i));
            }
        }
    }

    /// Checks the invariants listed on [`ClusterLod`].
    ///
    /// # Errors
    /// [`Invalid`] naming the first offending group or cluster.
    pub fn validate(&self) -> std::result::Result<(), Invalid> {
        const S: &str = "ClusterLod";
        let mut next_cluster = 0u32;
        let mut depth = 0u32;
        let mut produced = vec![false; self.groups.len()];
        for (g, group) in self.groups.iter().enumerate() {
            ensure!(
                S,
                group.depth >= depth,
                "group {g}: depth {} after {depth}",
                group.depth
            );
            depth = group.depth;
            ensure!(
                S,
                group.clusters.start == next_cluster && group.clusters.end > group.clusters.start,
                "group {g}: clusters {:?}, expected to start at {next_cluster}",
                group.clusters
            );
            next_cluster = group.clusters.end;
            let e = group.simplified.error;
            ensure!(S, !e.is_nan() && e >= 0.0, "group {g}: error {e}");
            for c in group.clusters.clone() {
                let Some(cluster) = self.clusters.get(c as usize) else {
                    return Err(Invalid {
                        structure: S,
                        message: format!("group {g}: cluster {c} past the end"),
                    });
                };
                ensure!(
                    S,
                    cluster.group as usize == g,
                    "cluster {c}: group {} in group {g}",
                    cluster.group
                );
                if let Some(r) = cluster.refined {
                    let Some(from) = self.groups.get(r as usize).filter(|_| (r as usize) < g)
                    else {
                        return Err(Invalid {
                            structure: S,
                            message: format!("cluster {c} of group {g}: produced by group {r}"),
                        });
                    };
                    ensure!(
                        S,
                        from.depth < group.depth,
                        "cluster {c}: depth {} from {}",
                        group.depth,
                        from.depth
                    );
                    ensure!(
                        S,
                        !from.simplified.is_terminal(),
                        "cluster {c}: produced by terminal group {r}"
                    );
                    ensure!(
                        S,
                        !e.is_nan() && from.simplified.error <= e,
                        "group {g}: error {e} below its child group {r}'s {}",
                        from.simplified.error
                    );
                    produced[r as usize] = true;
                }
                let t = &cluster.triangles;
                let count = t.end.saturating_sub(t.start) as usize;
                ensure!(
                    S,
                    t.start < t.end
                        && t.end as usize <= self.triangles.len()
                        && count <= MAX_TRIANGLES,
                    "cluster {c}: triangles {t:?} of {}",
                    self.triangles.len()
                );
                ensure!(
                    S,
                    !cluster.bounds.error.is_nan() && cluster.bounds.error >= 0.0,
                    "cluster {c}: error {}",
                    cluster.bounds.error
                );
            }
        }
        ensure!(
            S,
            next_cluster as usize == self.clusters.len(),
            "{} clusters, groups hold {next_cluster}",
            self.clusters.len()
        );
        let covered = self.clusters.last().map_or(0, |c| c.triangles.end as usize);
        ensure!(
            S,
            covered == self.triangles.len(),
            "clusters hold {covered} of {} triangles",
            self.triangles.len()
        );
        for (g, group) in self.groups.iter().enumerate() {
            ensure!(
                S,
                group.simplified.is_terminal() || produced[g],
                "group {g}: not terminal, but no cluster was produced by it"
            );
        }
        let n = self.positions.len();
        if let Some(i) = self
            .triangles
            .iter()
            .flatten()
            .position(|&v| v as usize >= n)
        {
            return Err(Invalid {
                structure: S,
                message: format!("triangle {}: an index past the {n} vertices", i / 3),
            });
        }
        Ok(())
    }
}

/// The checks that keep meshoptimizer's C++ inside its preconditions.
fn check(mesh: &Mesh) -> Result<()> {
    let n = mesh.positions.len();
    if u32::try_from(n).is_err() || u32::try_from(mesh.triangles.len() * 3).is_err() {
        return Err(invalid_mesh(format!(
            "{n} vertices and {} triangles: more than u32 indices",
            mesh.triangles.len()
        )));
    }
    if let Some(v) = mesh.positions.iter().position(|p| !p.is_finite()) {
        return Err(invalid_mesh(format!(
            "vertex {v} has a non-finite coordinate"
        )));
    }
    if let Some((t, v)) = mesh
        .triangles
        .iter()
        .enumerate()
        .find_map(|(t, tri)| tri.iter().find(|&&v| v as usize >= n).map(|&v| (t, v)))
    {
        return Err(invalid_mesh(format!(
            "triangle {t} names vertex {v} of {n}"
        )));
    }
    let p = &mesh.properties;
    p.check_counts(n).map_err(invalid_mesh)?;
    let finite_normals = p
        .normals
        .as_ref()
        .is_none_or(|s| s.iter().all(|x| x.is_finite()));
    let finite_uvs = p
        .uvs
        .as_ref()
        .is_none_or(|s| s.iter().all(|x| x.is_finite()));
    if !(finite_normals && finite_uvs) {
        return Err(invalid_mesh(
            "a normal or texture coordinate is not finite".into(),
        ));
    }
    Ok(())
}

fn invalid_mesh(message: String) -> Error {
    Error::InvalidMesh {
        source_name: "meshoptimizer's cluster LoD".into(),
        message,
    }
}

fn bounds_of(b: meshopt::ClodBounds) -> Bounds {
    Bounds {
        centre: Vec3::from_array(b.center),
        radius: b.radius,
        error: b.error,
    }
}

/// The vertex attributes meshoptimizer's demo gives `clodBuild`: the
/// normals, weighted, then the texture coordinates, unweighted but
/// protected (a vertex whose position another vertex shares with other
/// texture coordinates is a seam that permissive simplification keeps).
struct AttributeStream {
    values: Vec<f32>,
    stride_floats: usize,
    weights: Vec<f32>,
    protect_mask: u32,
}

impl AttributeStream {
    fn of(mesh: &Mesh) -> AttributeStream {
        let p = &mesh.properties;
        let normals = p.normals.as_deref();
        let uvs = p.uvs.as_deref();
        let weights = if normals.is_some() {
            vec![NORMAL_WEIGHT; 3]
        } else {
            Vec::new()
        };
        let stride_floats = weights.len() + if uvs.is_some() { 2 } else { 0 };
        let protect_mask = if uvs.is_some() {
            0b11 << weights.len()
        } else {
            0
        };
        let mut values = Vec::with_capacity(stride_floats * mesh.vertex_count());
        if stride_floats > 0 {
            for v in 0..mesh.vertex_count() {
                if let Some(n) = normals {
                    values.extend(n[v].to_array());
                }
                if let Some(uv) = uvs {
                    values.extend(uv[v].to_array());
                }
            }
        }
        AttributeStream {
            values,
            stride_floats,
            weights,
            protect_mask,
        }
    }
}
