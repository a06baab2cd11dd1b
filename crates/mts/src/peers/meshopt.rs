//! meshoptimizer (through the `meshopt` crate) as the reference stripifier.

use crate::mesh::Mesh;
use crate::simplify::Collapses;
use crate::strip::encode::RESTART_U32;
use crate::strip::Strips;

/// Largest sum over vertices of their triangle count squared that
/// [`refusal`] lets through to meshoptimizer. Its vertex-cache optimiser
/// and its simplifier's vertex classification scan a vertex's triangles
/// for each of them, so a vertex in k triangles costs k²: 20,000 copies of
/// one triangle (sum 1.2e9) took 24 s in `optimize_vertex_cache_strip`.
/// Real meshes stay far below (a regular mesh sums about 18 per triangle:
/// 72 million at 4 million triangles).
pub const MAX_VALENCE_WORK: u64 = 300_000_000;

/// Why meshoptimizer is not run on `mesh`, or `None` when it is: a mesh
/// whose vertices' squared triangle counts sum above [`MAX_VALENCE_WORK`]
/// (a huge fan, or many coincident triangles) would take minutes in the
/// peer, whose cost is not ours to bound. Callers skip the comparison and
/// say so. O(T).
#[must_use]
pub fn refusal(mesh: &Mesh) -> Option<String> {
    let mut valence = vec![0u64; mesh.vertex_count()];
    for t in &mesh.triangles {
        for &v in t {
            valence[v as usize] += 1;
        }
    }
    let work: u64 = valence.iter().map(|k| k * k).sum();
    if work <= MAX_VALENCE_WORK {
        return None;
    }
    let (v, most) = valence
        .iter()
        .enumerate()
        .max_by_key(|(_, &k)| k)
        .map(|(v, &k)| (v, k))
        .unwrap_or_default();
    Some(format!(
        "meshoptimizer skipped: vertex {v} is in {most} triangles (sum of squared valences \
         {work}, above {MAX_VALENCE_WORK}); meshoptimizer's time grows with the square of a \
         vertex's valence"
    ))
}

/// FIFO cache size used for every ACMR figure.
pub use crate::strip::acmr::CACHE_SIZE;

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

/// meshoptimizer's own `analyze_vertex_cache` ACMR (FIFO of
/// [`CACHE_SIZE`]); the core's [`crate::strip::acmr::fifo_acmr`] is the same
/// model, and a test holds them equal.
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
