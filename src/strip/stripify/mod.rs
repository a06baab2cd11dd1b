//! STRIPE-style hybrid stripification.
//!
//! After Evans, Skiena and Varshney, "Optimizing triangle strips for fast
//! rendering" (IEEE Visualization 1996), the search the MTS paper (section
//! 2.2) uses: a global pass finds large rectangular patches of
//! quadrilaterals and strips them along their rows ([`patches`]); a local
//! greedy pass strips what is left, starting from the triangle with fewest
//! free neighbours and avoiding swaps ([`greedy`]). Both build strips as
//! walks over triangles; [`path`] turns a walk into a vertex run.
//!
//! Strips only cross edges that [`TriangleAdjacency`] pairs (manifold and
//! consistently oriented), so boundaries, non-manifold edges and several
//! components need no special case, and every triangle keeps its winding.

mod greedy;
mod path;
mod patches;

use super::Strips;
use crate::mesh::{Mesh, TriangleAdjacency};
use greedy::Walk;

/// Tuning of [`stripify`]. The defaults were chosen by `mts strips` over
/// every model in `../shared/models` and the generated meshes (see the
/// field docs for what was measured).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StripifyOptions {
    /// Run the global quadrilateral-patch pass before the local pass.
    pub patches: bool,
    /// Smallest patch (in quadrilaterals) the global pass keeps; smaller
    /// ones are left to the local pass.
    pub min_patch_quads: usize,
    /// Costs of a swap, in "free neighbours", tried by the local pass when it
    /// picks the next triangle: score = free neighbours of the candidate +
    /// the penalty if it needs a swap; lowest wins. The local pass runs once
    /// per penalty from the same state and the run with fewest indices is
    /// kept. Below 1 means "fewest free neighbours first, swap as
    /// tie-break" (the rule of the STRIPE paper; best on 16 of the 20 shared
    /// models); above 1 avoids swaps unless the other side is two
    /// neighbours freer (best on `non_manif_hole.ply`: 1.221 against 1.314
    /// indices per triangle). Empty means `[0.5]`.
    pub swap_penalties: [Option<f32>; 2],
    /// Join strips whose end triangles are neighbours after both passes.
    pub join_ends: bool,
}

impl Default for StripifyOptions {
    fn default() -> StripifyOptions {
        StripifyOptions {
            patches: true,
            min_patch_quads: 512,
            swap_penalties: [Some(0.5), Some(1.5)],
            join_ends: true,
        }
    }
}

/// Cuts a mesh into generalized triangle strips.
///
/// The strips draw exactly the mesh's triangles, each once, with its
/// winding (see the module docs of [`crate::strip`] for the run encoding).
///
/// Cost: O(T) time and memory for T triangles (a constant number of passes
/// over the triangles; adjacency built without sorting).
#[must_use]
pub fn stripify(mesh: &Mesh, options: &StripifyOptions) -> Strips {
    let adjacency = TriangleAdjacency::new(mesh);
    stripify_with_adjacency(mesh, &adjacency, options)
}

/// [`stripify`] with an adjacency the caller already has.
#[must_use]
pub fn stripify_with_adjacency(
    mesh: &Mesh,
    adjacency: &TriangleAdjacency,
    options: &StripifyOptions,
) -> Strips {
    let mut walk = Walk::new(&mesh.triangles, &adjacency.neighbours);
    let mut patch_paths: Vec<Vec<u32>> = Vec::new();
    if options.patches {
        patches::strip_patches(&mut walk, &mesh.positions, options.min_patch_quads, &mut patch_paths);
    }
    let penalties: Vec<f32> = options.swap_penalties.iter().flatten().copied().collect();
    let penalties = if penalties.is_empty() { vec![0.5] } else { penalties };
    let mut best: Option<(Vec<u32>, Vec<u32>)> = None;
    for (i, &penalty) in penalties.iter().enumerate() {
        let mut paths = patch_paths.clone();
        if i + 1 < penalties.len() {
            let mut w = walk.clone();
            w.swap_penalty = penalty;
            greedy::strip_rest(&mut w, &mut paths);
        } else {
            walk.swap_penalty = penalty;
            greedy::strip_rest(&mut walk, &mut paths);
        }
        if options.join_ends {
            path::join_ends(&mut paths, &adjacency.neighbours);
        }
        let mut indices = Vec::with_capacity(mesh.triangle_count() * 6 / 5 + 3 * paths.len());
        let mut starts = Vec::with_capacity(paths.len() + 1);
        starts.push(0);
        for p in &paths {
            path::encode(p, &mesh.triangles, &adjacency.neighbours, &mut indices);
            starts.push(indices.len() as u32);
        }
        let cost = indices.len() + starts.len();
        if best.as_ref().is_none_or(|(bi, bs)| cost < bi.len() + bs.len()) {
            best = Some((indices, starts));
        }
    }
    let (indices, starts) = best.expect("at least one penalty is tried");
    let strips = Strips::from_runs(
        starts.windows(2).map(|w| &indices[w[0] as usize..w[1] as usize]),
        mesh.vertex_count() as u32,
    )
    .expect("stripify produced an invalid run (internal error)");
    debug_assert_eq!(strips.triangle_count(), mesh.triangle_count());
    strips
}
