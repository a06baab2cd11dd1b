//! Level-of-detail recovery (section 3.2 of the MTS paper) with the
//! coherence cache of section 4.
//!
//! The output is one `u32` index buffer laid out in per-strip *slots*: strip
//! `s` owns `slot_start[s]..slot_start[s] + slot_size[s]`, sized for its
//! sequence at its band's first LoD (the longest it ever gets, see
//! `build.rs`, "Monotone") plus one restart that separates it from the
//! next slot. What a strip does not use is filled with restart values,
//! which draw nothing. A new LoD re-walks only the strips whose validity
//! interval `[minRes, maxRes]` excludes it, and within such a strip only
//! from the first segment that changed to the first later one that did
//! not ([`super::segments`]), and reports what it rewrote as dirty ranges,
//! so a renderer uploads only those.
//! [`Extractor::write_compact`] gives the same strips without the padding
//! (what "indices sent" counts).
//!
//! **Decision: slots are laid out per band, all bands over the same
//! memory.** Only one band draws at any LoD, so each band's slots start at
//! index 0 and the buffer is as long as the largest band (usually band 0,
//! the input's strips), not the sum of all bands: the bunny's bands need
//! about a tenth of their sum (`docs/experiments/bands.md`), which lets a scene keep
//! one extractor per instance. Changing band rewrites the band's region
//! (one dirty range).

use super::records::{step, with_widths, Narrow, Word};
use super::segments;
use super::{MtsModel, END};
use crate::strip::encode::RESTART_U32;
use std::ops::Range;

/// What one LoD change did.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Update {
    /// The LoD now extracted.
    pub lod: usize,
    /// Strips walked again.
    pub strips_walked: usize,
    /// Dirty ranges reported (see [`Extractor::dirty_ranges`]).
    pub dirty_ranges: usize,
    /// Indices the walks wrote (a strip walked from one of its segments
    /// counts from there, and only up to where it met an unchanged one).
    pub indices_walked: usize,
}

/// Extracts any LoD of a model into a slot-laid index buffer, re-walking
/// only what changed since the last call.
///
/// Allocation happens in [`Extractor::new`] only: every buffer is sized for
/// the worst case there.
///
/// # Example
///
/// ```
/// use mts::mesh::generate::Generated;
/// use mts::model::{build_from_mesh, PipelineOptions};
/// use mts::strip::sorted_canonical;
/// use mts::Extractor;
///
/// let mesh = "torus:2k".parse::<Generated>()?.build();
/// let (model, _, _) = build_from_mesh(&mesh, &PipelineOptions::default(), &mut |_, _| {});
/// let mut extractor = Extractor::new(&model);
/// let half = extractor.set_ratio(0.5).lod;
/// // The strips draw exactly the replayed contraction sequence's triangles.
/// let replayed = model.collapses().triangles_at(&model.mesh(), half);
/// assert_eq!(sorted_canonical(&extractor.triangles()), sorted_canonical(&replayed));
/// // One contraction more: only the strips it changed are walked again, and
/// // only the index ranges they rewrote are to be uploaded.
/// let step = extractor.set_lod(half + 1);
/// assert!(step.strips_walked < model.strip_count());
/// let dirty: usize = extractor.dirty_ranges().iter().map(|r| r.len()).sum();
/// assert!(dirty < extractor.active_range().len());
/// // The same bytes as a walk from scratch.
/// let mut scratch = Extractor::new(&model);
/// scratch.set_lod_from_scratch(half + 1);
/// assert_eq!(extractor.buffer(), scratch.buffer());
/// # Ok::<(), mts::Error>(())
/// ```
#[derive(Debug, Clone)]
pub struct Extractor<'m> {
    model: &'m MtsModel,
    buffer: Vec<u32>,
    /// Per strip, where its slot starts in its band's region (the slot
    /// holds the model's `slot_size[s]` indices, its separating restart
    /// excluded).
    slot_start: Vec<u32>,
    /// Per band, the length of its region (slots and separators).
    band_len: Vec<u32>,
    /// Indices each strip uses now (its run breaks included).
    len: Vec<u32>,
    /// Validity interval of each strip's current sequence (inclusive).
    valid_from: Vec<u32>,
    valid_to: Vec<u32>,
    lod: Option<usize>,
    /// The band whose strips the buffer holds.
    band: Option<usize>,
    dirty: Vec<Range<usize>>,
    /// Sum of `len`, and strips with `len > 0`.
    used: usize,
    non_empty: usize,
    /// Walks cut at their slot's end (only a corrupt model can cause one).
    overflows: usize,
    /// Per strip, where its segments start in its band's region of the
    /// segment arrays, how many it may hold, and how many it holds (0:
    /// not walked in the current band).
    seg_base: Vec<u32>,
    seg_cap: Vec<u32>,
    seg_len: Vec<u32>,
    /// Segments: node (record), slot offset, validity interval.
    seg_rec: Vec<u32>,
    seg_off: Vec<u32>,
    seg_from: Vec<u32>,
    seg_to: Vec<u32>,
    /// Scratch: a walk's new part, and the segments it may meet again.
    tmp: Vec<u32>,
    old_rec: Vec<u32>,
    old_off: Vec<u32>,
    old_from: Vec<u32>,
    old_to: Vec<u32>,
}

