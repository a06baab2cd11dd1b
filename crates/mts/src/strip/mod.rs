//! Triangle strips: the [`Strips`] type, its encodings and the stripifier.
//!
//! A strip is a *run*: a vertex sequence `s` whose triangle `i` is
//! `(s[i], s[i+1], s[i+2])`, drawn with flipped winding for odd `i`
//! (what the GPU does for `TriangleStrip`). A *swap* is a repeated vertex:
//! the run `… x y x d …` makes the degenerate window `(x, y, x)` so that the
//! next triangle pivots on `x` instead of `y`. Decoding skips every window
//! with a repeated vertex.

pub use crate::encoding::{decode_restart_buffer, decode_run};

pub mod acmr;
pub mod cache_order;
pub mod encode;
pub mod stats;
pub mod stripify;
pub mod vertex_work;

pub use stripify::{stripify, stripify_along, StripifyOptions};

use crate::error::{Error, Result};
use crate::mesh::is_degenerate;

/// Generalized triangle strips over a mesh's vertices.
///
/// Invariants (checked by [`Strips::validate`]): every run has at least 3
/// vertices, every index is below `vertex_count` and is not the restart value
/// `u32::MAX`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Strips {
    /// All runs back to back.
    indices: Vec<u32>,
    /// Run `i` is `indices[starts[i]..starts[i + 1]]`; `starts[0] == 0`.
    starts: Vec<u32>,
    /// Number of vertices of the mesh the runs index.
    vertex_count: u32,
    /// Non-degenerate triangles the runs decode to.
    triangle_count: usize,
}

impl Strips {
    /// Builds strips from runs.
    ///
    /// # Errors
    /// [`Error::InvalidArgument`] if a run is shorter than 3 or an index is out
    /// of range.
    pub fn from_runs<'a>(
        runs: impl IntoIterator<Item = &'a [u32]>,
        vertex_count: u32,
    ) -> Result<Strips> {
        let mut strips = Strips {
            indices: Vec::new(),
            starts: vec![0],
            vertex_count,
            triangle_count: 0,
        };
        for run in runs {
            strips.indices.extend_from_slice(run);
            strips.starts.push(strips.indices.len() as u32);
        }
        strips.triangle_count = strips.runs().map(run_triangle_count).sum();
        strips
            .validate()
            .map_err(|e| Error::InvalidArgument(e.message))?;
        Ok(strips)
    }

    /// Builds strips from parts the caller has checked: runs back to back,
    /// their offsets (`starts[0] == 0`, one more than runs) and the number
    /// of triangles they draw. Checked in debug builds.
    pub(crate) fn from_parts(
        indices: Vec<u32>,
        starts: Vec<u32>,
        vertex_count: u32,
        triangle_count: usize,
    ) -> Strips {
        let strips = Strips {
            indices,
            starts,
            vertex_count,
            triangle_count,
        };
        #[cfg(debug_assertions)]
        {
            assert_eq!(strips.validate(), Ok(()));
            assert_eq!(
                strips.runs().map(run_triangle_count).sum::<usize>(),
                triangle_count
            );
        }
        strips
    }

    /// Builds strips from one buffer whose runs are separated by `restart`.
    /// Empty runs (two restarts in a row) are ignored.
    ///
    /// # Errors
    /// As [`Strips::from_runs`].
    pub fn from_restart_buffer(buffer: &[u32], restart: u32, vertex_count: u32) -> Result<Strips> {
        Strips::from_runs(
            buffer.split(|&i| i == restart).filter(|r| !r.is_empty()),
            vertex_count,
        )
    }

    /// Number of runs.
    #[must_use]
    pub fn run_count(&self) -> usize {
        self.starts.len() - 1
    }

    /// Run `i`.
    ///
    /// # Panics
    /// If `i >= run_count()`.
    #[must_use]
    pub fn run(&self, i: usize) -> &[u32] {
        &self.indices[self.starts[i] as usize..self.starts[i + 1] as usize]
    }

    /// All runs in order.
    pub fn runs(&self) -> impl ExactSizeIterator<Item = &[u32]> + '_ {
        (0..self.run_count()).map(move |i| self.run(i))
    }

    /// Number of vertices of the indexed mesh.
    #[must_use]
    pub fn vertex_count(&self) -> u32 {
        self.vertex_count
    }

    /// Non-degenerate triangles the runs draw.
    #[must_use]
    pub fn triangle_count(&self) -> usize {
        self.triangle_count
    }

    /// Swaps: degenerate windows inside runs, one index each.
    #[must_use]
    pub fn swap_count(&self) -> usize {
        self.indices.len() - 2 * self.run_count() - self.triangle_count
    }

    /// Indices the GPU reads with restart encoding: every run index plus one
    /// restart value between consecutive runs.
    #[must_use]
    pub fn restart_index_count(&self) -> usize {
        self.indices.len() + self.run_count().saturating_sub(1)
    }

    /// The oriented triangles drawn, in strip order (degenerates skipped, odd
    /// triangles flipped).
    ///
    /// Cost: O(indices), one allocation.
    #[must_use]
    pub fn triangles(&self) -> Vec<[u32; 3]> {
        let mut out = Vec::with_capacity(self.triangle_count);
        for run in self.runs() {
            decode_run(run, &mut out);
        }
        out
    }

    /// Checks the invariants listed on [`Strips`]: every run has at least
    /// three vertices, every index is below the vertex count.
    ///
    /// # Errors
    /// [`crate::Invalid`] naming the first broken one.
    pub fn validate(&self) -> std::result::Result<(), crate::Invalid> {
        for (i, run) in self.runs().enumerate() {
            crate::error::ensure!(
                "Strips",
                run.len() >= 3,
                "run {i} has {} vertices",
                run.len()
            );
            if let Some(v) = run.iter().find(|&&v| v >= self.vertex_count) {
                crate::error::ensure!(
                    "Strips",
                    false,
                    "run {i} uses vertex {v} of {}",
                    self.vertex_count
                );
            }
        }
        Ok(())
    }
}

