//! The whole pipeline from a mesh to its MTS model: strips of LoD 0 and the
//! contraction sequence (independent of each other, so computed on two
//! threads), then the per-strip graphs ([`super::build`]).

use super::{build_with_progress, BuildOptions, MtsModel};
use crate::mesh::Mesh;
use crate::simplify::{simplify, SimplifyOptions, Stop};
use crate::strip::{stripify, StripifyOptions};
use std::time::{Duration, Instant};

/// Options of every stage of [`build_from_mesh`].
#[derive(Debug, Clone, Default)]
pub struct PipelineOptions {
    /// The strips of LoD 0 (later bands use `build.stripify`).
    pub stripify: StripifyOptions,
    /// The contraction sequence.
    pub simplify: SimplifyOptions,
    /// The graphs.
    pub build: BuildOptions,
}

/// Wall-clock time of each stage of [`build_from_mesh`]. Stripifying and
/// simplifying overlap, so `total` is less than the sum.
#[derive(Debug, Clone, Copy, Default)]
pub struct PipelineTimings {
    /// Stripifying LoD 0 (on its own thread).
    pub stripify: Duration,
    /// Recording the contraction sequence (on its own thread).
    pub simplify: Duration,
    /// Building the graphs, after both.
    pub model: Duration,
    /// The whole pipeline.
    pub total: Duration,
}

/// Builds the MTS model of `mesh`: [`stripify`] and [`simplify`] at once on
/// two threads, then [`super::build`]. `progress(lods_done, max_lod)` is
/// called as the graph construction advances. Returns the model, where and
/// why the contraction sequence stopped, and the stage timings.
///
/// Cost: that of the three stages; peak memory about the sum of their
/// outputs plus the construction's working arrays.
///
/// # Panics
/// As [`super::build`]: optimal placement on a mesh with properties is
/// refused ([`super::can_build`]).
#[must_use]
pub fn build_from_mesh(
    mesh: &Mesh,
    options: &PipelineOptions,
    progress: &mut dyn FnMut(usize, usize),
) -> (MtsModel, Stop, PipelineTimings) {
    let t0 = Instant::now();
    let ((strips, t_strips), (simplification, t_simplify)) = std::thread::scope(|scope| {
        let strips = scope.spawn(|| {
            let t = Instant::now();
            let s = stripify(mesh, &options.stripify);
            (s, t.elapsed())
        });
        let t = Instant::now();
        let s = simplify(mesh, &options.simplify);
        let simplified = (s, t.elapsed());
        // A panic in the stripifier is a broken internal invariant: pass it on.
        let strips = strips
            .join()
            .unwrap_or_else(|e| std::panic::resume_unwind(e));
        (strips, simplified)
    });
    let t1 = Instant::now();
    let model = build_with_progress(
        mesh,
        &strips,
        &simplification.collapses,
        &options.build,
        progress,
    );
    let timings = PipelineTimings {
        stripify: t_strips,
        simplify: t_simplify,
        model: t1.elapsed(),
        total: t0.elapsed(),
    };
    (model, simplification.stop, timings)
}