/// How much of the coherence cache a LoD change uses.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Mode {
    /// Every strip walked whole (the reference).
    Scratch,
    /// Strips whose interval holds the LoD skipped, the others walked whole.
    Strips,
    /// As `Strips`, and a changed strip walked only from its changed
    /// segments.
    Segments,
}

/// Result of walking one strip.
pub(crate) struct Walk {
    pub(crate) len: u32,
    pub(crate) from: u32,
    pub(crate) to: u32,
    pub(crate) overflow: bool,
}

impl<'m> Extractor<'m> {
    /// An extractor for `model`, with nothing extracted yet (the buffer is
    /// all restarts). Cost: O(strips); the slot sizes come with the model.
    #[must_use]
    pub fn new(model: &'m MtsModel) -> Extractor<'m> {
        let strips = model.strip_count();
        let mut slot_start = Vec::with_capacity(strips);
        let mut seg_base = Vec::with_capacity(strips);
        let mut seg_cap = Vec::with_capacity(strips);
        let mut band_len = Vec::with_capacity(model.band_count());
        let mut segments = 0;
        for b in 0..model.band_count() {
            let (mut at, mut seg_at) = (0u32, 0usize);
            for s in model.band_strips(b) {
                slot_start.push(at);
                at += model.slot_size[s] + 1;
                let cap = segments::capacity(model.slot_size[s]);
                seg_base.push(seg_at as u32);
                seg_cap.push(cap as u32);
                seg_at += cap;
            }
            band_len.push(at);
            segments = segments.max(seg_at);
        }
        let total = band_len.iter().copied().max().unwrap_or(0) as usize;
        let widest = model.slot_size.iter().copied().max().unwrap_or(0);
        let most = seg_cap.iter().copied().max().unwrap_or(0) as usize;
        Extractor {
            model,
            buffer: vec![RESTART_U32; total],
            slot_start,
            band_len,
            len: vec![0; strips],
            valid_from: vec![1; strips],
            valid_to: vec![0; strips],
            lod: None,
            band: None,
            dirty: Vec::with_capacity(strips + 1),
            used: 0,
            non_empty: 0,
            overflows: 0,
            seg_base,
            seg_cap,
            seg_len: vec![0; strips],
            seg_rec: vec![0; segments],
            seg_off: vec![0; segments],
            seg_from: vec![0; segments],
            seg_to: vec![0; segments],
            tmp: vec![0; widest as usize],
            old_rec: vec![0; most],
            old_off: vec![0; most],
            old_from: vec![0; most],
            old_to: vec![0; most],
        }
    }

    /// The model extracted from.
    #[must_use]
    pub fn model(&self) -> &'m MtsModel {
        self.model
    }

    /// Extracts `lod` (clamped to `max_lod`), re-walking only the strips
    /// whose validity interval excludes it. The output is identical to
    /// [`Extractor::set_lod_from_scratch`].
    pub fn set_lod(&mut self, lod: usize) -> Update {
        self.update(lod, true)
    }

    /// Extracts `lod` walking every strip (no coherence): the reference the
    /// coherent path is measured and tested against.
    pub fn set_lod_from_scratch(&mut self, lod: usize) -> Update {
        self.update(lod, false)
    }

    /// [`Extractor::set_lod`] at the finest LoD with at most `budget`
    /// triangles.
    pub fn set_triangles(&mut self, budget: usize) -> Update {
        self.set_lod(self.model.lod_for_triangles(budget))
    }

    /// [`Extractor::set_lod`] at `ratio` of the full triangle count.
    pub fn set_ratio(&mut self, ratio: f64) -> Update {
        self.set_lod(self.model.lod_for_ratio(ratio))
    }

