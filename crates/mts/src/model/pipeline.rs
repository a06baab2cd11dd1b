//! The whole pipeline from a mesh to its MTS model: strips of LoD 0 and the
//! contraction sequence (independent of each other, so computed on two
//! threads), then the per-strip graphs ([`super::build`]).

use super::{build_with_progress, can_build, BuildOptions, MtsModel};
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

/// Builds the MTS model of `mesh`: [`stripify()`] and [`simplify()`] at
/// once on two threads, then [`super::build`]. `progress(lods_done,
/// max_lod)` is called as the graph construction advances. Returns the model, where and
/// why the contraction sequence stopped, and the stage timings.
///
/// Cost: that of the three stages; peak memory about the sum of their
/// outputs plus the construction's working arrays.
///
/// # Panics
/// As [`super::build`]: optimal placement on a mesh with properties is
/// refused ([`super::can_build`]); [`try_build_from_mesh`] returns that as
/// an error instead.
///
/// # Example
///
/// ```
/// use mts::mesh::generate::Generated;
/// use mts::model::{build_from_mesh, PipelineOptions};
///
/// let mesh = "icosphere:5k".parse::<Generated>()?.build();
/// let mut progress_calls = 0;
/// let (model, stop, timings) =
///     build_from_mesh(&mesh, &PipelineOptions::default(), &mut |_, _| progress_calls += 1);
/// // LoD 0 is the full mesh, and there is one LoD per contraction made.
/// assert_eq!(model.triangle_count(0), mesh.triangle_count());
/// assert_eq!(model.max_lod(), stop.lod);
/// assert_eq!(model.triangle_count(model.max_lod()), stop.triangles);
/// assert!(progress_calls > 0 && timings.model <= timings.total);
/// # Ok::<(), mts::Error>(())
/// ```
#[must_use]
pub fn build_from_mesh(
    mesh: &Mesh,
    options: &PipelineOptions,
    progress: &mut dyn FnMut(usize, usize),
) -> (MtsModel, Stop, PipelineTimings) {
    match try_build_from_mesh(mesh, options, progress) {
        Ok(built) => built,
        Err(e) => panic!("build_from_mesh: {e}"),
    }
}

/// [`build_from_mesh`], with the options the model cannot be built from
/// (optimal placement on a mesh with vertex properties or seams: created
/// vertices whose counts vary per step, [`super::can_build`]) returned as
/// an error before any work is done, or after the contraction sequence
/// when only it tells.
///
/// # Errors
/// [`crate::Error::InvalidArgument`] naming the options.
///
/// # Example
///
/// ```
/// use mts::mesh::generate::Generated;
/// use mts::model::{try_build_from_mesh, PipelineOptions};
/// use mts::simplify::Placement;
///
/// // A torus with UVs, seams, normals and colours.
/// let mesh = "torus:2k".parse::<Generated>()?.build_with_properties();
/// let mut options = PipelineOptions::default();
/// assert!(try_build_from_mesh(&mesh, &options, &mut |_, _| {}).is_ok());
/// options.simplify.placement = Placement::Optimal;
/// let refused = try_build_from_mesh(&mesh, &options, &mut |_, _| {});
/// assert!(matches!(refused, Err(mts::Error::InvalidArgument(_))));
/// # Ok::<(), mts::Error>(())
/// ```
pub fn try_build_from_mesh(
    mesh: &Mesh,
    options: &PipelineOptions,
    progress: &mut dyn FnMut(usize, usize),
) -> crate::Result<(MtsModel, Stop, PipelineTimings)> {
    let refused = || {
        crate::Error::InvalidArgument(
            "optimal placement creates vertices the MTS model cannot hold on a mesh with \
             vertex properties or seams: use endpoint placement, or drop the properties"
                .into(),
        )
    };
    let optimal = options.simplify.placement == crate::simplify::Placement::Optimal;
    if optimal && !mesh.properties.is_empty() {
        return Err(refused());
    }
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
    if !can_build(&simplification.collapses) {
        return Err(refused());
    }
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
    Ok((model, simplification.stop, timings))
}
