//! The strip encoding of `docs/design.md` ("Strip encoding"): how a
//! run of vertices or a restart-joined index buffer draws triangles.
//!
//! A leaf: it imports nothing from the crate, so every layer reads strips
//! through it — the PLY reader's `tristrips`, [`crate::strip`], the
//! extractor and its verification, the renderer and the bench — without
//! importing the layer above it.

/// Restart value for `u32` index buffers.
pub const RESTART_U32: u32 = u32::MAX;
/// Restart value for `u16` index buffers.
pub const RESTART_U16: u16 = u16::MAX;

/// Whether a triangle repeats a vertex index (draws nothing). The one test
/// used by loaders, cleaning, validation and strip decoding.
#[must_use]
#[inline]
pub fn is_degenerate(t: [u32; 3]) -> bool {
    t[0] == t[1] || t[1] == t[2] || t[0] == t[2]
}

/// Appends the oriented triangles of one run to `out`.
///
/// Triangle `i` is `(s[i], s[i+1], s[i+2])` for even `i` and
/// `(s[i+1], s[i], s[i+2])` for odd `i`; windows with a repeated vertex are
/// skipped. Cost: O(run), no allocation beyond `out`'s growth.
pub fn decode_run(run: &[u32], out: &mut Vec<[u32; 3]>) {
    out.extend(run_triangles(run));
}

/// The oriented triangles of one run, as [`decode_run`] appends them:
/// the one strip rule, for callers that fold them without a list.
pub fn run_triangles(run: &[u32]) -> impl Iterator<Item = [u32; 3]> + '_ {
    run.windows(3).enumerate().filter_map(|(i, w)| {
        let [a, b, c] = [w[0], w[1], w[2]];
        (!is_degenerate([a, b, c])).then_some(if i % 2 == 0 { [a, b, c] } else { [b, a, c] })
    })
}

/// Appends the oriented triangles of a buffer of runs joined by
/// [`RESTART_U32`] to `out` (each run decoded by [`decode_run`]).
/// Cost: O(buffer).
pub fn decode_restart_buffer(buffer: &[u32], out: &mut Vec<[u32; 3]>) {
    for run in buffer.split(|&i| i == RESTART_U32) {
        decode_run(run, out);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn runs_alternate_winding_and_skip_swaps() {
        // 0 1 2 3 2 4: windows (0,1,2), (1,2,3) flipped, (2,3,2) a swap,
        // (3,2,4) flipped.
        let mut out = Vec::new();
        decode_restart_buffer(&[0, 1, 2, 3, 2, 4, RESTART_U32, 5, 6, 7], &mut out);
        assert_eq!(out, vec![[0, 1, 2], [2, 1, 3], [2, 3, 4], [5, 6, 7]]);
    }
}
