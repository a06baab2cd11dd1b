//! Chooses what a camera draws of a [`Hierarchy`]: a cut of the DAG, after
//! Karis's Nanite rule as meshoptimizer's cluster LoD applies it, made
//! continuous: the groups on the cut draw their models at the coarsest LoD
//! within the pixel threshold (the core's [`lod_for_screen_error`] rule at
//! the group's nearest point).
//!
//! **The rule.** A group is *coarse* when its output error, projected at
//! its sphere's nearest point, is within the threshold and its children are
//! coarse (errors grow and spheres hold their children's, so the second
//! condition only guards rounding; [`select_into`] finds the same cut
//! top-down, visiting only the open groups and their children, see
//! [`Selection`]). A group is *open* when it is not coarse
//! or is a root (no group consumes its output). An open group whose
//! children are all coarse draws its model at LoD `k`, the coarsest within
//! the threshold (its last when it is a coarse root); an open group with a
//! child that is not coarse draws, as they are, those of its input clusters
//! whose producer is coarse (level-0 groups have no child, so they always
//! draw their model when open).
//!
//! **Why it has no crack.** Start from the input, cut into level-0
//! clusters, and apply to it, children before parents, one replacement per
//! group: a coarse group replaces its input clusters by its output
//! clusters; an open group whose children are all coarse replaces them by
//! its model's LoD `k`; any other group replaces nothing. Each replacement
//! finds its inputs drawn (they are the outputs of coarse children, placed
//! by their replacements and consumed by no other group, or input
//! clusters), and what it leaves is exactly what the cut draws. Each
//! replacement keeps the boundary of the region it replaces: a group's
//! outer border (every point that a triangle of another group of its level
//! uses) is locked in its sequence, and so is every boundary point whose
//! fan is not a consistently oriented half-disc (`build.rs`,
//! `loose_border_points`: an unlocked vertex with boundary edges slides
//! along them, one without moves none), so no border point is removed or
//! moved, and a contraction of an unlocked vertex `u` into a neighbour
//! turns the fan around `u` into a fan around the neighbour over the same
//! link, which keeps every edge of that link (the border edges among
//! them). So as multisets of directed edges without their reverses, the
//! drawn set's boundary is the input's, except where a group simplified
//! the input's own boundary, between unlocked points of it: on a closed
//! input every drawn edge has its reverse drawn exactly once. Seams ride
//! along: the border is locked by point, and a point's vertices move
//! together. `tests/hierarchy.rs` checks the statement on sweeps of
//! cameras.

use super::{Hierarchy, NO_GROUP};
use crate::screen_error::{lod_for_screen_error, Projection};
use glam::Vec3;

/// What one camera draws of a [`Hierarchy`], from [`select`].
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Cut {
    /// Groups drawn through their models: `(group, lod)`, ascending by
    /// group.
    pub groups: Vec<(u32, u32)>,
    /// Clusters drawn as they are (inputs of an open group whose other
    /// inputs are refined), ascending.
    pub clusters: Vec<u32>,
}

impl Cut {
    /// The drawn triangles in input vertex numbers: each group's replay at
    /// its LoD, then the clusters' triangles. O(drawn groups' submeshes);
    /// the oracle of the tests, not a renderer's path.
    #[must_use]
    pub fn triangles(&self, h: &Hierarchy) -> Vec<[u32; 3]> {
        let mut out = Vec::new();
        for &(g, lod) in &self.groups {
            out.extend(h.groups[g as usize].triangles_at(lod as usize));
        }
        for &c in &self.clusters {
            out.extend(h.cluster_triangles(c as usize));
        }
        out
    }

    /// How many triangles the cut draws, from the groups' LoD tables. O(cut).
    #[must_use]
    pub fn triangle_count(&self, h: &Hierarchy) -> usize {
        let groups: usize = self
            .groups
            .iter()
            .map(|&(g, lod)| h.groups[g as usize].model.triangle_count(lod as usize))
            .sum();
        let clusters: usize = self
            .clusters
            .iter()
            .map(|&c| h.cluster_triangle_count(c as usize))
            .sum();
        groups + clusters
    }
}

/// The cut of `h` seen from `eye` (model coordinates, no transform) through
/// `projection`, with at most `pixel_threshold` pixels of projected error
/// (see the module documentation for the rule and why it has no crack).
/// A threshold that is not a finite number above 0 draws full detail, as
/// [`lod_for_screen_error`] does.
///
/// Cost: as [`select_into`], plus the allocation of the cut and of the
/// selection table (O(groups)); [`select_into`] reuses them.
#[must_use]
pub fn select(h: &Hierarchy, projection: &Projection, eye: Vec3, pixel_threshold: f32) -> Cut {
    let mut scratch = Selection::default();
    let mut cut = Cut::default();
    select_into(h, projection, eye, pixel_threshold, &mut scratch, &mut cut);
    cut
}

