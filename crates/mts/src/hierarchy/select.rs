//! Chooses what a camera draws of a [`Hierarchy`]: a cut of the DAG, after
//! Karis's Nanite rule as meshoptimizer's cluster LoD applies it, made
//! continuous: the groups on the cut draw their models at the coarsest LoD
//! within the pixel threshold (the core's [`lod_for_screen_error`](crate::lod_for_screen_error) rule at
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
use crate::screen_error::{coarsest_within, relative_error_limit, Projection};
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
/// [`lod_for_screen_error`](crate::lod_for_screen_error) does.
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
    /// Per group: its grown sphere and output error, in one cache line's
    /// reach (the traversal reads little else).
    spheres: Vec<Sphere>,
    /// `children[children_start[g]..children_start[g + 1]]`, with each
    /// child's sphere beside it in `child_spheres` (a copy: a visit reads
    /// its children's spheres in a row, not from all over `spheres`).
    children_start: Vec<u32>,
    children: Vec<u32>,
    child_spheres: Vec<Sphere>,
    /// Input clusters and their producers (and producers' spheres, as
    /// above), `inputs_start` as above.
    inputs_start: Vec<u32>,
    input_cluster: Vec<u32>,
    input_producer: Vec<u32>,
    producer_spheres: Vec<Sphere>,
    /// Groups no group consumes the output of.
    roots: Vec<u32>,
    /// Per group, the selection that last visited it.
    visited: Vec<u32>,
    /// Per group, its last LoD from [`lod_for_screen_error`](crate::lod_for_screen_error)'s rule and the
    /// relative-error limits it holds for (`lo <= limit < hi`), so that a
    /// camera that moved a little finds most LoDs without reading the
    /// group's error table.
    lods: Vec<LodMemo>,
    stamp: u32,
    stack: Vec<u32>,
}

/// See [`Selection::lods`]; with the group's diagonal and floor, so that
/// a memo that holds reads nothing else.
#[derive(Debug, Clone, Copy)]
struct LodMemo {
    lod: u32,
    diagonal: f32,
    floor: f64,
    lo: f64,
    hi: f64,
}

impl LodMemo {
    /// Holds for no limit.
    fn new(diagonal: f32, floor: f64) -> LodMemo {
        LodMemo {
            lod: 0,
            diagonal,
            floor,
            lo: f64::INFINITY,
            hi: f64::NEG_INFINITY,
        }
    }
}

/// A group's sphere (grown, see [`Selection`]) and output error.
#[derive(Debug, Clone, Copy, Default)]
struct Sphere {
    centre: [f64; 3],
    radius: f64,
    error: f64,
}

/// The projected-error test of one selection, with what does not depend
/// on the group worked out once: a perspective camera's error `e` at
/// distance `d - r` projects to `e × k / (d - r)` pixels (`k` the pixels
/// per unit at distance 1), within `t` exactly when `d ≥ r + e × k / t`,
/// which needs no square root, tangent or division per group (compared
/// squared). The same inequality as [`Projection::pixels_per_unit`] and
/// [`lod_for_screen_error`](crate::lod_for_screen_error) evaluate, rearranged; rounding may move a
/// group lying on the threshold to either side, and [`select_exhaustive`]
/// uses the same test.
#[derive(Debug, Clone, Copy)]
enum Fit {
    /// No threshold: nothing is coarse (full detail).
    Never,
    /// A degenerate projection (0 pixels per unit): everything fits.
    Always,
    /// Fits when the distance from `eye` is at least `r + e × per_error`.
    Perspective { eye: [f64; 3], per_error: f64 },
    /// Fits when the error is at most `max_error`.
    Orthographic { max_error: f64 },
}

impl Fit {
    fn new(projection: &Projection, eye: Vec3, pixel_threshold: f32) -> Fit {
        if !(pixel_threshold.is_finite() && pixel_threshold > 0.0) {
            return Fit::Never;
        }
        let t = f64::from(pixel_threshold);
        // Pixels per unit at distance 1: `k` for a perspective camera,
        // the constant for an orthographic one; 0 when degenerate.
        let k = f64::from(projection.pixels_per_unit(1.0));
        if k.is_nan() {
            return Fit::Never;
        }
        if k == 0.0 {
            return Fit::Always;
        }
        match projection {
            Projection::Perspective { .. } => Fit::Perspective {
                eye: eye.as_dvec3().to_array(),
                per_error: k / t,
            },
            Projection::Orthographic { .. } => Fit::Orthographic { max_error: t / k },
        }
    }

