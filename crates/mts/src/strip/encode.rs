//! Index-buffer encodings of [`Strips`]: restart (`u32` or `u16`) and
//! degenerate stitching for backends that ignore primitive restart.

use super::Strips;

pub use crate::encoding::{RESTART_U16, RESTART_U32};

impl Strips {
    /// One `u32` buffer, runs joined by [`RESTART_U32`].
    ///
    /// Cost: O(indices), one allocation of [`Strips::restart_index_count`].
    #[must_use]
    pub fn to_restart_u32(&self) -> Vec<u32> {
        let mut out = Vec::with_capacity(self.restart_index_count());
        for (i, run) in self.runs().enumerate() {
            if i > 0 {
                out.push(RESTART_U32);
            }
            out.extend_from_slice(run);
        }
        out
    }

    /// One `u16` buffer joined by [`RESTART_U16`], or `None` when some vertex
    /// index does not fit below the restart value (more than 65,535 vertices).
    #[must_use]
    pub fn to_restart_u16(&self) -> Option<Vec<u16>> {
        if self.vertex_count() > u32::from(RESTART_U16) {
            return None;
        }
        Some(
            self.to_restart_u32()
                .into_iter()
                .map(|i| {
                    if i == RESTART_U32 {
                        RESTART_U16
                    } else {
                        i as u16
                    }
                })
                .collect(),
        )
    }

    /// One `u32` buffer without restart values: runs stitched by repeating
    /// the last vertex of a run and the first of the next, plus one more copy
    /// of that first vertex when needed so that every run starts at an even
    /// position (keeping its winding). Every window across a seam repeats a
    /// vertex, so the seams draw nothing.
    ///
    /// Cost: O(indices).
    #[must_use]
    pub fn to_stitched(&self) -> Vec<u32> {
        let mut out = Vec::with_capacity(self.restart_index_count() + 3 * self.run_count());
        for (i, run) in self.runs().enumerate() {
            if i > 0 {
                let last = *out.last().expect("previous run is not empty");
                out.push(last);
                out.push(run[0]);
                if out.len() % 2 == 1 {
                    out.push(run[0]);
                }
            }
            out.extend_from_slice(run);
        }
        out
    }
}

/// Re-encodes a restart-joined `u32` buffer (runs separated by
/// [`RESTART_U32`], as [`crate::Extractor::buffer`] holds them, padding
/// included) into one run without restart values, stitched the way
/// [`Strips::to_stitched`] does; runs shorter than three indices draw
/// nothing and are dropped. Writes into `out` (cleared first).
///
/// Cost: O(indices), no allocation beyond growing `out`.
pub fn stitch_restart_buffer(buffer: &[u32], out: &mut Vec<u32>) {
    out.clear();
    for run in buffer.split(|&i| i == RESTART_U32) {
        if run.len() < 3 {
            continue;
        }
        if let Some(&last) = out.last() {
            out.push(last);
            out.push(run[0]);
            if out.len() % 2 == 1 {
                out.push(run[0]);
            }
        }
        out.extend_from_slice(run);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::strip::decode_run;

    fn strips() -> Strips {
        Strips::from_runs(
            [&[0, 1, 2, 3, 4][..], &[5, 6, 7, 8][..], &[1, 5, 9][..]],
            10,
        )
        .unwrap()
    }

    #[test]
    fn restart_encodings_agree() {
        let s = strips();
        let b32 = s.to_restart_u32();
        assert_eq!(
            b32,
            vec![0, 1, 2, 3, 4, RESTART_U32, 5, 6, 7, 8, RESTART_U32, 1, 5, 9]
        );
        let b16 = s.to_restart_u16().unwrap();
        assert_eq!(b16.len(), b32.len());
        assert_eq!(b16[5], RESTART_U16);
        assert!(Strips::from_runs([&[0, 1, 70_000][..]], 70_001)
            .unwrap()
            .to_restart_u16()
            .is_none());
    }

    #[test]
    fn stitched_buffer_draws_the_same_triangles() {
        let s = strips();
        let stitched = s.to_stitched();
        let mut drawn = Vec::new();
        decode_run(&stitched, &mut drawn);
        assert_eq!(drawn, s.triangles());
        assert!(!stitched.contains(&RESTART_U32));
    }

    #[test]
    fn stitching_a_padded_restart_buffer_matches_to_stitched() {
        let s = strips();
        let mut padded = vec![RESTART_U32, RESTART_U32];
        for run in s.runs() {
            padded.extend_from_slice(run);
            padded.extend([RESTART_U32, 7, RESTART_U32, RESTART_U32]);
        }
        let mut out = vec![42];
        stitch_restart_buffer(&padded, &mut out);
        assert_eq!(out, s.to_stitched());
    }
}
