//! Quadric-error pair contractions recorded as one level-of-detail sequence.
//!
//! [`simplify`] runs Garland and Heckbert's greedy pair contraction
//! (`contract.rs`) until no valid pair or no triangle remains and records
//! every step in [`Collapses`], which answers representatives, triangle
//! counts and the naive replay at any LoD. `quadric.rs` holds the error
//! quadrics, `pairs.rs` the candidate pairs, and `queue.rs`, `fans.rs`
//! and `refusals.rs` the loop's flat structures: the priority queue, the
//! triangles around each vertex (and the neighbours of wide fans) and the
//! targets a guard refused. [`simplify_locked`] keeps chosen vertices in
//! place (a part's border, `crate::hierarchy`); the flags are an argument,
//! not a field of [`SimplifyOptions`], so that the options stay `Copy` and
//! callers that spell every field out are unchanged.

mod collapses;
mod contract;
mod fans;
mod pairs;
pub mod quadric;
mod queue;
mod refusals;
mod regions;

pub use collapses::{Collapse, Collapses};
pub use contract::{simplify, simplify_locked};
pub use regions::{
    cut_into_regions, region_borders, regions_refusal, simplify_in_regions, MAX_REGIONS,
    REGION_SHARE,
};

/// Where a contraction puts the surviving vertex.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Placement {
    /// Keep the endpoint with the lower quadric error (the default: the
    /// model then holds only original vertices, as the MTS model needs).
    #[default]
    Endpoint,
    /// Create a vertex at the quadric's minimiser (or the best of the two
    /// endpoints and the midpoint when the minimiser is ill-defined); the
    /// new vertices are appended after the input's.
    Optimal,
}

/// Settings of [`simplify`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SimplifyOptions {
    /// Where the surviving vertex goes.
    pub placement: Placement,
    /// Also pair vertices that share no edge but lie closer than this
    /// fraction of the bounding-box diagonal (Garland and Heckbert's
    /// "virtual pairs", which can join separate parts). Off by default.
    pub pair_distance: Option<f32>,
    /// Weight of the planes that hold boundary edges in place, relative to
    /// the `sqrt(area)` weight of face planes (a boundary edge of length
    /// `l` adds a plane of weight `boundary_weight × l` through it,
    /// perpendicular to its triangle, and its triangle's plane at the
    /// same weight).
    ///
    /// The default is 15. Over 6 vertex orders × 40 rows (geometric mean
    /// of the median Hausdorff ratios to meshoptimizer's; only open models
    /// move): 5 → 0.739, 10 → 0.736, 12.5 → 0.730, 15 → 0.719, 20 →
    /// 0.723, 30 → 0.718, 40 → 0.732, 100 → 0.740; over 10 orders 10 →
    /// 0.741, 15 and 20 → 0.722. At 15 teapot at 10% went 1.02 → 0.69,
    /// bunny_res3 at 1% 0.82 → 0.62 and beetle at 1% 2.85 → 2.33, and no
    /// row's median rose by more than 0.05 (at 20 alligator at 1% 0.71 →
    /// 0.92 did). With the 15° crease gate that came after: 10 → 0.713,
    /// 15 → 0.698, 20 → 0.704.
    pub boundary_weight: f64,
    /// Stop once the mesh has at most this many triangles (the sequence
    /// then ends there); `None` runs until no valid pair or no triangle
    /// remains.
    pub stop_at_triangles: Option<usize>,
    /// How much distorting each vertex property costs, on a mesh with
    /// properties (see [`AttributeWeights`]).
    pub attribute_weights: AttributeWeights,
}

/// Weights of the property errors in the contraction cost: an error of
/// `1 / weight` in a property (UV units, unit-normal components, colour
/// channels in 0..=1) costs as much as moving the surface by one
/// bounding-box diagonal. Zero leaves the property out of the cost (seams
/// are kept whatever the weights).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AttributeWeights {
    /// Texture coordinates.
    pub uv: f32,
    /// Normal components.
    pub normal: f32,
    /// Colour channels.
    pub color: f32,
}

