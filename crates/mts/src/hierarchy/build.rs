//! Builds the DAG level by level (after meshoptimizer's `clodBuild`): cut
//! the level's triangles into clusters, group them, simplify each group
//! toward half with its outer border locked, record its strips as an
//! [`MtsModel`], cut its output into the next level's clusters.

use super::grouping::group;
use super::partition::partition;
use super::{Cluster, Group, Hierarchy, HierarchyOptions, NO_GROUP, STUCK_RATIO};
use crate::mesh::Mesh;
use crate::model::MtsModel;
use crate::simplify::{simplify_locked, Placement};
use crate::strip::stripify;
use glam::Vec3;

/// Builds the hierarchy of `mesh` (see the module documentation of
/// [`super`]): groups of each level built in parallel on all cores.
///
/// Cost: about that of [`crate::model::build_from_mesh`] over twice the
/// triangles (each level about half the one below), in pieces of about
/// `group_clusters × cluster_triangles` triangles; memory about twice the
/// per-object model's.
///
/// # Errors
/// [`crate::Error::InvalidArgument`] for optimal placement: its created
/// vertices are not input vertices, which the groups' vertex maps and the
/// locked borders need.
///
/// # Panics
/// If `mesh` breaks the [`Mesh`] invariants.
pub fn build(mesh: &Mesh, options: &HierarchyOptions) -> crate::Result<Hierarchy> {
    build_with_progress(mesh, options, &|_| {})
}

/// How far [`build_with_progress`] is: the triangles of the groups built
/// so far, over all levels, against about twice the input's (each level
/// about half the one below; the count may end a little above or below).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct BuildProgress {
    /// The level being built (0: the input's clusters).
    pub level: u32,
    /// Input triangles of the groups built so far, every level counted.
    pub triangles_done: usize,
    /// Twice the input's triangles: what `triangles_done` approaches.
    pub triangles_expected: usize,
}

