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
    /// Cost of a swap, in "free neighbours", when the local pass picks the
    /// next triangle: score = free neighbours of the candidate + this if it
    /// needs a swap; lowest wins. Any value above 2 means "never swap when
    /// the other side is free".
    pub swap_penalty: f32,
    /// Join strips whose end triangles are neighbours after both passes.
    pub join_ends: bool,
}

impl Default for StripifyOptions {
    fn default() -> StripifyOptions {
        StripifyOptions {
            patches: true,
            min_patch_quads: 512,
            swap_penalty: 0.5,
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
    let mut walk = Walk::new(&mesh.triangles, &adjacency.neighbours, options.swap_penalty);
    let mut paths: Vec<Vec<u32>> = Vec::new();
    if options.patches {
        patches::strip_patches(&mut walk, &mesh.positions, options.min_patch_quads, &mut paths);
    }
    greedy::strip_rest(&mut walk, &mut paths);
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
    let strips = Strips::from_runs(
        starts.windows(2).map(|w| &indices[w[0] as usize..w[1] as usize]),
        mesh.vertex_count() as u32,
    )
    .expect("stripify produced an invalid run (internal error)");
    debug_assert_eq!(strips.triangle_count(), mesh.triangle_count());
    strips
}
