//! What a renderer keeps of a [`Hierarchy`] between frames: one index
//! buffer in input vertex numbers that holds the current cut's strips, and
//! one coherent [`Extractor`] per group on the cut, so that a new camera
//! walks only the groups whose LoD changed and reports the index ranges it
//! rewrote.
//!
//! **Layout.** The buffer is an arena of *slots*: every drawn group owns a
//! slot as long as its extractor's buffer (its largest band), every drawn
//! cluster one as long as its strips ([`Hierarchy::cluster_strip`]). Slots
//! are separated by one restart value ([`RESTART_U32`]) and padded with
//! restarts, so the whole arena draws as one primitive-restart strip (or
//! stitched, where restarts are ignored). A group or cluster leaving the
//! cut fills its slot with restarts and returns it to a free list
//! (first fit, neighbours merged); one entering takes the first free slot
//! that fits, or grows the arena. [`ViewDependent::dirty_ranges`] lists
//! what the last [`ViewDependent::update`] wrote.
//!
//! **Culling.** With a [`Frustum`], a group or cluster whose bounding
//! sphere lies outside it is not placed in the arena; the cut itself (and
//! so every LoD) does not depend on it, so culling cannot open a crack in
//! what is visible.
//!
//! **Cost.** An update selects (O(open groups and their children), see
//! [`select_into`]), merges the new cut with the previous one (both
//! sorted), walks the extractors of groups whose LoD changed (only their
//! changed strips, [`Extractor::set_lod`]) and copies their dirty ranges,
//! mapped to input vertex numbers, into their slots. The walks and copies
//! of one update run on every core when there are enough of them (each
//! owns its extractor and its slot of the arena); the counts of indices
//! and triangles are kept as groups come, go and change, not recounted.
//! Extractors are made when a group first enters the cut and kept after
//! it leaves, so that returning costs a coherent walk, not a new
//! extractor. Along a flight the cost follows the camera's speed: on
//! `terrain:4M` at 1 px, a crossing in 120 frames changes 290 of the
//! 1,020 drawn groups a frame, one in 3,000 frames 18
//! (`docs/experiments/hierarchy.md`, "Update time").

use super::select::{select_into, Cut, Selection};
use super::Hierarchy;
use crate::model::Extractor;
use crate::screen_error::Projection;
use crate::strip::encode::RESTART_U32;
use glam::{Mat4, Vec3, Vec4};
use std::ops::Range;

/// "No slot" in [`ViewDependent`]'s slot tables.
const NONE: u32 = u32::MAX;

/// Groups to walk in one update from which the walks go on every core
/// (below it, a thread's start costs more than it saves: a group walks in
/// about 10 µs).
const PARALLEL_WALKS: usize = 24;

/// One group's walk in [`ViewDependent::update`].
#[derive(Debug)]
struct Walk<'h> {
    group: u32,
    lod: u32,
    /// Whether the group enters the drawn set (else it changes LoD).
    entering: bool,
    /// Its slot in the arena (`len`: its extractor's buffer).
    start: usize,
    len: usize,
    extractor: Extractor<'h>,
    walked: usize,
    /// Indices its drawn LoD sent before the walk (0 when entering).
    indices_before: usize,
}

/// The six planes of a view frustum, inward normals (`n·p + d ≥ 0`
/// inside), from a view-projection matrix with wgpu's clip space (`z` in
/// 0..1).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Frustum {
    planes: [Vec4; 6],
}

impl Frustum {
    /// The frustum of `view_projection` (Gribb and Hartmann's extraction,
    /// planes normalized).
    #[must_use]
    pub fn from_view_projection(view_projection: Mat4) -> Frustum {
        let m = view_projection.transpose();
        let (r0, r1, r2, r3) = (m.x_axis, m.y_axis, m.z_axis, m.w_axis);
        let planes = [r3 + r0, r3 - r0, r3 + r1, r3 - r1, r2, r3 - r2].map(|p| {
            let len = p.truncate().length();
            if len > 0.0 && len.is_finite() {
                p / len
            } else {
                p
            }
        });
        Frustum { planes }
    }