/// What [`select_into`] keeps between calls: a compact table of the
/// groups (their spheres, output errors, children and inputs in flat
/// arrays, so that a selection touches a few cache lines per group, not a
/// [`super::Group`] and its model), and the traversal's working arrays.
///
/// **Decision: spheres are re-centred in `f64` and grown so that a parent
/// holds its children with a margin.** The traversal is top-down and stops
/// at the first coarse group, which is sound only if a group within the
/// threshold has every descendant within it too. Errors are monotone up
/// the DAG by construction (a group's floor is its children's largest
/// output error); distances are monotone only if a parent's sphere holds
/// its children's, which the build guarantees within `f32` rounding. Here
/// each radius is raised, children first, to `|c - c'| + r' ` of every
/// child plus a relative `1e-9` margin, and distances are computed in `f64`: the
/// parent is then never farther than its child for any eye within `1e6`
/// radii, and the projected error test is monotone down the DAG.
#[derive(Debug, Clone, Default)]
pub struct Selection {
    /// `(groups, clusters)` of the hierarchy the table was made for.
    made_for: Option<(usize, usize)>,
    centre: Vec<[f64; 3]>,
    radius: Vec<f64>,
    output_error: Vec<f64>,
    floor: Vec<f64>,
    /// `children[children_start[g]..children_start[g + 1]]`.
    children_start: Vec<u32>,
    children: Vec<u32>,
    /// Input clusters and their producers, `inputs_start` as above.
    inputs_start: Vec<u32>,
    input_cluster: Vec<u32>,
    input_producer: Vec<u32>,
    /// Groups no group consumes the output of.
    roots: Vec<u32>,
    /// Per group, the selection that last visited it.
    visited: Vec<u32>,
    stamp: u32,
    stack: Vec<u32>,
}

impl Selection {
    fn make(&mut self, h: &Hierarchy) {
        let n = h.groups.len();
        *self = Selection::default();
        self.children_start.push(0);
        self.inputs_start.push(0);
        for (i, g) in h.groups.iter().enumerate() {
            let c = g.centre.as_dvec3();
            let mut r = f64::from(g.radius);
            for &child in &g.children {
                let child = child as usize;
                let cc = self.centre[child];
                let d =
                    ((cc[0] - c.x).powi(2) + (cc[1] - c.y).powi(2) + (cc[2] - c.z).powi(2)).sqrt();
                r = r.max(d + self.radius[child]);
            }
            self.centre.push(c.to_array());
            self.radius.push(r * (1.0 + 1e-9) + f64::MIN_POSITIVE);
            self.output_error.push(f64::from(g.output_error()));
            self.floor.push(f64::from(g.floor));
            self.children.extend_from_slice(&g.children);
            self.children_start.push(self.children.len() as u32);
            for &c in &g.inputs {
                self.input_cluster.push(c);
                self.input_producer.push(h.clusters[c as usize].producer);
            }
            self.inputs_start.push(self.input_cluster.len() as u32);
            let root = g
                .outputs
                .first()
                .is_none_or(|&c| h.clusters[c as usize].consumer == NO_GROUP);
            if root {
                self.roots.push(i as u32);
            }
        }
        self.visited = vec![0; n];
        self.made_for = Some((n, h.clusters.len()));
    }

    /// Pixels per model unit at group `g`'s nearest point.
    fn scale(&self, g: usize, projection: &Projection, eye: [f64; 3]) -> f32 {
        let c = self.centre[g];
        let d =
            ((eye[0] - c[0]).powi(2) + (eye[1] - c[1]).powi(2) + (eye[2] - c[2]).powi(2)).sqrt();
        projection.pixels_per_unit((d - self.radius[g]).max(0.0) as f32)
    }

    /// Whether group `g`'s output projects within `threshold` (see
    /// [`Selection`] for why this is monotone down the DAG).
    fn fits(
        &self,
        g: usize,
        projection: &Projection,
        eye: [f64; 3],
        threshold: Option<f64>,
    ) -> bool {
        let Some(threshold) = threshold else {
            return false;
        };
        let ppu = self.scale(g, projection, eye);
        let error = self.output_error[g];
        !ppu.is_nan() && (error == 0.0 || error * f64::from(ppu) <= threshold)
    }
}