/// [`build`], calling `progress` (from any thread, in no particular
/// order) after each group is built.
///
/// # Errors
/// As [`build`].
pub fn build_with_progress(
    mesh: &Mesh,
    options: &HierarchyOptions,
    progress: &(dyn Fn(BuildProgress) + Sync),
) -> crate::Result<Hierarchy> {
    if options.pipeline.simplify.placement != Placement::Endpoint {
        return Err(crate::Error::InvalidArgument(
            "the hierarchy needs endpoint placement: its groups draw input vertices".into(),
        ));
    }
    let point_of = |v: u32| mesh.properties.position_id(v);
    let points = (0..mesh.vertex_count() as u32)
        .map(|v| point_of(v) as usize + 1)
        .max()
        .unwrap_or(0);
    let mut h = Hierarchy {
        clusters: Vec::new(),
        groups: Vec::new(),
        positions: mesh.positions.clone(),
        properties: mesh.properties.clone(),
        cluster_strips: Vec::new(),
        vertex_count: mesh.vertex_count(),
        triangle_count: mesh.triangle_count(),
    };
    let mut current: Vec<u32> = Vec::new();
    // Every cluster's triangles, while the levels are built; the hierarchy
    // keeps only their strips.
    let mut triangles: Vec<[u32; 3]> = Vec::new();
    for part in partition(&mesh.positions, &mesh.triangles, options.cluster_triangles) {
        let tris = part.iter().map(|&t| mesh.triangles[t as usize]);
        current.push(h.add_cluster(&mut triangles, tris, NO_GROUP));
    }
    let mut level = 0u32;
    let done = std::sync::atomic::AtomicUsize::new(0);
    while !current.is_empty() {
        let slices: Vec<&[[u32; 3]]> = current
            .iter()
            .map(|&c| {
                let r = &h.clusters[c as usize].triangles;
                &triangles[r.start as usize..r.end as usize]
            })
            .collect();
        let grouped = group(
            &mesh.positions,
            point_of,
            &slices,
            options.group_clusters.max(1),
        );
        // The outer borders: points that triangles of two groups use.
        let mut owner = vec![NO_GROUP; points];
        let mut shared = vec![false; points];
        for (gi, members) in grouped.iter().enumerate() {
            for &m in members {
                for t in slices[m as usize] {
                    for &v in t {
                        let p = point_of(v) as usize;
                        if owner[p] == NO_GROUP {
                            owner[p] = gi as u32;
                        } else if owner[p] != gi as u32 {
                            shared[p] = true;
                        }
                    }
                }
            }
        }
        let inputs: Vec<Vec<[u32; 3]>> = grouped
            .iter()
            .map(|members| {
                members
                    .iter()
                    .flat_map(|&m| slices[m as usize].iter().copied())
                    .collect()
            })
            .collect();
        let built = build_groups(mesh, &inputs, &shared, options, &|triangles| {
            let before = done.fetch_add(triangles, std::sync::atomic::Ordering::Relaxed);
            progress(BuildProgress {
                level,
                triangles_done: before + triangles,
                triangles_expected: 2 * mesh.triangle_count(),
            });
        });
        let (mut total_in, mut total_out) = (0usize, 0usize);
        let mut next = Vec::new();
        for (gi, b) in built.into_iter().enumerate() {
            let id = h.groups.len() as u32;
            let group_inputs: Vec<u32> = grouped[gi].iter().map(|&m| current[m as usize]).collect();
            let mut children: Vec<u32> = Vec::new();
            for &c in &group_inputs {
                let cluster = &mut h.clusters[c as usize];
                cluster.consumer = id;
                if cluster.producer != NO_GROUP {
                    children.push(cluster.producer);
                }
            }
            children.sort_unstable();
            children.dedup();
            let mut floor = 0f32;
            let mut radius = b.radius;
            for &c in &children {
                let child = &h.groups[c as usize];
                floor = floor.max(child.output_error());
                radius = radius.max(child.centre.distance(b.centre) + child.radius);
            }
            total_in += inputs[gi].len();
            total_out += b.output.len();
            let mut outputs = Vec::new();
            for part in partition(&mesh.positions, &b.output, options.cluster_triangles) {
                let tris = part.iter().map(|&t| b.output[t as usize]);
                outputs.push(h.add_cluster(&mut triangles, tris, id));
            }
            next.extend_from_slice(&outputs);
            h.groups.push(Group {
                level,
                inputs: group_inputs,
                outputs,
                children,
                vertices: b.vertices,
                model: b.model,
                floor,
                diagonal: b.diagonal,
                centre: b.centre,
                radius,
            });
        }
        let stuck = total_out as f64 > STUCK_RATIO * total_in as f64;
        if grouped.len() <= 1 || stuck {
            break;
        }
        current = next;
        level += 1;
    }
    super::strips::strip_clusters(&mut h, &triangles, &options.pipeline.stripify);
    #[cfg(debug_assertions)]
    if let Err(e) = h.validate() {
        panic!("hierarchy::build made an invalid hierarchy: {e}");
    }
    Ok(h)
}

impl Hierarchy {
    /// Appends a cluster of `triangles` made by `producer` (not yet
    /// consumed), its triangles to `all` (the build's list of every
    /// cluster's triangles), and returns its index.
    fn add_cluster(
        &mut self,
        all: &mut Vec<[u32; 3]>,
        triangles: impl Iterator<Item = [u32; 3]>,
        producer: u32,
    ) -> u32 {
        let start = all.len() as u32;
        all.extend(triangles);
        self.clusters.push(Cluster {
            triangles: start..all.len() as u32,
            producer,
            consumer: NO_GROUP,
            strip: 0..0,
        });
        (self.clusters.len() - 1) as u32
    }
}

/// What [`build_group`] makes of one group's input.
struct Built {
    vertices: Vec<u32>,
    model: MtsModel,
    diagonal: f32,
    /// Its last LoD's triangles, in input vertex numbers.
    output: Vec<[u32; 3]>,
    centre: Vec3,
    radius: f32,
}

/// [`build_group`] of every group, on all cores, in group order; `built`
/// is told each group's input triangles once it is built.
fn build_groups(
    mesh: &Mesh,
    inputs: &[Vec<[u32; 3]>],
    shared: &[bool],
    options: &HierarchyOptions,
    built: &(dyn Fn(usize) + Sync),
) -> Vec<Built> {
    crate::parallel::map_indexed(
        inputs.len(),
        || vec![u32::MAX; mesh.vertex_count()],
        |remap, i| {
            let b = build_group(mesh, &inputs[i], shared, options, remap);
            built(inputs[i].len());
            b
        },
    )
}

