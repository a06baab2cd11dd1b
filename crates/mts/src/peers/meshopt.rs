//! meshoptimizer (through the `meshopt` crate) as the reference stripifier.

use crate::mesh::Mesh;
use crate::simplify::AttributeWeights;
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

/// The weights ([`AttributeWeights`], one per stream: each float of the
/// stream gets it) this peer gives meshoptimizer's `simplifyWithAttributes`
/// by default. Its scale is not [`crate::simplify()`]'s:
///
/// meshoptimizer scales positions into the unit cube (by the largest
/// extent) and adds each triangle's attribute error, weighted by its area,
/// to its position quadrics: a change of `1/weight` in an attribute across
/// a distance `d` costs about what moving the surface by `d` does. Its
/// README recommends about 1 for normalised attributes (unit normals,
/// colours in 0..=1) and, for texture coordinates, 10 to 100 depending on
/// their density, or `1/sqrt(average UV area of a triangle)`.
///
/// Normals and colours 1, as meshoptimizer's README recommends for
/// normalised attributes; texture coordinates 30, the middle (on a log
/// scale) of its 10 to 100. Its density rule gives 109 on spot.obj and
/// 84 on pirate.obj. Over the four textured rows of
/// `examples/property_error.rs` (spot and pirate at 10% and 1%) the
/// mean UV RMS of meshoptimizer's LoDs was 0.188 at weight 10, 0.177
/// at 30 and 0.185 at 100 (`--uv-weight`); a normal weight of 0.5 or 2
/// against 1 moved beetle's normal RMS at 10% by under 0.5°.
pub const MESHOPT_WEIGHTS: AttributeWeights = AttributeWeights {
    normal: 1.0,
    uv: 30.0,
    color: 1.0,
};

/// meshoptimizer's `simplifyWithAttributes` toward `target_triangles`, with
/// the normals, texture coordinates and colours `mesh` has as attributes
/// (interleaved `f32`, weighted by `weights`), no vertex locked, default
/// options and no error limit: returns its triangles (indices into
/// `mesh.positions`). Split vertices (same position, other properties) are
/// seams to it, as to [`simplify`]. It may stop above the target. A mesh
/// without property streams is simplified on positions alone.
///
/// Cost: meshoptimizer's (see [`refusal`], which callers check first);
/// allocates the attribute buffer, `(3 + 2 + 4) × 4` bytes a vertex at
/// most.
#[must_use]
pub fn simplify_with_attributes(
    mesh: &Mesh,
    target_triangles: usize,
    weights: AttributeWeights,
) -> Vec<[u32; 3]> {
    let p = &mesh.properties;
    let mut stream_weights = Vec::new();
    if p.normals.is_some() {
        stream_weights.extend([weights.normal; 3]);
    }
    if p.uvs.is_some() {
        stream_weights.extend([weights.uv; 2]);
    }
    if p.colors.is_some() {
        stream_weights.extend([weights.color; 4]);
    }
    let stride = stream_weights.len();
    let mut attributes = Vec::with_capacity(stride * mesh.vertex_count());
    for v in 0..mesh.vertex_count() {
        if let Some(n) = &p.normals {
            attributes.extend(n[v].to_array());
        }
        if let Some(uv) = &p.uvs {
            attributes.extend(uv[v].to_array());
        }
        if let Some(c) = &p.colors {
            attributes.extend(c[v].to_array());
        }
    }
    let positions: Vec<[f32; 3]> = mesh.positions.iter().map(|p| p.to_array()).collect();
    // A lock array of `false` rather than none: the wrapper reads one
    // entry per vertex from whatever slice it gets.
    let unlocked = vec![false; mesh.vertex_count()];
    let out = meshopt::simplify_with_attributes_and_locks_decoder(
        &mesh.index_list(),
        &positions,
        &attributes,
        &stream_weights,
        stride * std::mem::size_of::<f32>(),
        &unlocked,
        target_triangles * 3,
        f32::MAX,
        meshopt::SimplifyOptions::None,
        None,
    );
    out.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect()
}

/// [`simplify_to_lod`] with [`simplify_with_attributes`]: meshoptimizer's
/// attribute-aware simplification asked for the triangle count of `lod`,
/// and the LoD to compare it with (`lod`, or the LoD at meshoptimizer's
/// count where it stops above). Callers check [`refusal`] first.
#[must_use]
pub fn simplify_with_attributes_to_lod(
    mesh: &Mesh,
    collapses: &Collapses,
    lod: usize,
    weights: AttributeWeights,
) -> (Vec<[u32; 3]>, usize) {
    let wanted = collapses.triangle_count(lod);
    let theirs = simplify_with_attributes(mesh, wanted, weights);
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