fn run_triangle_count(run: &[u32]) -> usize {
    run.windows(3)
        .filter(|w| !is_degenerate([w[0], w[1], w[2]]))
        .count()
}

/// A triangle rotated so that its smallest index comes first: equal for the
/// same oriented triangle whatever its starting vertex.
#[must_use]
pub fn canonical_triangle(t: [u32; 3]) -> [u32; 3] {
    let m = (0..3).min_by_key(|&i| t[i]).unwrap_or(0);
    [t[m], t[(m + 1) % 3], t[(m + 2) % 3]]
}

/// The triangles as a sorted list of [`canonical_triangle`]s: two lists with
/// equal results hold the same multiset of oriented triangles.
#[must_use]
pub fn sorted_canonical(triangles: &[[u32; 3]]) -> Vec<[u32; 3]> {
    let mut v: Vec<[u32; 3]> = triangles.iter().map(|&t| canonical_triangle(t)).collect();
    v.sort_unstable();
    v
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn swap_is_one_repeated_vertex() {
        // The paper's Fig. 1 right: 0 1 2 3 4 swap 5 6, sent as 0 1 2 3 4 3 5 6.
        let strips = Strips::from_runs([&[0, 1, 2, 3, 4, 3, 5, 6][..]], 7).unwrap();
        assert_eq!(strips.triangle_count(), 5);
        assert_eq!(strips.swap_count(), 1);
        assert_eq!(
            strips.triangles(),
            vec![[0, 1, 2], [2, 1, 3], [2, 3, 4], [4, 3, 5], [5, 3, 6]]
        );
    }

    #[test]
    fn restart_buffer_round_trip_counts() {
        let s = Strips::from_restart_buffer(&[0, 1, 2, 3, u32::MAX, 4, 5, 6], u32::MAX, 7).unwrap();
        assert_eq!(s.run_count(), 2);
        assert_eq!(s.triangle_count(), 3);
        assert_eq!(s.restart_index_count(), 8);
        assert_eq!(s.swap_count(), 0);
    }

    #[test]
    fn bad_runs_are_refused() {
        assert!(Strips::from_runs([&[0, 1][..]], 3).is_err());
        assert!(Strips::from_runs([&[0, 1, 5][..]], 3).is_err());
    }

    #[test]
    fn canonical_rotation_keeps_orientation() {
        assert_eq!(canonical_triangle([5, 2, 9]), [2, 9, 5]);
        assert_ne!(canonical_triangle([5, 9, 2]), canonical_triangle([5, 2, 9]));
    }
}