/// One group: its submesh (input vertices and properties, no texture: the
/// input's serves), simplified to half its triangles with the points in
/// `shared` locked, and its model. `remap` is all `u32::MAX` on entry and
/// on return.
fn build_group(
    mesh: &Mesh,
    triangles: &[[u32; 3]],
    shared: &[bool],
    options: &HierarchyOptions,
    remap: &mut [u32],
) -> Built {
    let (submesh, vertices) = mesh.submesh(triangles, remap);
    let loose = loose_border_points(&submesh);
    let locked: Vec<bool> = vertices
        .iter()
        .zip(0u32..)
        .map(|(&v, i)| {
            shared[mesh.properties.position_id(v) as usize]
                || loose[submesh.properties.position_id(i) as usize]
        })
        .collect();
    let mut simplify_options = options.pipeline.simplify;
    simplify_options.stop_at_triangles = Some(submesh.triangle_count() / 2);
    let collapses = simplify_locked(&submesh, &simplify_options, &locked).collapses;
    let strips = stripify(&submesh, &options.pipeline.stripify);
    let model = crate::model::build(&submesh, &strips, &collapses, &options.pipeline.build);
    let output = collapses
        .triangles_at(&submesh, collapses.max_lod())
        .into_iter()
        .map(|t| t.map(|v| vertices[v as usize]))
        .collect();
    let (lo, hi) = crate::mesh::bounds_of(&submesh.positions).unwrap_or_default();
    let centre = 0.5 * (lo + hi);
    let radius = submesh
        .positions
        .iter()
        .map(|p| p.distance(centre))
        .fold(0f32, f32::max);
    Built {
        vertices,
        model,
        diagonal: submesh.diagonal(),
        output,
        centre,
        radius,
    }
}

