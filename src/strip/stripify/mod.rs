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

/// Meshes with at least this many triangles run the local-pass attempts on
/// two threads.
const PARALLEL_MIN_TRIANGLES: usize = 20_000;

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
    let fresh = Walk::new(&mesh.triangles, &adjacency.neighbours);
    // Starting states for the local pass: after the global pass, and (when
    // the global pass ran) without it. Patches win on some scans (bunny:
    // 1.199 against 1.204 indices per triangle) and lose on meshes the
    // greedy pass already walks in one strip (icosphere: 1.031 against
    // 1.008), so both are tried and the cheaper result is kept.
    let mut starts_states: Vec<(Walk<'_>, Vec<Vec<u32>>)> = Vec::with_capacity(2);
    if options.patches {
        let mut walk = fresh.clone();
        let mut paths = Vec::new();
        patches::strip_patches(&mut walk, &mesh.positions, options.min_patch_quads, &mut paths);
        if !paths.is_empty() {
            starts_states.push((walk, paths));
        }
    }
    starts_states.push((fresh, Vec::new()));
    let penalties: Vec<f32> = options.swap_penalties.iter().flatten().copied().collect();
    let penalties = if penalties.is_empty() { vec![0.5] } else { penalties };
    let attempts: Vec<(usize, f32)> = (0..starts_states.len())
        .flat_map(|state| penalties.iter().map(move |&p| (state, p)))
        .collect();
    let run = |attempts: &[(usize, f32)]| -> Option<(Vec<u32>, Vec<u32>)> {
        let mut best: Option<(Vec<u32>, Vec<u32>)> = None;
        for &(state, penalty) in attempts {
            let (walk, patch_paths) = &starts_states[state];
            let mut paths = patch_paths.clone();
            let mut w = walk.clone();
            w.swap_penalty = penalty;
            greedy::strip_rest(&mut w, &mut paths);
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
            if best.as_ref().is_none_or(|(bi, bs)| indices.len() + starts.len() < bi.len() + bs.len()) {
                best = Some((indices, starts));
            }
        }
        best
    };
    // Attempts are independent: split them over two threads when the mesh
    // is large enough to pay for the spawn (measured: ~50 µs per thread).
    let best = if mesh.triangle_count() >= PARALLEL_MIN_TRIANGLES && attempts.len() > 1 {
        let (left, right) = attempts.split_at(attempts.len() / 2);
        let (a, b) = std::thread::scope(|scope| {
            let handle = scope.spawn(|| run(left));
            let b = run(right);
            (handle.join().expect("stripify worker panicked"), b)
        });
        match (a, b) {
            (Some(a), Some(b)) => Some(if a.0.len() + a.1.len() <= b.0.len() + b.1.len() { a } else { b }),
            (a, b) => a.or(b),
        }
    } else {
        run(&attempts)
    };
    let (indices, starts) = best.expect("at least one penalty is tried");
    let strips = Strips::from_runs(
        starts.windows(2).map(|w| &indices[w[0] as usize..w[1] as usize]),
        mesh.vertex_count() as u32,
    )
    .expect("stripify produced an invalid run (internal error)");
    debug_assert_eq!(strips.triangle_count(), mesh.triangle_count());
    strips
}