    fn update(&mut self, lod: usize, coherent: bool) -> Update {
        let model = self.model;
        let lod = lod.min(model.max_lod());
        let band = model.band_of(lod);
        self.dirty.clear();
        let (mut walked, mut indices) = (0, 0);
        if let Some(old) = self.band.filter(|&b| b != band) {
            // The new band's slots take the region over: forget the old
            // band's strips, pad the region, and report it whole.
            for s in model.band_strips(old) {
                self.len[s] = 0;
                self.seg_len[s] = 0;
                self.valid_from[s] = 1;
                self.valid_to[s] = 0;
            }
            let old_len = self.band_len[old] as usize;
            self.buffer[..old_len].fill(RESTART_U32);
            self.used = 0;
            self.non_empty = 0;
            let region = old_len.max(self.band_len[band] as usize);
            if region > 0 {
                self.dirty.push(0..region);
            }
        }
        let birth = model.band_first_lod(band) as u32;
        // Within the band, a jump over more than a quarter of its LoDs
        // changes most segments: strips left valid are still skipped, the
        // others are walked whole, straight into their slots (the same
        // bytes; meeting segments would cost more than it saves).
        let span = (model
            .band_lod
            .get(band + 1)
            .map_or(model.max_lod() + 1, |&l| l as usize))
            - birth as usize;
        let near = self
            .lod
            .filter(|_| self.band == Some(band))
            .is_some_and(|old| 4 * old.abs_diff(lod) <= span);
        let mode = match (coherent, near) {
            (false, _) => Mode::Scratch,
            (true, true) => Mode::Segments,
            (true, false) => Mode::Strips,
        };
        for s in model.band_strips(band) {
            if let Some(n) = self.refresh(s, birth, lod as u32, mode) {
                walked += 1;
                indices += n;
            }
        }
        self.lod = Some(lod);
        self.band = Some(band);
        Update {
            lod,
            strips_walked: walked,
            dirty_ranges: self.dirty.len(),
            indices_walked: indices,
        }
    }

    /// Walks strip `s` at `lod` into its slot unless (in the coherent
    /// modes) its validity interval holds `lod`; in [`Mode::Segments`],
    /// only from its first segment that `lod` changes ([`segments`]).
    /// Returns the indices it walked, if it walked.
    fn refresh(&mut self, s: usize, birth: u32, lod: u32, mode: Mode) -> Option<usize> {
        if mode != Mode::Scratch && self.valid_from[s] <= lod && lod <= self.valid_to[s] {
            return None;
        }
        let coherent = mode == Mode::Segments;
        let base = self.seg_base[s] as usize;
        let segs = base..base + self.seg_cap[s] as usize;
        let n = self.seg_len[s] as usize;
        // The first segment that `lod` changes; the segments after it may
        // be met again if any of them still holds `lod`.
        let (start, old_count) = if coherent && n > 0 {
            let holds = |k: usize| self.seg_from[base + k] <= lod && lod <= self.seg_to[base + k];
            // One pass: the first changed segment, and how many after it
            // still hold. Meeting them again is worth it only if most do
            // (else walking the whole rest is cheaper than the checks).
            let (mut first, mut holding) = (None, 0);
            for k in 0..n {
                match (first, holds(k)) {
                    (None, false) => first = Some(k),
                    (Some(_), true) => holding += 1,
                    _ => {}
                }
            }
            let first = first.unwrap_or(0);
            let kept = if 2 * holding > n - first - 1 {
                base + first + 1..base + n
            } else {
                0..0
            };
            let count = kept.len();
            self.old_rec[..count].copy_from_slice(&self.seg_rec[kept.clone()]);
            self.old_off[..count].copy_from_slice(&self.seg_off[kept.clone()]);
            self.old_from[..count].copy_from_slice(&self.seg_from[kept.clone()]);
            self.old_to[..count].copy_from_slice(&self.seg_to[kept]);
            (first, count)
        } else {
            (0, 0)
        };
        let old_len = self.len[s] as usize;
        let start_at = self.slot_start[s] as usize;
        let slot = start_at..start_at + self.model.slot_size[s] as usize;
        let old = segments::Old {
            rec: &self.old_rec[..old_count],
            off: &self.old_off[..old_count],
            from: &self.old_from[..old_count],
            to: &self.old_to[..old_count],
            len: old_len,
        };
        let mut seg = segments::Segments {
            rec: &mut self.seg_rec[segs.clone()],
            off: &mut self.seg_off[segs.clone()],
            from: &mut self.seg_from[segs.clone()],
            to: &mut self.seg_to[segs],
        };
        let strip = segments::Strip {
            model: self.model,
            s,
            birth,
            lod,
            start,
        };
        let (out, tmp) = (&mut self.buffer[slot], &mut self.tmp[..]);
        let w = with_widths!(&self.model.rec_vertex, &self.model.rec_label, |v, l| {
            segments::rewalk(&strip, v, l, out, tmp, &mut seg, &old)
        });
        self.overflows += usize::from(w.overflow);
        self.seg_len[s] = w.segments as u32;
        let (from, to) = segments::interval(
            &self.seg_from[base..base + w.segments],
            &self.seg_to[base..base + w.segments],
        );
        self.valid_from[s] = from;
        self.valid_to[s] = to;
        self.set_len(s, w.len, w.dirty);
        Some(w.walked)
    }

