//! Simplification quality against meshoptimizer at one triangle count: the
//! comparison `mts simplify` prints and `mts bench` tabulates, in one place.
//!
//! Both surfaces are measured against the input as Metro does
//! ([`crate::distance`]: Cignoni, Rocchini, Scopigno 1998), meshoptimizer's
//! `simplify` asked for the triangle count of the project's LoD
//! ([`super::meshopt::simplify_to_lod`]).

use super::meshopt::simplify_to_lod;
use crate::distance::{surface_distance, Surface, SurfaceDistance};
use crate::mesh::Mesh;
use crate::simplify::Collapses;
use std::time::Instant;

/// One simplified surface measured against the input.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Measurement {
    /// Triangles of the simplified surface.
    pub triangle_count: usize,
    /// Its distance to the input, relative to the input's bounding-box
    /// diagonal.
    pub distance: SurfaceDistance,
}

/// The project's LoD and meshoptimizer's `simplify` at one triangle count.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct QualityComparison {
    /// The LoD the project's surface was measured at: the one asked for,
    /// or, where meshoptimizer stops above its triangle count, the LoD at
    /// meshoptimizer's count.
    pub lod: usize,
    /// The project's surface at [`QualityComparison::lod`].
    pub ours: Measurement,
    /// meshoptimizer's result.
    pub meshopt: Measurement,
    /// Wall-clock milliseconds of meshoptimizer's `simplify` (one run).
    pub meshopt_ms: f64,
}

/// Measures the project's surface at `lod` of `collapses` (computed from
/// `reference`) and meshoptimizer's `simplify` of `reference` asked for the
/// same triangle count, each with `samples` points per side (see
/// [`surface_distance`]). `ours` builds the project's surface at the LoD
/// it is given ([`QualityComparison::lod`]): each caller keeps its own
/// construction (every position kept, or the unreferenced ones dropped),
/// since the vertex order changes the sampling's last bits and with them
/// the published figures.
///
/// # Panics
/// If `lod > collapses.max_lod()`, or meshoptimizer refuses `reference`
/// (a valid [`Mesh`] never causes that).
///
/// Cost: meshoptimizer's `simplify` and two [`surface_distance`] calls,
/// O((T + samples) log T) each.
#[must_use]
pub fn compare(
    reference: &Mesh,
    collapses: &Collapses,
    lod: usize,
    samples: usize,
    ours: impl FnOnce(usize) -> Mesh,
) -> QualityComparison {
    let t = Instant::now();
    let (theirs, lod) = simplify_to_lod(reference, collapses, lod);
    let meshopt_ms = t.elapsed().as_secs_f64() * 1e3;
    let ours = ours(lod);
    let ours = Measurement {
        triangle_count: ours.triangle_count(),
        distance: surface_distance(reference.into(), (&ours).into(), samples),
    };
    let meshopt = Measurement {
        triangle_count: theirs.len(),
        distance: surface_distance(reference.into(), Surface::over(reference, &theirs), samples),
    };
    QualityComparison {
        lod,
        ours,
        meshopt,
        meshopt_ms,
    }
}