    /// Whether a sphere may be seen: false only when it lies wholly
    /// outside one plane.
    #[must_use]
    pub fn may_see(&self, centre: Vec3, radius: f32) -> bool {
        self.planes
            .iter()
            .all(|p| p.truncate().dot(centre) + p.w >= -radius)
    }
}

/// A camera as [`ViewDependent::update`] takes it.
#[derive(Debug, Clone, Copy)]
pub struct View {
    /// How model units project to pixels.
    pub projection: Projection,
    /// The eye, in model coordinates.
    pub eye: Vec3,
    /// The largest projected error drawn, in pixels.
    pub pixel_threshold: f32,
    /// What is visible; `None` draws every group and cluster of the cut.
    pub frustum: Option<Frustum>,
}

/// What one [`ViewDependent::update`] did.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct FrameUpdate {
    /// Groups drawn through their models, and clusters drawn as they are
    /// (culled ones excluded).
    pub groups_drawn: usize,
    /// See [`FrameUpdate::groups_drawn`].
    pub clusters_drawn: usize,
    /// Groups that entered the drawn set, left it, or changed LoD on it.
    pub groups_entered: usize,
    /// See [`FrameUpdate::groups_entered`].
    pub groups_left: usize,
    /// See [`FrameUpdate::groups_entered`].
    pub groups_changed: usize,
    /// Clusters that entered or left the drawn set.
    pub clusters_entered: usize,
    /// See [`FrameUpdate::clusters_entered`].
    pub clusters_left: usize,
    /// Strips the groups' extractors walked.
    pub strips_walked: usize,
    /// Indices written into the arena (the dirty ranges' total length).
    pub indices_written: usize,
}

/// The index buffer of a [`Hierarchy`]'s cut, kept up to date camera after
/// camera (see the module documentation).
#[derive(Debug)]
pub struct ViewDependent<'h> {
    h: &'h Hierarchy,
    selection: Selection,
    cut: Cut,
    /// Per group: its extractor once it has been drawn.
    extractors: Vec<Option<Extractor<'h>>>,
    /// Per group and per cluster: its slot's start in `buffer` ([`NONE`]
    /// when not drawn), and for groups the LoD drawn.
    group_slot: Vec<u32>,
    group_lod: Vec<u32>,
    cluster_slot: Vec<u32>,
    /// Drawn groups and clusters, ascending (culled ones left out).
    drawn_groups: Vec<u32>,
    drawn_clusters: Vec<u32>,
    next_groups: Vec<u32>,
    next_clusters: Vec<u32>,
    /// The LoDs of `next_groups` (scratch).
    lods: Vec<u32>,
    /// Groups to walk this update (scratch): group, LoD, its extractor
    /// taken out of `extractors` while it walks, the strips it walked.
    walks: Vec<Walk<'h>>,
    buffer: Vec<u32>,
    /// Free slots (start, length including the separating restart),
    /// ascending by start, none adjacent.
    free: Vec<(u32, u32)>,
    dirty: Vec<Range<usize>>,
    /// Indices of the drawn strips without padding, and their triangles.
    indices_sent: usize,
    triangles: usize,
}

impl<'h> ViewDependent<'h> {
    /// Nothing drawn yet: the first [`ViewDependent::update`] fills the
    /// arena.
    #[must_use]
    pub fn new(h: &'h Hierarchy) -> ViewDependent<'h> {
        let (ng, nc) = (h.groups.len(), h.clusters.len());
        ViewDependent {
            h,
            selection: Selection::default(),
            cut: Cut::default(),
            extractors: (0..ng).map(|_| None).collect(),
            group_slot: vec![NONE; ng],
            group_lod: vec![NONE; ng],
            cluster_slot: vec![NONE; nc],
            drawn_groups: Vec::new(),
            drawn_clusters: Vec::new(),
            next_groups: Vec::new(),
            next_clusters: Vec::new(),
            lods: Vec::new(),
            walks: Vec::new(),
            buffer: Vec::new(),
            free: Vec::new(),
            dirty: Vec::new(),
            indices_sent: 0,
            triangles: 0,
        }
    }

    /// The hierarchy drawn.
    #[must_use]
    pub fn hierarchy(&self) -> &'h Hierarchy {
        self.h
    }