    /// Whether a group's output projects within the threshold (see
    /// [`Selection`] for why this is monotone down the DAG).
    #[inline]
    fn fits(self, s: &Sphere) -> bool {
        if s.error == 0.0 {
            return !matches!(self, Fit::Never);
        }
        match self {
            Fit::Never => false,
            Fit::Always => true,
            Fit::Perspective { eye, per_error } => {
                let c = s.centre;
                let d2 =
                    (eye[0] - c[0]).powi(2) + (eye[1] - c[1]).powi(2) + (eye[2] - c[2]).powi(2);
                let need = s.radius + s.error * per_error;
                d2 >= need * need
            }
            Fit::Orthographic { max_error } => s.error <= max_error,
        }
    }
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
                let child = &self.spheres[child as usize];
                let cc = child.centre;
                let d =
                    ((cc[0] - c.x).powi(2) + (cc[1] - c.y).powi(2) + (cc[2] - c.z).powi(2)).sqrt();
                r = r.max(d + child.radius);
            }
            self.spheres.push(Sphere {
                centre: c.to_array(),
                radius: r * (1.0 + 1e-9) + f64::MIN_POSITIVE,
                error: f64::from(g.output_error()),
            });
            self.lods.push(LodMemo::new(g.diagonal, f64::from(g.floor)));
            self.children.extend_from_slice(&g.children);
            for &child in &g.children {
                self.child_spheres.push(self.spheres[child as usize]);
            }
            self.children_start.push(self.children.len() as u32);
            for &c in &g.inputs {
                let producer = h.clusters[c as usize].producer;
                self.input_cluster.push(c);
                self.input_producer.push(producer);
                // A producer comes before its consumer (a level below).
                self.producer_spheres.push(
                    self.spheres
                        .get(producer as usize)
                        .copied()
                        .unwrap_or_default(),
                );
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
    fn scale(&self, g: usize, projection: &Projection, eye: Vec3) -> f32 {
        let c = self.spheres[g].centre;
        let eye = eye.as_dvec3();
        let d = ((eye.x - c[0]).powi(2) + (eye.y - c[1]).powi(2) + (eye.z - c[2]).powi(2)).sqrt();
        projection.pixels_per_unit((d - self.spheres[g].radius).max(0.0) as f32)
    }

    /// The LoD an open group whose children are all coarse draws: its last
    /// when it fits itself (a coarse root), else the coarsest within the
    /// threshold at its nearest point, LoD 0 when even its floor (the
    /// error its inputs carry) does not fit there.
    fn lod_of(
        &mut self,
        h: &Hierarchy,
        g: usize,
        fit: Fit,
        projection: &Projection,
        eye: Vec3,
        pixel_threshold: f32,
    ) -> usize {
        if fit.fits(&self.spheres[g]) {
            return h.groups[g].model.max_lod();
        }
        if matches!(fit, Fit::Never) {
            return 0;
        }
        let scale = self.scale(g, projection, eye);
        let memo = self.lods[g];
        if memo.floor * f64::from(scale) > f64::from(pixel_threshold) {
            return 0;
        }
        // `lod_for_screen_error(collapses, diagonal, 1, scale, threshold)`,
        // remembered by the limit it answered for.
        let Some(limit) = relative_error_limit(memo.diagonal, 1.0, scale, pixel_threshold) else {
            return 0;
        };
        if memo.lo <= limit && limit < memo.hi {
            return memo.lod as usize;
        }
        let collapses = h.groups[g].model.collapses();
        let lod = coarsest_within(collapses, limit);
        let hi = if lod < collapses.max_lod() {
            f64::from(collapses.error(lod + 1))
        } else {
            f64::INFINITY
        };
        self.lods[g] = LodMemo {
            lod: lod as u32,
            lo: f64::from(collapses.error(lod)),
            hi,
            ..memo
        };
        lod
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
    let fit = Fit::new(projection, eye, pixel_threshold);
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
        for (&c, sphere) in s.children[a..b].iter().zip(&s.child_spheres[a..b]) {
            if !fit.fits(sphere) {
                all_coarse = false;
                stack.push(c);
            }
        }
        if all_coarse {
            let lod = s.lod_of(h, gi, fit, projection, eye, pixel_threshold);
            cut.groups.push((g, lod as u32));
        } else {
            let (a, b) = (s.inputs_start[gi] as usize, s.inputs_start[gi + 1] as usize);
            for i in a..b {
                if s.input_producer[i] != NO_GROUP && fit.fits(&s.producer_spheres[i]) {
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
    let fit = Fit::new(projection, eye, pixel_threshold);
    let n = h.groups.len();
    let mut coarse = vec![false; n];
    for (i, g) in h.groups.iter().enumerate() {
        coarse[i] = fit.fits(&s.spheres[i]) && g.children.iter().all(|&c| coarse[c as usize]);
    }
    let mut cut = Cut::default();
    for (i, g) in h.groups.iter().enumerate() {
        let root = s.roots.binary_search(&(i as u32)).is_ok();
        if coarse[i] && !root {
            continue;
        }
        if g.children.iter().all(|&c| coarse[c as usize]) {
            let lod = s.lod_of(h, i, fit, projection, eye, pixel_threshold);
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
