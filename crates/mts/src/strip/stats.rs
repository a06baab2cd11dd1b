//! Figures of merit for a set of strips.

use super::Strips;

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
    /// Milliseconds the stripifier took.
    pub ms: f64,
}

impl StripStats {
    /// Measures `strips`; `ms` is the time the caller measured.
    #[must_use]
    pub fn new(strips: &Strips, ms: f64) -> StripStats {
        let triangles = strips.triangle_count();
        let indices_restart = strips.restart_index_count();
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
            ms,
        }
    }
}