    /// Selects the cut for `view` and brings the arena to it.
    pub fn update(&mut self, view: &View) -> FrameUpdate {
        let h = self.h;
        self.dirty.clear();
        select_into(
            h,
            &view.projection,
            view.eye,
            view.pixel_threshold,
            &mut self.selection,
            &mut self.cut,
        );
        let visible = |centre: Vec3, radius: f32| {
            view.frustum
                .as_ref()
                .is_none_or(|f| f.may_see(centre, radius))
        };
        let mut next_groups = std::mem::take(&mut self.next_groups);
        let mut next_clusters = std::mem::take(&mut self.next_clusters);
        next_groups.clear();
        next_clusters.clear();
        let mut lods = std::mem::take(&mut self.lods);
        lods.clear();
        for &(g, lod) in &self.cut.groups {
            let group = &h.groups[g as usize];
            if visible(group.centre, group.radius) {
                next_groups.push(g);
                lods.push(lod);
            }
        }
        for &c in &self.cut.clusters {
            // A cluster lies within its producer's sphere.
            let producer = &h.groups[h.clusters[c as usize].producer as usize];
            if visible(producer.centre, producer.radius) {
                next_clusters.push(c);
            }
        }
        let mut update = FrameUpdate {
            groups_drawn: next_groups.len(),
            clusters_drawn: next_clusters.len(),
            ..FrameUpdate::default()
        };
        // Leaving first, so that their slots can be taken by those entering.
        let previous = std::mem::take(&mut self.drawn_groups);
        for_missing(&previous, &next_groups, |g| {
            self.release_group(g);
            update.groups_left += 1;
        });
        let previous_clusters = std::mem::take(&mut self.drawn_clusters);
        for_missing(&previous_clusters, &next_clusters, |c| {
            self.release_cluster(c);
            update.clusters_left += 1;
        });
        // Groups entering or changing LoD walk their extractors and copy
        // what changed into their slots, on every core: each walk owns its
        // extractor and its slot. Entering groups take their slots first,
        // in group order.
        let mut walks = std::mem::take(&mut self.walks);
        walks.clear();
        for (&g, &lod) in next_groups.iter().zip(&lods) {
            let gi = g as usize;
            let entering = self.group_slot[gi] == NONE;
            if !entering && self.group_lod[gi] == lod {
                continue;
            }
            let model = &h.groups[gi].model;
            let extractor = self.extractors[gi]
                .take()
                .unwrap_or_else(|| Extractor::new(model));
            let len = extractor.buffer().len();
            let (start, indices_before) = if entering {
                let start = allocate(&mut self.free, &mut self.buffer, len + 1);
                (start, 0)
            } else {
                (self.group_slot[gi] as usize, extractor.indices_sent())
            };
            walks.push(Walk {
                group: g,
                lod,
                entering,
                start,
                len,
                extractor,
                walked: 0,
                indices_before,
            });
        }
        walks.sort_unstable_by_key(|w| w.start);
        let mut jobs: Vec<(&mut Walk<'h>, &mut [u32])> = Vec::with_capacity(walks.len());
        let (mut rest, mut offset) = (&mut self.buffer[..], 0);
        for w in &mut walks {
            let (_, tail) = std::mem::take(&mut rest).split_at_mut(w.start - offset);
            let (slot, tail) = tail.split_at_mut(w.len);
            (rest, offset) = (tail, w.start + w.len);
            jobs.push((w, slot));
        }
        crate::parallel::for_each_mut(&mut jobs, PARALLEL_WALKS, 8, |(w, slot)| {
            let vertices = &h.groups[w.group as usize].vertices;
            let e = &mut w.extractor;
            w.walked = e.set_lod(w.lod as usize).strips_walked;
            if w.entering {
                let active = e.active_range();
                copy_mapped(&mut slot[active.clone()], &e.buffer()[active], vertices);
            } else {
                for r in e.dirty_ranges() {
                    copy_mapped(&mut slot[r.clone()], &e.buffer()[r.clone()], vertices);
                }
            }
        });
        drop(jobs);
        walks.sort_unstable_by_key(|w| w.group);
        for w in walks.drain(..) {
            update.strips_walked += w.walked;
            if w.entering {
                update.groups_entered += 1;
            } else {
                update.groups_changed += 1;
            }
            self.landed(w);
        }
        self.walks = walks;
        for &c in &next_clusters {
            if self.cluster_slot[c as usize] == NONE {
                update.clusters_entered += 1;
                self.place_cluster(c);
            }
        }
        self.next_groups = previous;
        self.next_clusters = previous_clusters;
        self.drawn_groups = next_groups;
        self.drawn_clusters = next_clusters;
        self.lods = lods;
        let len = self.buffer.len();
        self.dirty.retain_mut(|r| {
            r.end = r.end.min(len);
            r.start < r.end
        });
        #[cfg(debug_assertions)]
        self.check_counts();
        update.indices_written = self.dirty.iter().map(Range::len).sum();
        update
    }

    /// The arena: the cut's strips in input vertex numbers, runs and slots
    /// separated by [`RESTART_U32`]. Draw all of it.
    #[must_use]
    pub fn buffer(&self) -> &[u32] {
        &self.buffer
    }

    /// The ranges of [`ViewDependent::buffer`] the last update wrote (the
    /// arena may also have shrunk or grown: compare its length).
    #[must_use]
    pub fn dirty_ranges(&self) -> &[Range<usize>] {
        &self.dirty
    }

    /// The last cut selected (culled groups and clusters included).
    #[must_use]
    pub fn cut(&self) -> &Cut {
        &self.cut
    }

    /// Indices the drawn strips send without the arena's padding: each
    /// group's [`Extractor::indices_sent`] and each cluster's strips.
    #[must_use]
    pub fn indices_sent(&self) -> usize {
        self.indices_sent
    }

    /// Triangles drawn (culled groups and clusters left out).
    #[must_use]
    pub fn triangle_count(&self) -> usize {
        self.triangles
    }

    /// The drawn triangles, decoded from the arena: the oracle of tests,
    /// not a renderer's path. O(arena).
    #[must_use]
    pub fn triangles(&self) -> Vec<[u32; 3]> {
        let mut out = Vec::with_capacity(self.triangles);
        for run in self.buffer.split(|&v| v == RESTART_U32) {
            crate::encoding::decode_run(run, &mut out);
        }
        out
    }

    /// Bytes held: the arena, the slot tables and every extractor made.
    #[must_use]
    pub fn memory_bytes(&self) -> usize {
        let extractors: usize = self
            .extractors
            .iter()
            .flatten()
            .map(Extractor::memory_bytes)
            .sum();
        extractors
            + 4 * (self.buffer.capacity()
                + self.group_slot.len()
                + self.group_lod.len()
                + self.cluster_slot.len())
            + 8 * self.free.capacity()
    }

    /// Checks the running counts against a recount of what is drawn.
    #[cfg(debug_assertions)]
    fn check_counts(&self) {
        let h = self.h;
        let (mut indices, mut triangles) = (0, 0);
        for &g in &self.drawn_groups {
            if let Some(e) = &self.extractors[g as usize] {
                indices += e.indices_sent();
                triangles += self.group_triangles(g, self.group_lod[g as usize]);
            }
        }
        for &c in &self.drawn_clusters {
            indices += h.cluster_strip(c as usize).len();
            triangles += h.cluster_triangle_count(c as usize);
        }
        debug_assert_eq!((indices, triangles), (self.indices_sent, self.triangles));
    }

    /// Triangles group `g` draws at `lod`.
    fn group_triangles(&self, g: u32, lod: u32) -> usize {
        self.h.groups[g as usize].model.triangle_count(lod as usize)
    }

    /// Records walk `w`, its indices copied into its slot: the dirty
    /// ranges (a new slot whole, with its separating restart: a GPU buffer
    /// may hold anything there after the arena shrank and grew again), the
    /// counts, the slot and LoD; the extractor goes back to its place.
    fn landed(&mut self, w: Walk<'h>) {
        let g = w.group as usize;
        let e = w.extractor;
        if w.entering {
            self.dirty.push(w.start..w.start + w.len + 1);
            self.group_slot[g] = w.start as u32;
        } else {
            let s = w.start;
            self.dirty
                .extend(e.dirty_ranges().iter().map(|r| s + r.start..s + r.end));
            self.triangles -= self.group_triangles(w.group, self.group_lod[g]);
        }
        self.indices_sent = self.indices_sent + e.indices_sent() - w.indices_before;
        self.triangles += self.group_triangles(w.group, w.lod);
        self.group_lod[g] = w.lod;
        self.extractors[g] = Some(e);
    }

    fn release_group(&mut self, g: u32) {
        let start = self.group_slot[g as usize];
        let lod = self.group_lod[g as usize];
        self.group_slot[g as usize] = NONE;
        self.group_lod[g as usize] = NONE;
        if let Some(e) = &self.extractors[g as usize] {
            let (len, indices) = (e.buffer().len(), e.indices_sent());
            self.indices_sent -= indices;
            self.triangles -= self.group_triangles(g, lod);
            self.release(start as usize, len + 1);
        }
    }

    fn place_cluster(&mut self, c: u32) {
        let strip = self.h.cluster_strip(c as usize);
        let start = allocate(&mut self.free, &mut self.buffer, strip.len() + 1);
        self.buffer[start..start + strip.len()].copy_from_slice(strip);
        self.dirty.push(start..start + strip.len() + 1);
        self.cluster_slot[c as usize] = start as u32;
        self.indices_sent += strip.len();
        self.triangles += self.h.cluster_triangle_count(c as usize);
    }

    fn release_cluster(&mut self, c: u32) {
        let start = self.cluster_slot[c as usize];
        self.cluster_slot[c as usize] = NONE;
        let len = self.h.cluster_strip(c as usize).len();
        self.indices_sent -= len;
        self.triangles -= self.h.cluster_triangle_count(c as usize);
        self.release(start as usize, len + 1);
    }

    /// Fills slot `start..start + len` with restarts and frees it.
    fn release(&mut self, start: usize, len: usize) {
        self.buffer[start..start + len].fill(RESTART_U32);
        self.dirty.push(start..start + len);
        let (mut s, mut l) = (start as u32, len as u32);
        let i = self.free.partition_point(|&(fs, _)| fs < s);
        // Merge with the next free slot, then the previous one.
        if i < self.free.len() && self.free[i].0 == s + l {
            l += self.free[i].1;
            self.free.remove(i);
        }
        if i > 0 && self.free[i - 1].0 + self.free[i - 1].1 == s {
            s = self.free[i - 1].0;
            l += self.free[i - 1].1;
            self.free.remove(i - 1);
            self.free.insert(i - 1, (s, l));
        } else {
            self.free.insert(i, (s, l));
        }
        // A free slot at the end shrinks the arena.
        if let Some(&(fs, fl)) = self.free.last() {
            if (fs + fl) as usize == self.buffer.len() {
                self.free.pop();
                self.buffer.truncate(fs as usize);
            }
        }
    }
}

/// Writes `source` (a group's extractor indices) into `target` in input
/// vertex numbers: restarts stay, model vertex `v` becomes `vertices[v]`.
fn copy_mapped(target: &mut [u32], source: &[u32], vertices: &[u32]) {
    for (t, &v) in target.iter_mut().zip(source) {
        *t = if v == RESTART_U32 {
            RESTART_U32
        } else {
            vertices[v as usize]
        };
    }
}

/// A slot of `len` indices (all restarts): the first free one that
/// fits, else the arena's end.
fn allocate(free: &mut Vec<(u32, u32)>, buffer: &mut Vec<u32>, len: usize) -> usize {
    if let Some(i) = free.iter().position(|&(_, l)| l as usize >= len) {
        let (start, l) = free[i];
        if l as usize == len {
            free.remove(i);
        } else {
            free[i] = (start + len as u32, l - len as u32);
        }
        return start as usize;
    }
    let start = buffer.len();
    buffer.resize(start + len, RESTART_U32);
    start
}

/// Calls `f` on every element of `old` not in `new` (both ascending).
fn for_missing(old: &[u32], new: &[u32], mut f: impl FnMut(u32)) {
    let mut j = 0;
    for &x in old {
        while j < new.len() && new[j] < x {
            j += 1;
        }
        if j >= new.len() || new[j] != x {
            f(x);
        }
    }
}
