//! Coherence inside a strip: the strip's walk cut into *segments* of about
//! [`SEGMENT`] indices, each with its own validity interval, so that a LoD
//! change re-walks only from the first segment it invalidates and stops
//! as soon as the new walk meets a later segment that is still valid
//! (the MTS paper's future work, "introducing coherence inside every
//! strip").
//!
//! A segment starts where the walk is about to write a node's vertex: its
//! node (record), its offset in the strip's slot, and the interval of LoDs
//! `[from, to]` over which every decision the walk made inside it (arcs
//! skipped and taken, and for the first segment the beginning) stays the
//! same. The walk from a node depends only on the node and the LoD, so:
//! - a walk at LoD `L'` agrees with the current one up to the first
//!   segment whose interval excludes `L'`, and may start there;
//! - once it is about to write a node that starts a later current segment
//!   whose interval, and every later one's, holds `L'`, the rest is that
//!   segment onwards unchanged: it is moved (one `copy_within`, when the
//!   new part's length differs) instead of walked.
//!
//! The new part is written to a scratch buffer first, since it may be
//! longer than the part it replaces. The result is the same bytes as a
//! walk of the whole strip (`Extractor::set_lod_from_scratch` checks it
//! in the tests); segments only decide how much is walked.
//!
//! **Decision: segments of 32 indices, and at most `2 × slot / 32 + 2` per
//! strip.** Shorter segments find the change more precisely but cost a
//! bookkeeping step each; a partial walk that meets a valid segment leaves
//! a short segment before it, so the count is capped (past the cap the
//! walk goes on to the strip's end and lays regular segments again).
//! Figures: `docs/experiments/coherence.md`.

use super::records::{step, Word};
use super::{MtsModel, END};
use crate::strip::encode::RESTART_U32;

/// Indices per segment (the walk cuts at the first node at or past it).
pub(crate) const SEGMENT: usize = 32;

/// Segment capacity of a strip whose slot holds `slot` indices.
pub(crate) fn capacity(slot: u32) -> usize {
    2 * (slot as usize / SEGMENT) + 2
}

/// One strip's segments: node, offset, interval, in four parallel slices
/// of the strip's capacity.
pub(crate) struct Segments<'a> {
    pub(crate) rec: &'a mut [u32],
    pub(crate) off: &'a mut [u32],
    pub(crate) from: &'a mut [u32],
    pub(crate) to: &'a mut [u32],
}

/// The strip's segments before this walk, from the first one that may be
/// met again (copied out, since the new segments overwrite them).
pub(crate) struct Old<'a> {
    pub(crate) rec: &'a [u32],
    pub(crate) off: &'a [u32],
    pub(crate) from: &'a [u32],
    pub(crate) to: &'a [u32],
    /// The strip's sequence length before this walk.
    pub(crate) len: usize,
}

/// What a (partial) walk did.
pub(crate) struct Rewalk {
    /// The strip's new sequence length.
    pub(crate) len: usize,
    /// Segments now.
    pub(crate) segments: usize,
    /// First and one-past-last index of the slot that changed.
    pub(crate) dirty: (usize, usize),
    /// Indices the walk wrote itself (not moved).
    pub(crate) walked: usize,
    pub(crate) overflow: bool,
}

/// The walk state that the model's width choice does not touch.
pub(crate) struct Strip<'a> {
    pub(crate) model: &'a MtsModel,
    pub(crate) s: usize,
    pub(crate) birth: u32,
    pub(crate) lod: u32,
    /// The segment to walk from (0: from the strip's beginnings).
    pub(crate) start: usize,
}

