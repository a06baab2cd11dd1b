//! meshoptimizer (through the `meshopt` crate) as the reference stripifier.

use crate::mesh::Mesh;
use crate::simplify::Collapses;
use crate::strip::encode::RESTART_U32;
use crate::strip::Strips;

/// FIFO cache size used for every ACMR figure.
pub const CACHE_SIZE: u32 = 16;

/// meshoptimizer's strips for `mesh`, as its documentation recommends:
/// `optimize_vertex_cache_strip` first, then `stripify` with restart.
///
/// # Panics
/// If meshoptimizer refuses the input, which a valid [`Mesh`] never causes.
#[must_use]
pub fn stripify(mesh: &Mesh) -> Strips {
    let n = mesh.vertex_count();
    let ordered = meshopt::optimize_vertex_cache_strip(&mesh.index_list(), n);
    let buffer = meshopt::stripify(&ordered, n, RESTART_U32)
        .expect("meshopt::stripify failed on a valid mesh");
    Strips::from_restart_buffer(&buffer, RESTART_U32, n as u32)
        .expect("meshopt produced an invalid strip")
}

/// Average cache miss ratio of a triangle list in meshoptimizer's FIFO
/// model with [`CACHE_SIZE`] entries.
#[must_use]
pub fn acmr(triangles: &[[u32; 3]], vertex_count: usize) -> f64 {
    if triangles.is_empty() {
        return 0.0;
    }
    let list: Vec<u32> = triangles.iter().flatten().copied().collect();
    f64::from(meshopt::analyze_vertex_cache(&list, vertex_count, CACHE_SIZE, 0, 0).acmr)
}

/// meshoptimizer's `simplify` toward `target_triangles`, with its default
/// options and no error limit, as a user would call it: returns its
/// triangles (indices into `mesh.positions`). It may stop above the target
/// when its topology rules allow no further collapse.
#[must_use]
pub fn simplify(mesh: &Mesh, target_triangles: usize) -> Vec<[u32; 3]> {
    let positions: Vec<[f32; 3]> = mesh.positions.iter().map(|p| p.to_array()).collect();
    let out = meshopt::simplify_decoder(
        &mesh.index_list(),
        &positions,
        target_triangles * 3,
        f32::MAX,
        meshopt::SimplifyOptions::None,
        None,
    );
    out.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect()
}

/// meshoptimizer's `simplify` asked for the triangle count of `lod` of
/// `collapses`, and the LoD to compare it with: `lod` itself, or, where
/// meshoptimizer stops above that count, the LoD at its count. The quality
/// comparisons (`mts simplify`, `mts bench`, `examples/order_spread.rs`)
/// all go through here, so they compare at one triangle count.
#[must_use]
pub fn simplify_to_lod(mesh: &Mesh, collapses: &Collapses, lod: usize) -> (Vec<[u32; 3]>, usize) {
    let wanted = collapses.triangle_count(lod);
    let theirs = simplify(mesh, wanted);
    let lod = if theirs.len() > wanted {
        collapses.lod_for_triangles(theirs.len())
    } else {
        lod
    };
    (theirs, lod)
}

/// meshoptimizer's `optimize_vertex_cache` on a triangle list: the same
/// triangles (same winding) reordered for the post-transform vertex cache,
/// the triangle-list baseline the renderer's throughput is measured
/// against. Cost: O(triangles), one allocation.
#[must_use]
pub fn optimize_vertex_cache(triangles: &[[u32; 3]], vertex_count: usize) -> Vec<[u32; 3]> {
    let list: Vec<u32> = triangles.iter().flatten().copied().collect();
    meshopt::optimize_vertex_cache(&list, vertex_count)
        .chunks_exact(3)
        .map(|c| [c[0], c[1], c[2]])
        .collect()
}