    /// Records that strip `s` now uses `new` indices of its slot: pads what
    /// it no longer uses and reports the slot's part `dirty` (offsets in
    /// the slot), with the padding, as dirty.
    fn set_len(&mut self, s: usize, new: usize, dirty: (usize, usize)) {
        let start = self.slot_start[s] as usize;
        let old = self.len[s] as usize;
        if old > new {
            self.buffer[start + new..start + old].fill(RESTART_U32);
        }
        self.used = self.used + new - old;
        self.non_empty = self.non_empty + usize::from(new > 0) - usize::from(old > 0);
        self.len[s] = new as u32;
        // `dirty` covers the padding: a walk that shrank the strip reports
        // up to its old length.
        let (lo, hi) = dirty;
        debug_assert!(old <= new || hi >= old);
        if hi > lo {
            let range = start + lo..start + hi;
            match self.dirty.last_mut() {
                Some(last) if last.end + 1 >= range.start && last.start <= range.start => {
                    last.end = last.end.max(range.end);
                }
                _ => self.dirty.push(range),
            }
        }
    }

    /// The LoD last extracted, if any.
    #[must_use]
    pub fn lod(&self) -> Option<usize> {
        self.lod
    }

    /// The part of [`Extractor::buffer`] holding the current band's slots
    /// (it starts at 0): everything after it is restart values, so a
    /// renderer may draw only this range.
    #[must_use]
    pub fn active_range(&self) -> Range<usize> {
        match self.band {
            Some(b) => 0..self.band_len[b] as usize,
            None => 0..0,
        }
    }

    /// The slot-laid index buffer (restart value [`RESTART_U32`]).
    #[must_use]
    pub fn buffer(&self) -> &[u32] {
        &self.buffer
    }

    /// Index ranges of [`Extractor::buffer`] rewritten by the last call,
    /// ascending and disjoint (adjacent slots merged).
    #[must_use]
    pub fn dirty_ranges(&self) -> &[Range<usize>] {
        &self.dirty
    }

    /// The current strip sequence of strip `s` (its run breaks included).
    #[must_use]
    pub fn strip(&self, s: usize) -> &[u32] {
        let start = self.slot_start[s] as usize;
        &self.buffer[start..start + self.len[s] as usize]
    }

    /// Indices a compact restart-encoded buffer of the current LoD holds:
    /// every strip's sequence, one restart between non-empty strips.
    #[must_use]
    pub fn indices_sent(&self) -> usize {
        self.used + self.non_empty.saturating_sub(1)
    }

    /// Bytes of the extractor's own arrays (the index buffer, per-strip
    /// state, segments and scratch), not counting the model.
    #[must_use]
    pub fn memory_bytes(&self) -> usize {
        let words = self.buffer.len()
            + self.slot_start.len()
            + self.band_len.len()
            + self.len.len()
            + self.valid_from.len()
            + self.valid_to.len()
            + self.seg_base.len()
            + self.seg_cap.len()
            + self.seg_len.len()
            + self.seg_rec.len()
            + self.seg_off.len()
            + self.seg_from.len()
            + self.seg_to.len()
            + self.tmp.len()
            + self.old_rec.len()
            + self.old_off.len()
            + self.old_from.len()
            + self.old_to.len();
        4 * words + std::mem::size_of::<Range<usize>>() * self.dirty.capacity()
    }

    /// Strip walks that hit the end of their slot and were cut (always 0
    /// for a model from [`super::build`]; a corrupt file can cause it).
    #[must_use]
    pub fn overflows(&self) -> usize {
        self.overflows
    }