/// Walks strip `st.s` at `st.lod` from segment `st.start` into `out` (its
/// slot), laying segments into `segs`
/// and stopping early where it meets a valid segment of `old`. `tmp` is
/// scratch at least as long as the slot.
pub(crate) fn rewalk<V: Word, L: Word>(
    st: &Strip<'_>,
    vertex: &[V],
    label: &[L],
    out: &mut [u32],
    tmp: &mut [u32],
    segs: &mut Segments<'_>,
    old: &Old<'_>,
) -> Rewalk {
    let (model, start) = (st.model, st.start);
    let (birth, lod) = (st.birth, st.lod);
    let max_lod = model.max_lod() as u32;
    let cap = segs.rec.len();
    let code = &model.rec_code[..];
    let mut from = 0u32;
    let mut to = max_lod;
    let origin = if start == 0 {
        0
    } else {
        segs.off[start] as usize
    };
    let finish = |segs: &mut Segments<'_>, k: usize, from: u32, to: u32| {
        segs.from[k] = from;
        segs.to[k] = to;
    };
    // The first node: from the beginnings, or the segment's own.
    let mut r = if start == 0 {
        let begins = model.begins_of(st.s);
        let mut b = begins.start;
        while b < begins.end && model.begin_res[b] < lod {
            from = from.max(model.begin_res[b] + 1);
            b += 1;
        }
        let node = if b == begins.end {
            END
        } else {
            to = to.min(model.begin_res[b]);
            model.begin_node[b]
        };
        if node == END {
            segs.rec[0] = END;
            segs.off[0] = 0;
            finish(segs, 0, from, to);
            return Rewalk {
                len: 0,
                segments: 1,
                dirty: (0, old.len),
                walked: 0,
                overflow: false,
            };
        }
        segs.rec[0] = node;
        segs.off[0] = 0;
        node as usize
    } else {
        segs.rec[start] as usize
    };
    let rel = lod.saturating_sub(birth);
    let holds = |m: usize| old.from[m] <= lod && lod <= old.to[m];
    // With no segment to meet, the walk writes its slot directly.
    let direct = old.rec.is_empty();
    let mut origin = origin;
    let mut t = 0usize;
    let mut k = start;
    let mut j = 0usize;
    // Where the old content now lies: its offsets plus `shift`, up to
    // `old_end`.
    let mut shift = 0isize;
    let mut old_end = old.len;
    // The furthest the slot's content has reached: past the new end, it is
    // padded.
    let mut high = old.len;
    let (dirty_lo, mut dirty_hi) = (origin, origin);
    let mut walked = 0;
    let mut overflow = false;
    'nodes: loop {
        let room = out.len() - origin;
        if t > 0 && !direct {
            // Met a valid segment of the old walk: keep it and the valid
            // ones after it, then walk again from the next changed one.
            while j < old.rec.len() && (old.rec[j] as usize) < r {
                j += 1;
            }
            if j < old.rec.len() && old.rec[j] as usize == r && holds(j) {
                let m = (j + 1..old.rec.len()).find(|&m| !holds(m));
                let kept = m.unwrap_or(old.rec.len()) - j;
                let (p, q) = (origin + t, (old.off[j] as isize + shift) as usize);
                // Keeping costs a move of the whole tail when the length
                // changed: worth it only when the kept part is at least a
                // sixteenth of that tail (a move is that much cheaper per
                // index than a walk).
                let kept_to = m.map_or(old_end, |m| (old.off[m] as isize + shift) as usize);
                let worth = p == q || 16 * (kept_to - q) >= old_end - q;
                if worth
                    && k + 1 + kept + usize::from(m.is_some()) <= cap
                    && p + (old_end - q) <= out.len()
                {
                    finish(segs, k, from, to);
                    if p != q {
                        out.copy_within(q..old_end, p);
                        let moved_end = p + old_end - q;
                        dirty_hi = dirty_hi.max(old_end).max(moved_end);
                        old_end = moved_end;
                        high = high.max(old_end);
                        shift += p as isize - q as isize;
                    } else {
                        dirty_hi = dirty_hi.max(p);
                    }
                    out[origin..p].copy_from_slice(&tmp[..t]);
                    walked += t;
                    for n in j..j + kept {
                        k += 1;
                        segs.rec[k] = old.rec[n];
                        segs.off[k] = (old.off[n] as isize + shift) as u32;
                        segs.from[k] = old.from[n];
                        segs.to[k] = old.to[n];
                    }
                    let Some(m) = m else {
                        if high > old_end {
                            out[old_end..high].fill(RESTART_U32);
                        }
                        return Rewalk {
                            len: old_end,
                            segments: k + 1,
                            dirty: (dirty_lo, dirty_hi),
                            walked,
                            overflow: false,
                        };
                    };
                    // Walk again from changed segment `m`, whose node the
                    // kept segments lead to.
                    r = old.rec[m] as usize;
                    origin = (old.off[m] as isize + shift) as usize;
                    k += 1;
                    segs.rec[k] = r as u32;
                    segs.off[k] = origin as u32;
                    (from, to) = (0, max_lod);
                    j = m + 1;
                    t = 0;
                    continue 'nodes;
                }
            }
        }
        if t > 0 && origin + t - segs.off[k] as usize >= SEGMENT && k + 1 < cap {
            finish(segs, k, from, to);
            k += 1;
            segs.rec[k] = r as u32;
            segs.off[k] = (origin + t) as u32;
            from = 0;
            to = max_lod;
        }
        if t >= room {
            overflow = true;
            break;
        }
        let v = vertex[r].get();
        if direct {
            out[origin + t] = v;
        } else {
            tmp[t] = v;
        }
        t += 1;
        let mut interval = (from, to);
        let next = step(code, label, &model.far, r, rel, birth, &mut interval);
        (from, to) = interval;
        let Some((next, run_break)) = next else {
            break;
        };
        if run_break {
            if t >= room {
                overflow = true;
                break;
            }
            if direct {
                out[origin + t] = RESTART_U32;
            } else {
                tmp[t] = RESTART_U32;
            }
            t += 1;
        }
        r = next;
    }
    finish(segs, k, from, to);
    if !direct {
        out[origin..origin + t].copy_from_slice(&tmp[..t]);
    }
    let len = origin + t;
    // What the old content left past the new end (moved there, or longer
    // before) draws nothing.
    let high = high.max(old_end);
    if high > len {
        out[len..high].fill(RESTART_U32);
    }
    Rewalk {
        len,
        segments: k + 1,
        dirty: (dirty_lo, dirty_hi.max(len).max(high)),
        walked: walked + t,
        overflow,
    }
}

/// A whole walk's validity interval from its segments' (their
/// intersection).
pub(crate) fn interval(from: &[u32], to: &[u32]) -> (u32, u32) {
    (
        from.iter().copied().max().unwrap_or(0),
        to.iter().copied().min().unwrap_or(0),
    )
}
