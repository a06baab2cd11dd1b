//! [`LodSource`]: the one interface over MTS and the baselines, so that the
//! benchmarks, the CLI and the renderer treat every method alike.
//!
//! Every source answers the LoD numbering of `docs/design.md` (LoD 0
//! is the full mesh, LoD `k` the mesh after `k` contractions of its own
//! sequence), keeps one index buffer that a LoD change rewrites in place,
//! and reports which parts it rewrote.

use glam::Vec3;
use std::ops::Range;

/// How a source's index buffer is drawn.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Topology {
    /// Generalized triangle strips joined by the restart value `u32::MAX`
    /// (odd triangles of a run flipped, degenerate ones skipped).
    StripRestart,
    /// Three indices per triangle, counter-clockwise.
    TriangleList,
}

/// A multiresolution mesh that can be asked for any LoD.
///
/// Object-safe: the CLI and the benches hold `Box<dyn LodSource>`.
pub trait LodSource {
    /// Short name of the method (`mts`, `pm`, `multilevel`, `cluster`,
    /// `discrete`), as the CLI's `--method` spells it.
    fn name(&self) -> &'static str;

    /// The coarsest LoD; LoDs run from 0 (full mesh) to `max_lod()`.
    fn max_lod(&self) -> usize;

    /// Triangles drawn at `lod` (clamped to `max_lod()`). O(1).
    fn triangle_count(&self, lod: usize) -> usize;

    /// The vertex buffer the indices refer to (its numbering is the
    /// method's own; [`LodSource::triangles`] maps back to the input's).
    fn positions(&self) -> &[Vec3];

    /// The property streams (normals, UVs, colours) in the order of
    /// [`LodSource::positions`], uploaded once: every LoD draws the same
    /// vertices, so a LoD change rewrites indices only.
    fn properties(&self) -> &crate::mesh::Properties;

    /// How [`LodSource::indices`] is drawn.
    fn topology(&self) -> Topology;

    /// Switches to `lod` (clamped to `max_lod()`), rewriting only what
    /// changes; returns the LoD now current. Cost: the method's own (see
    /// each implementation); no allocation after construction.
    fn set_lod(&mut self, lod: usize) -> usize;

    /// The LoD last set, if any.
    fn lod(&self) -> Option<usize>;

    /// The index buffer to draw for the current LoD (a prefix of the
    /// method's whole buffer; indices into [`LodSource::positions`]).
    fn indices(&self) -> &[u32];

    /// Index ranges of the whole buffer rewritten by the last
    /// [`LodSource::set_lod`], ascending and disjoint; a renderer uploads
    /// those that fall inside [`LodSource::indices`].
    fn dirty_ranges(&self) -> &[Range<usize>];

    /// Bytes the source holds in memory: its structure plus its working
    /// index buffer.
    fn memory_bytes(&self) -> usize;

    /// Bytes of the method's file (or stream) for the same data. May cost
    /// a serialization (O(size)).
    fn file_bytes(&self) -> usize;

    /// The oriented triangles of the current LoD in the input mesh's vertex
    /// numbering (what the tests compare with the replay oracle). Allocates.
    fn triangles(&self) -> Vec<[u32; 3]>;
}

/// The finest LoD of `source` with at most `budget` triangles
/// (`max_lod()` when even the coarsest has more): a binary search over
/// [`LodSource::triangle_count`], which does not increase with the LoD.
/// O(log LoDs × the source's count cost).
#[must_use]
pub fn lod_for_triangles(source: &dyn LodSource, budget: usize) -> usize {
    let (mut lo, mut hi) = (0, source.max_lod());
    while lo < hi {
        let mid = (lo + hi) / 2;
        if source.triangle_count(mid) <= budget {
            hi = mid;
        } else {
            lo = mid + 1;
        }
    }
    lo
}
