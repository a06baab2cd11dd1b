//! STRIPE-style hybrid stripification.
//!
//! After Evans, Skiena and Varshney, "Optimizing triangle strips for fast
//! rendering" (IEEE Visualization 1996), the search the MTS paper (section
//! 2.2) uses: a global pass finds large rectangular patches of
//! quadrilaterals and strips them along their rows (`patches.rs`); a local
//! greedy pass strips what is left, starting from the triangle with fewest
//! free neighbours and avoiding swaps (`greedy.rs`). Both build strips as
//! walks over triangles; `path.rs` turns a walk into a vertex run. An
//! option replaces both passes with a cache-aware local pass (`cache.rs`):
//! short strips in rows, each around the last row's vertices, for vertex
//! reuse as well as index count.
//!
//! Strips only cross edges that [`TriangleAdjacency`] pairs (manifold and
//! consistently oriented), so boundaries, non-manifold edges and several
//! components need no special case, and every triangle keeps its winding.

mod cache;
mod greedy;
mod patches;
mod path;

use super::Strips;
use crate::mesh::{Mesh, TriangleAdjacency};
use greedy::Walk;

/// Meshes with at least this many triangles run the patch start and the
/// plain start on two threads (a spawn costs tens of microseconds).
const PARALLEL_MIN_TRIANGLES: usize = 20_000;

/// Penalties after the first are tried only on meshes below this size. On
/// the shared models the second penalty won only below it (`non_manif_hole`,
/// `3holes`, `teapot`); penalty 0.5 won on all nine larger ones, where an
/// extra run would add a third of the time.
const EXTRA_PENALTIES_MAX_TRIANGLES: usize = 20_000;

/// A candidate result: all runs back to back and where each starts.
struct Encoded {
    indices: Vec<u32>,
    starts: Vec<u32>,
}

impl Encoded {
    /// Indices sent with restart encoding: the runs plus one restart value
    /// between consecutive runs (`starts` has one entry more than runs).
    fn cost(&self) -> usize {
        self.indices.len() + self.starts.len().saturating_sub(2)
    }
}

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
    /// per penalty from the untouched mesh, and with the first penalty after
    /// the global pass; the run with fewest indices is kept. Below 1 means
    /// "fewest free neighbours first, swap as tie-break" (the rule of the STRIPE paper; best on 16 of the 20 shared
    /// models); above 1 avoids swaps unless the other side is two
    /// neighbours freer (best on `non_manif_hole.ply`: 1.221 against 1.314
    /// indices per triangle). Empty means `[0.5]`. Meshes of 20K triangles
    /// or more use only the first penalty (see
    /// `EXTRA_PENALTIES_MAX_TRIANGLES`).
    pub swap_penalties: [Option<f32>; 2],
    /// Join strips whose end triangles are neighbours, after the patch
    /// start. After a local pass from the untouched mesh there is nothing to
    /// join: a strip ends only when its end triangle has no free neighbour,
    /// so any neighbour is in a strip finished earlier, whose own end had
    /// no free neighbour then either (measured: 0 joins on all 23 meshes).
    /// Patch rows are taken before they grow, so their ends can meet
    /// (bunny: 13 joins, icosphere 100K: 29).
    pub join_ends: bool,
    /// Strip for the vertex cache as well as for index count: one
    /// cache-aware local pass (`stripify/cache.rs`) replaces the passes
    /// above (the other fields are then ignored). Off by default: on the
    /// shared models its FIFO-16 ACMR is within +0.05 of a cache-ordered
    /// list's on 18 of 20 (the default's is 0.19–0.34 above), but it sends 22–34%
    /// more indices than the default and 6–22% more than meshoptimizer's
    /// strips, and a driver that empties its vertex cache at each restart
    /// (lavapipe) loses the reuse unless the runs are stitched
    /// (docs/experiments/vertex-work.md).
    pub cache_aware: bool,
}