/// The defaults are small: on the shared models with properties (spot,
/// pirate, beetle) every larger weight tried (UV 0.2 to 17, normals 0.03
/// to 0.6) made both the geometric error and the measured property error
/// worse, since the property error is sampled at the closest point of the
/// input and follows the geometry; these keep both within a few percent of
/// weight 0 while still ranking contractions where geometry cannot tell
/// them apart (a flat grid with a bent UV map: UV error 0.0035 at weight 0,
/// 0.0003 at 0.2). See `docs/experiments/properties.md`.
impl Default for AttributeWeights {
    fn default() -> AttributeWeights {
        AttributeWeights {
            uv: 0.01,
            normal: 0.001,
            color: 0.01,
        }
    }
}

impl Default for SimplifyOptions {
    fn default() -> SimplifyOptions {
        SimplifyOptions {
            placement: Placement::Endpoint,
            pair_distance: None,
            boundary_weight: 15.0,
            stop_at_triangles: None,
            attribute_weights: AttributeWeights::default(),
        }
    }
}

/// Why a contraction sequence ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum StopReason {
    /// [`SimplifyOptions::stop_at_triangles`] was reached.
    TargetReached,
    /// Every remaining candidate pair was rejected by a guard (counts in
    /// [`Stop`]), or no candidate pair was left at all.
    NoValidPair,
    /// No triangle is left: the last ones were contracted away (an open
    /// sheet is cut down to nothing; a closed part folds flat into a
    /// doubled triangle, which the next contraction removes, as
    /// meshoptimizer's `simplify` does with a target of 0), or the input
    /// had none.
    NoTriangleLeft,
}

/// Where and why the sequence ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Stop {
    /// Why it ended.
    pub reason: StopReason,
    /// The last LoD (the number of contractions made).
    pub lod: usize,
    /// Triangles left at that LoD.
    pub triangles: usize,
    /// Vertices still referenced by a triangle at that LoD.
    pub vertices: usize,
    /// Candidate pairs examined in the final round, all rejected.
    pub candidates_left: usize,
    /// Of those, rejected because a triangle normal would flip.
    pub rejected_flip: usize,
    /// Of those, rejected by a topology rule: an edge would hold more
    /// triangles than the input's most crowded edge (or two), an interior
    /// vertex's move would pinch the surface, or a border vertex would
    /// leave its border.
    pub rejected_topology: usize,
}

impl std::fmt::Display for Stop {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self.reason {
            StopReason::TargetReached => write!(
                f,
                "target reached at LoD {} ({} triangles)",
                self.lod, self.triangles
            ),
            StopReason::NoTriangleLeft => {
                write!(f, "no triangle left at LoD {}", self.lod)
            }
            StopReason::NoValidPair => write!(
                f,
                "no valid pair left at LoD {} ({} triangles, {} vertices): \
                 {} candidates, {} would flip a normal, {} break a topology rule",
                self.lod,
                self.triangles,
                self.vertices,
                self.candidates_left,
                self.rejected_flip,
                self.rejected_topology
            ),
        }
    }
}

/// The result of [`simplify`]: the sequence and where it stopped.
#[derive(Debug, Clone, PartialEq)]
pub struct Simplification {
    /// The recorded contraction sequence.
    pub collapses: Collapses,
    /// Where and why it ended.
    pub stop: Stop,
}

/// Hints the cache to load `x` (the loops here wait on memory, not on
/// arithmetic, and their next loads are known early). No effect off x86-64.
#[inline(always)]
pub(crate) fn prefetch<T: ?Sized>(x: &T) {
    #[cfg(target_arch = "x86_64")]
    // SAFETY: a prefetch of a valid reference never faults or writes.
    unsafe {
        use std::arch::x86_64::{_mm_prefetch, _MM_HINT_T0};
        _mm_prefetch::<_MM_HINT_T0>(std::ptr::from_ref(x).cast::<i8>());
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = x;
}