/// The points of `mesh` (by position id) that [`build_group`] locks besides
/// its outer border: every point on the *boundary* (some edge at it is held
/// by more triangles in one direction than in the other, the boundary that
/// `select.rs` keeps and `tests/hierarchy.rs` checks) whose fan is not a
/// single consistently oriented half-disc (exactly two edges of one
/// triangle, every other edge two triangles of opposite directions, in one
/// piece). Also every corner of a triangle with a repeated point.
///
/// Why: contracting `u` into `v` puts `v` in place of `u` in every triangle,
/// so `u`'s boundary edges become `v`'s. That is harmless when `v` is a
/// boundary point of the input too, and the simplifier sees to it only for
/// the borders it knows: a vertex on an edge of one triangle (or of four or
/// more) leaves only along such an edge. A half-disc's boundary edges are
/// edges of one triangle, so it slides along its border, and a point off
/// the boundary moves no boundary edge wherever it goes (a fold of a closed
/// part included): neither is locked, so a manifold input's hierarchy is
/// unchanged. But an edge of two triangles of the same direction (a flipped
/// triangle beside its neighbours, a doubled one on its sheet), or of
/// three, is a boundary edge that the simplifier counts as interior: a
/// vertex whose boundary is made of such edges goes anywhere, onto an
/// interior point, and that point is left with edges no triangle reverses,
/// a crack against the neighbouring group (which keeps the shared point).
/// The property test `random_surfaces_are_cut_without_cracks` found it; in
/// its smallest form (`a_flipped_triangle_is_cut_without_cracks`), one
/// flipped triangle in a hilly 4 × 4 grid: each of its corners has two
/// edges held twice in one direction, and level 0 contracted one corner
/// onto a locked interior point, leaving two open edges there. A fan in
/// several pieces (a bowtie, or a half-disc beside a closed pocket) is
/// locked as well: once the pocket collapsed, the simplifier moved such a
/// vertex along its stale pair onto the pocket's interior point.
///
/// This judges the group's input. A fan can change kind during the sequence
/// (a merge up to the input's most crowded edge can make a fin at a
/// half-disc); no group of 61,000 random surfaces (holes, flipped, doubled
/// and opposed triangles, fins) moved the boundary that way
/// (`docs/experiments/hierarchy.md`).
///
/// Cost: O(corners log corners).
fn loose_border_points(mesh: &Mesh) -> Vec<bool> {
    let point = |v: u32| mesh.properties.position_id(v);
    let points = (0..mesh.vertex_count() as u32)
        .map(|v| point(v) as usize + 1)
        .max()
        .unwrap_or(0);
    let mut loose = vec![false; points];
    // Corners by point: (point, the point after it, the point before it).
    let mut corners: Vec<(u32, u32, u32)> = Vec::with_capacity(3 * mesh.triangle_count());
    for t in &mesh.triangles {
        let p = t.map(point);
        if p[0] == p[1] || p[1] == p[2] || p[2] == p[0] {
            for q in p {
                loose[q as usize] = true;
            }
            continue;
        }
        for k in 0..3 {
            corners.push((p[k], p[(k + 1) % 3], p[(k + 2) % 3]));
        }
    }
    corners.sort_unstable();
    let (mut around, mut counts, mut parent) = (Vec::new(), Vec::new(), Vec::new());
    for fan in corners.chunk_by(|x, y| x.0 == y.0) {
        // The link: an edge (after, before) per triangle over the
        // neighbours; a half-disc's is one path, each neighbour at most once
        // after the point and once before it.
        around.clear();
        around.extend(fan.iter().flat_map(|&(_, a, b)| [a, b]));
        around.sort_unstable();
        around.dedup();
        counts.clear();
        counts.resize(around.len(), (0u32, 0u32));
        parent.clear();
        parent.extend(0..around.len());
        let index = |w: u32| around.binary_search(&w).unwrap_or(0);
        for &(_, a, b) in fan {
            let (i, j) = (index(a), index(b));
            counts[i].0 += 1;
            counts[j].1 += 1;
            let (ri, rj) = (root(&mut parent, i), root(&mut parent, j));
            parent[ri] = rj;
        }
        let on_boundary = counts.iter().any(|&(after, before)| after != before);
        let once = counts
            .iter()
            .all(|&(after, before)| after <= 1 && before <= 1);
        let pieces = (0..around.len())
            .filter(|&i| root(&mut parent, i) == i)
            .count();
        if on_boundary && !(once && pieces == 1) {
            loose[fan[0].0 as usize] = true;
        }
    }
    loose
}

/// The root of `i` in the union-find forest `parent`, halving the path.
fn root(parent: &mut [usize], mut i: usize) -> usize {
    while parent[i] != i {
        parent[i] = parent[parent[i]];
        i = parent[i];
    }
    i
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::Properties;

    fn loose(triangles: Vec<[u32; 3]>) -> Vec<u32> {
        let n = triangles.iter().flatten().max().map_or(0, |&m| m + 1);
        let mesh = Mesh {
            positions: vec![Vec3::ZERO; n as usize],
            triangles,
            properties: Properties::default(),
        };
        let flags = loose_border_points(&mesh);
        (0..n).filter(|&p| flags[p as usize]).collect()
    }

    #[test]
    fn only_boundary_points_without_a_half_disc_are_loose() {
        // A 2 × 2 grid: discs and half-discs.
        let grid = crate::mesh::generate::grid(2, 2).triangles;
        assert_eq!(loose(grid.clone()), Vec::<u32>::new());
        // One triangle flipped: its corners have edges held twice in one
        // direction; the other points are as they were.
        let mut flipped = grid;
        let t = flipped.iter().position(|t| t.contains(&4)).unwrap();
        let [a, b, c] = flipped[t];
        flipped[t] = [a, c, b];
        let mut corners = vec![a, b, c];
        corners.sort_unstable();
        assert_eq!(loose(flipped), corners);
        // A closed pocket (two opposed triangles) has no boundary; beside a
        // triangle its shared point's fan is in two pieces.
        assert_eq!(loose(vec![[0, 1, 2], [0, 2, 1]]), Vec::<u32>::new());
        assert_eq!(loose(vec![[0, 1, 2], [0, 2, 1], [0, 3, 4]]), [0]);
        // A fin: three triangles on edge (0, 1).
        assert_eq!(loose(vec![[0, 1, 2], [1, 0, 3], [0, 1, 4]]), [0, 1]);
    }
}