impl Default for StripifyOptions {
    fn default() -> StripifyOptions {
        StripifyOptions {
            patches: true,
            min_patch_quads: 512,
            swap_penalties: [Some(0.5), Some(1.5)],
            join_ends: true,
            cache_aware: false,
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
    if options.cache_aware {
        return stripify_cache_aware(mesh);
    }
    if options.patches && mesh.triangle_count() >= PARALLEL_MIN_TRIANGLES {
        // The patch pass's longest-edge test needs only positions: compute
        // it on the second core while the adjacency is built.
        let (adjacency, longest) = std::thread::scope(|scope| {
            let handle = scope.spawn(|| patches::longest_edges(&mesh.triangles, &mesh.positions));
            let adjacency = TriangleAdjacency::new(mesh);
            (adjacency, handle.join().expect("stripify worker panicked"))
        });
        stripify_impl(mesh, &adjacency, Some(longest), options, None)
    } else {
        let adjacency = TriangleAdjacency::new(mesh);
        stripify_impl(mesh, &adjacency, None, options, None)
    }
}

/// [`stripify`] with strips laid along a contraction sequence (issue 34's
/// experiment, `docs/experiments/strip-lifetimes.md`, step 0e): `death[t]`
/// is the LoD at which triangle `t` dies, and the local pass adds
/// `weight × |death(next) − death(current)| / (max death + 1)` to each
/// candidate's score, so that a strip's neighbouring triangles die at
/// close LoDs. Below 0.5 (the scores' step) it only breaks ties. Not used
/// by the model builder: it did not pay (see the experiment).
///
/// # Panics
/// If `death` does not hold one LoD per triangle.
#[must_use]
pub fn stripify_along(
    mesh: &Mesh,
    options: &StripifyOptions,
    death: &[u32],
    weight: f32,
) -> Strips {
    assert_eq!(
        death.len(),
        mesh.triangle_count(),
        "one death LoD per triangle"
    );
    let adjacency = TriangleAdjacency::new(mesh);
    stripify_impl(mesh, &adjacency, None, options, Some((death, weight)))
}

/// [`stripify`] with [`StripifyOptions::cache_aware`].
fn stripify_cache_aware(mesh: &Mesh) -> Strips {
    let adjacency = TriangleAdjacency::new(mesh);
    let mut walk = Walk::new(&mesh.triangles, &adjacency);
    let mut paths = Vec::new();
    cache::strip_cache_aware(&mut walk, mesh.vertex_count(), &mut paths);
    let mut indices = Vec::with_capacity(mesh.triangle_count() * 6 / 5 + 3 * paths.len());
    let mut starts = Vec::with_capacity(paths.len() + 1);
    starts.push(0);
    for p in &paths {
        path::encode(p, &mesh.triangles, &adjacency, false, &mut indices);
        starts.push(indices.len() as u32);
    }
    Strips::from_parts(
        indices,
        starts,
        mesh.vertex_count() as u32,
        mesh.triangle_count(),
    )
}

fn stripify_impl(
    mesh: &Mesh,
    adjacency: &TriangleAdjacency,
    longest: Option<Vec<u8>>,
    options: &StripifyOptions,
    death: Option<(&[u32], f32)>,
) -> Strips {
    let mut fresh = Walk::new(&mesh.triangles, adjacency);
    if let Some((d, _)) = death {
        fresh.death = death;
        fresh.death_span = d.iter().max().map_or(1, |m| m + 1);
    }
    let penalties: Vec<f32> = options.swap_penalties.iter().flatten().copied().collect();
    let mut penalties = if penalties.is_empty() {
        vec![0.5]
    } else {
        penalties
    };
    if mesh.triangle_count() >= EXTRA_PENALTIES_MAX_TRIANGLES {
        penalties.truncate(1);
    }

    // One run of the local pass from `w` (with `paths` already made), then
    // `join`ed if asked, and encoded.
    let attempt =
        |mut w: Walk<'_>, mut paths: Vec<Vec<u32>>, penalty: f32, join: bool| -> Encoded {
            w.swap_penalty = penalty;
            greedy::strip_rest(&mut w, &mut paths);
            if join {
                path::join_ends(&mut paths, adjacency);
            }
            let mut indices = Vec::with_capacity(mesh.triangle_count() * 6 / 5 + 3 * paths.len());
            let mut starts = Vec::with_capacity(paths.len() + 1);
            starts.push(0);
            for p in &paths {
                path::encode(p, &mesh.triangles, adjacency, true, &mut indices);
                starts.push(indices.len() as u32);
            }
            Encoded { indices, starts }
        };
    // From the untouched mesh, with every penalty.
    let from_fresh = || {
        penalties
            .iter()
            .map(|&p| attempt(fresh.clone(), Vec::new(), p, false))
            .min_by_key(Encoded::cost)
            .expect("at least one penalty")
    };
    // After the global pass, with the first penalty. Patches win on some
    // scans (bunny: 1.193 against 1.204 indices per triangle) and lose on
    // meshes the local pass walks in one strip (icosphere: 1.031 against
    // 1.008), so both starts are tried and the cheaper result is kept.
    let from_patches = || {
        if !options.patches {
            return None;
        }
        let longest =
            longest.unwrap_or_else(|| patches::longest_edges(&mesh.triangles, &mesh.positions));
        let mut walk = fresh.clone();
        let mut paths = Vec::new();
        patches::strip_patches(&mut walk, &longest, options.min_patch_quads, &mut paths);
        (!paths.is_empty()).then(|| attempt(walk, paths, penalties[0], options.join_ends))
    };
    // The two are independent: on two threads when the mesh is large enough
    // to pay for the spawn.
    let (patched, plain) = if mesh.triangle_count() >= PARALLEL_MIN_TRIANGLES && options.patches {
        std::thread::scope(|scope| {
            let handle = scope.spawn(from_patches);
            let plain = from_fresh();
            (handle.join().expect("stripify worker panicked"), plain)
        })
    } else {
        (from_patches(), from_fresh())
    };
    let best = match patched {
        Some(p) if p.cost() < plain.cost() => p,
        _ => plain,
    };
    let Encoded { indices, starts } = best;
    // Every path draws each of its triangles once, so the runs draw them all.
    Strips::from_parts(
        indices,
        starts,
        mesh.vertex_count() as u32,
        mesh.triangle_count(),
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::strip::sorted_canonical;

    /// Laid along any death order, the strips draw exactly the mesh's
    /// triangles with their winding; a weight of zero is the plain local
    /// pass; a heavy weight changes the strips.
    #[test]
    fn strips_along_a_death_order_draw_the_mesh() {
        let mesh = crate::mesh::generate::torus(24, 12);
        let local = StripifyOptions {
            patches: false,
            ..StripifyOptions::default()
        };
        let death: Vec<u32> = (0..mesh.triangle_count() as u32)
            .map(|t| (t * 7919) % 101)
            .collect();
        let want = sorted_canonical(&mesh.triangles);
        let plain = stripify(&mesh, &local);
        assert_eq!(stripify_along(&mesh, &local, &death, 0.0), plain);
        let heavy = stripify_along(&mesh, &local, &death, 8.0);
        heavy.validate().unwrap();
        assert_eq!(sorted_canonical(&heavy.triangles()), want);
        assert_ne!(heavy, plain);
    }
}
