//! Figures of merit for a set of strips.

use super::vertex_work::{vertex_work, CacheModel};
use super::Strips;
use crate::lod::Topology;

/// What `mts strips` reports for one stripifier.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct StripStats {
    /// Non-degenerate triangles drawn.
    pub triangles: usize,
    /// Runs.
    pub strips: usize,
    /// Swaps (repeated vertices inside runs).
    pub swaps: usize,
    /// Indices sent with restart encoding, restart values included.
    pub indices_restart: usize,
    /// `indices_restart / triangles`.
    pub indices_per_triangle: f64,
    /// Average cache miss ratio (vertex transforms per triangle) of the
    /// strips' triangle order in a 16-entry FIFO cache.
    pub acmr: f64,
    /// Modelled vertex-shader invocations per triangle of the restart
    /// buffer in batches of 96 indices (NVIDIA, after Kerbl et al. 2018;
    /// restart values count toward a batch: see [`super::vertex_work`]).
    pub acmr_batch96: f64,
    /// The same in batches of 384 indices (AMD).
    pub acmr_batch384: f64,
    /// The same through a 32-entry LRU cache.
    pub acmr_lru32: f64,
    /// The same through a 32-entry LRU cache emptied at every restart (the
    /// model that fits Mesa's lavapipe: see [`CacheModel::LruPerRun`]).
    pub acmr_lru32_run: f64,
    /// Milliseconds the stripifier took.
    pub ms: f64,
}

impl StripStats {
    /// Measures `strips`; `ms` is the time the caller measured.
    #[must_use]
    pub fn new(strips: &Strips, ms: f64) -> StripStats {
        let triangles = strips.triangle_count();
        let indices_restart = strips.restart_index_count();
        let buffer = strips.to_restart_u32();
        let per_triangle =
            |model| vertex_work(&buffer, Topology::StripRestart, model).per_triangle();
        StripStats {
            triangles,
            strips: strips.run_count(),
            swaps: strips.swap_count(),
            indices_restart,
            indices_per_triangle: indices_restart as f64 / triangles.max(1) as f64,
            acmr: super::acmr::fifo_acmr(
                &strips.triangles(),
                strips.vertex_count() as usize,
                super::acmr::CACHE_SIZE,
            ),
            acmr_batch96: per_triangle(CacheModel::Batch(96)),
            acmr_batch384: per_triangle(CacheModel::Batch(384)),
            acmr_lru32: per_triangle(CacheModel::Lru(32)),
            acmr_lru32_run: per_triangle(CacheModel::LruPerRun(32)),
            ms,
        }
    }
}