    /// Writes the current LoD without padding into `out` (cleared first):
    /// [`Extractor::indices_sent`] indices.
    pub fn write_compact(&self, out: &mut Vec<u32>) {
        out.clear();
        for s in 0..self.len.len() {
            if self.len[s] > 0 {
                if !out.is_empty() {
                    out.push(RESTART_U32);
                }
                out.extend_from_slice(self.strip(s));
            }
        }
    }

    /// The oriented triangles the buffer draws, strip by strip
    /// (degenerates skipped, odd triangles flipped).
    #[must_use]
    pub fn triangles(&self) -> Vec<[u32; 3]> {
        let mut out = Vec::new();
        crate::encoding::decode_restart_buffer(&self.buffer, &mut out);
        out
    }
}

/// Walks strip `s` (of a band born at LoD `birth`) at LoD `lod` into
/// `out` (Fig. 5 of the paper), tracking the validity interval: the largest
/// label skipped bounds it below, the smallest label taken above.
pub(crate) fn walk(model: &MtsModel, s: usize, birth: u32, lod: u32, out: &mut [u32]) -> Walk {
    with_widths!(&model.rec_vertex, &model.rec_label, |v, l| {
        walk_records(model, v, l, s, birth, lod, out)
    })
}

fn walk_records<V: Word, L: Word>(
    model: &MtsModel,
    vertex: &[V],
    label: &[L],
    s: usize,
    birth: u32,
    lod: u32,
    out: &mut [u32],
) -> Walk {
    let mut w = Walk {
        len: 0,
        from: 0,
        to: model.max_lod() as u32,
        overflow: false,
    };
    let begins = model.begins_of(s);
    let mut b = begins.start;
    while b < begins.end && model.begin_res[b] < lod {
        w.from = w.from.max(model.begin_res[b] + 1);
        b += 1;
    }
    if b == begins.end {
        return w;
    }
    w.to = w.to.min(model.begin_res[b]);
    let node = model.begin_node[b];
    if node == END {
        return w;
    }
    // The beginnings put `lod` inside the band, so labels compare relative
    // to its first LoD.
    let rel = lod.saturating_sub(birth);
    let code = &model.rec_code[..];
    let mut len = 0usize;
    let mut r = node as usize;
    loop {
        if len >= out.len() {
            w.overflow = true;
            break;
        }
        out[len] = vertex[r].get();
        len += 1;
        let mut interval = (w.from, w.to);
        let next = step(code, label, &model.far, r, rel, birth, &mut interval);
        (w.from, w.to) = interval;
        let Some((next, run_break)) = next else {
            break;
        };
        if run_break {
            if len >= out.len() {
                w.overflow = true;
                break;
            }
            out[len] = RESTART_U32;
            len += 1;
        }
        r = next;
    }
    w.len = len as u32;
    w
}

/// MTS as one of the [`LodSource`](crate::lod::LodSource)s the CLI, the benches and the renderer
/// treat alike.
impl crate::lod::LodSource for Extractor<'_> {
    fn name(&self) -> &'static str {
        "mts"
    }

    fn max_lod(&self) -> usize {
        self.model().max_lod()
    }

    fn triangle_count(&self, lod: usize) -> usize {
        self.model().triangle_count(lod.min(self.model().max_lod()))
    }

    fn positions(&self) -> &[glam::Vec3] {
        self.model().positions()
    }

    fn properties(&self) -> &crate::mesh::Properties {
        self.model().properties()
    }

    fn topology(&self) -> crate::lod::Topology {
        crate::lod::Topology::StripRestart
    }

    /// The coherent walk of [`Extractor::set_lod`].
    fn set_lod(&mut self, lod: usize) -> usize {
        Extractor::set_lod(self, lod).lod
    }

    fn lod(&self) -> Option<usize> {
        Extractor::lod(self)
    }

    fn indices(&self) -> &[u32] {
        self.buffer()
    }

    fn dirty_ranges(&self) -> &[Range<usize>] {
        Extractor::dirty_ranges(self)
    }

    fn memory_bytes(&self) -> usize {
        self.model().stats().memory_bytes + Extractor::memory_bytes(self)
    }

    /// Serializes the model as `mts build` writes it (coded, version 5, at
    /// [`crate::model::compress::DEFAULT_LEVEL`]; O(model), about a second
    /// on the bunny).
    fn file_bytes(&self) -> usize {
        self.model()
            .to_compressed_bytes(crate::model::compress::DEFAULT_LEVEL)
            .len()
    }

    fn triangles(&self) -> Vec<[u32; 3]> {
        Extractor::triangles(self)
    }
}