/// [`select`] into `cut` (cleared first), with `scratch`'s table and
/// arrays: after the first call for `h` it allocates nothing once the
/// vectors have grown.
///
/// Cost: O(open groups and their children and input clusters): the
/// traversal starts at the roots and stops at coarse groups, so a cut of a
/// few hundred groups costs the same for a hierarchy of thousands or
/// millions. The first call for a hierarchy builds the table, O(groups).
pub fn select_into(
    h: &Hierarchy,
    projection: &Projection,
    eye: Vec3,
    pixel_threshold: f32,
    scratch: &mut Selection,
    cut: &mut Cut,
) {
    if scratch.made_for != Some((h.groups.len(), h.clusters.len())) {
        scratch.make(h);
    }
    let s = scratch;
    let threshold = (pixel_threshold.is_finite() && pixel_threshold > 0.0)
        .then_some(f64::from(pixel_threshold));
    let eye = eye.as_dvec3().to_array();
    cut.groups.clear();
    cut.clusters.clear();
    s.stamp = s.stamp.wrapping_add(1);
    if s.stamp == 0 {
        s.visited.fill(0);
        s.stamp = 1;
    }
    let mut stack = std::mem::take(&mut s.stack);
    stack.clear();
    stack.extend_from_slice(&s.roots);
    while let Some(g) = stack.pop() {
        let gi = g as usize;
        if s.visited[gi] == s.stamp {
            continue;
        }
        s.visited[gi] = s.stamp;
        // `g` is open (not coarse, or a root): its children decide.
        let (a, b) = (
            s.children_start[gi] as usize,
            s.children_start[gi + 1] as usize,
        );
        let mut all_coarse = true;
        for &c in &s.children[a..b] {
            if !s.fits(c as usize, projection, eye, threshold) {
                all_coarse = false;
                stack.push(c);
            }
        }
        if all_coarse {
            let group = &h.groups[gi];
            let lod = if s.fits(gi, projection, eye, threshold) {
                // A coarse root.
                group.model.max_lod()
            } else {
                let scale = s.scale(gi, projection, eye);
                match threshold {
                    Some(t) if s.floor[gi] * f64::from(scale) <= t => lod_for_screen_error(
                        group.model.collapses(),
                        group.diagonal,
                        1.0,
                        scale,
                        pixel_threshold,
                    ),
                    _ => 0,
                }
            };
            cut.groups.push((g, lod as u32));
        } else {
            let (a, b) = (s.inputs_start[gi] as usize, s.inputs_start[gi + 1] as usize);
            for i in a..b {
                let producer = s.input_producer[i];
                if producer != NO_GROUP && s.fits(producer as usize, projection, eye, threshold) {
                    cut.clusters.push(s.input_cluster[i]);
                }
            }
        }
    }
    s.stack = stack;
    cut.groups.sort_unstable();
    cut.clusters.sort_unstable();
}

/// The same cut as [`select`], computed the long way: every group's
/// coarseness bottom-up (coarse when its output fits and all its children
/// are coarse), then the rule. O(groups); the oracle the traversal of
/// [`select_into`] is tested against.
#[must_use]
pub fn select_exhaustive(
    h: &Hierarchy,
    projection: &Projection,
    eye: Vec3,
    pixel_threshold: f32,
) -> Cut {
    let mut s = Selection::default();
    s.make(h);
    let threshold = (pixel_threshold.is_finite() && pixel_threshold > 0.0)
        .then_some(f64::from(pixel_threshold));
    let eye64 = eye.as_dvec3().to_array();
    let n = h.groups.len();
    let mut coarse = vec![false; n];
    for (i, g) in h.groups.iter().enumerate() {
        coarse[i] = s.fits(i, projection, eye64, threshold)
            && g.children.iter().all(|&c| coarse[c as usize]);
    }
    let mut cut = Cut::default();
    for (i, g) in h.groups.iter().enumerate() {
        let root = s.roots.binary_search(&(i as u32)).is_ok();
        if coarse[i] && !root {
            continue;
        }
        if g.children.iter().all(|&c| coarse[c as usize]) {
            let scale = s.scale(i, projection, eye64);
            let lod = if coarse[i] {
                g.model.max_lod()
            } else {
                match threshold {
                    Some(t) if s.floor[i] * f64::from(scale) <= t => lod_for_screen_error(
                        g.model.collapses(),
                        g.diagonal,
                        1.0,
                        scale,
                        pixel_threshold,
                    ),
                    _ => 0,
                }
            };
            cut.groups.push((i as u32, lod as u32));
        } else {
            for &c in &g.inputs {
                let producer = h.clusters[c as usize].producer;
                if producer != NO_GROUP && coarse[producer as usize] {
                    cut.clusters.push(c);
                }
            }
        }
    }
    cut.clusters.sort_unstable();
    cut
}
