//! Chooses what a camera draws of a [`Hierarchy`]: a cut of the DAG, after
//! Karis's Nanite rule as meshoptimizer's cluster LoD applies it, made
//! continuous: the groups on the cut draw their models at the coarsest LoD
//! within the pixel threshold (the core's [`lod_for_screen_error`] rule at
//! the group's nearest point).
//!
//! **The rule.** A group is *coarse* when its output error, projected at
//! its sphere's nearest point, is within the threshold and its children are
//! coarse (errors grow and spheres hold their children's, so the second
//! condition only guards rounding). A group is *open* when it is not coarse
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
//! uses) is locked in its sequence, so no border point is removed or
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
use crate::screen_error::{lod_for_screen_error, nearest_distance, Projection};
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
            out.extend_from_slice(h.cluster_triangles(c as usize));
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
            .map(|&c| h.cluster_triangles(c as usize).len())
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
/// Cost: O(groups + their input clusters); allocates the cut and a flag
/// and a scale per group.
#[must_use]
pub fn select(h: &Hierarchy, projection: &Projection, eye: Vec3, pixel_threshold: f32) -> Cut {
    let sane = pixel_threshold.is_finite() && pixel_threshold > 0.0;
    let n = h.groups.len();
    let mut coarse = vec![false; n];
    let mut scale = vec![0f32; n];
    for (i, g) in h.groups.iter().enumerate() {
        let ppu = projection.pixels_per_unit(nearest_distance(eye, g.centre, g.radius));
        scale[i] = ppu;
        let error = g.output_error();
        let fits = sane
            && !ppu.is_nan()
            && (error == 0.0 || f64::from(error) * f64::from(ppu) <= f64::from(pixel_threshold));
        // Children come first: their flags are final.
        coarse[i] = fits && g.children.iter().all(|&c| coarse[c as usize]);
    }
    let mut cut = Cut::default();
    for (i, g) in h.groups.iter().enumerate() {
        let root = g
            .outputs
            .first()
            .is_none_or(|&c| h.clusters[c as usize].consumer == NO_GROUP);
        if coarse[i] && !root {
            continue;
        }
        if g.children.iter().all(|&c| coarse[c as usize]) {
            let lod = if coarse[i] {
                g.model.max_lod()
            } else if !sane || f64::from(g.floor) * f64::from(scale[i]) > f64::from(pixel_threshold)
            {
                0
            } else {
                lod_for_screen_error(
                    g.model.collapses(),
                    g.diagonal,
                    1.0,
                    scale[i],
                    pixel_threshold,
                )
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
