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
//! **Cost.** An update selects (O(groups + their input clusters), no
//! allocation once warm), merges the new cut with the previous one (both
//! sorted), walks the extractors of groups whose LoD changed (only their
//! changed strips, [`Extractor::set_lod`]) and copies their dirty ranges,
//! mapped to input vertex numbers. Extractors are made when a group first
//! enters the cut and kept after it leaves, so that returning costs a
//! coherent walk, not a new extractor.

use super::select::{select_into, Cut, Selection};
use super::Hierarchy;
use crate::model::Extractor;
use crate::screen_error::Projection;
use crate::strip::encode::RESTART_U32;
use glam::{Mat4, Vec3, Vec4};
use std::ops::Range;

/// "No slot" in [`ViewDependent`]'s slot tables.
const NONE: u32 = u32::MAX;

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
        for (&g, &lod) in next_groups.iter().zip(&lods) {
            if self.group_slot[g as usize] == NONE {
                update.groups_entered += 1;
                update.strips_walked += self.place_group(g, lod);
            } else if self.group_lod[g as usize] != lod {
                update.groups_changed += 1;
                update.strips_walked += self.walk_group(g, lod);
            }
        }
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
        self.count();
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

    /// Indices and triangles of what is drawn now.
    fn count(&mut self) {
        let h = self.h;
        let (mut indices, mut triangles) = (0, 0);
        for &g in &self.drawn_groups {
            if let Some(e) = &self.extractors[g as usize] {
                indices += e.indices_sent();
                triangles += h.groups[g as usize]
                    .model
                    .triangle_count(self.group_lod[g as usize] as usize);
            }
        }
        for &c in &self.drawn_clusters {
            indices += h.cluster_strip(c as usize).len();
            triangles += h.cluster_triangle_count(c as usize);
        }
        self.indices_sent = indices;
        self.triangles = triangles;
    }

    /// Puts group `g` at `lod` into a new slot; returns the strips walked.
    fn place_group(&mut self, g: u32, lod: u32) -> usize {
        let h = self.h;
        let group = &h.groups[g as usize];
        let extractor =
            self.extractors[g as usize].get_or_insert_with(|| Extractor::new(&group.model));
        let walked = extractor.set_lod(lod as usize).strips_walked;
        let len = extractor.buffer().len();
        let start = self.allocate(len + 1);
        let extractor = self.extractors[g as usize].as_ref().expect("made above");
        let active = extractor.active_range();
        copy_mapped(
            &mut self.buffer[start + active.start..start + active.end],
            &extractor.buffer()[active.clone()],
            &group.vertices,
        );
        // The separating restart too: a GPU buffer may hold anything there
        // after the arena shrank and grew again.
        self.dirty.push(start..start + len + 1);
        self.group_slot[g as usize] = start as u32;
        self.group_lod[g as usize] = lod;
        walked
    }

    /// Moves drawn group `g` to `lod`: a coherent walk, its dirty ranges
    /// copied. Returns the strips walked.
    fn walk_group(&mut self, g: u32, lod: u32) -> usize {
        let group = &self.h.groups[g as usize];
        let start = self.group_slot[g as usize] as usize;
        let Some(extractor) = self.extractors[g as usize].as_mut() else {
            return 0;
        };
        let walked = extractor.set_lod(lod as usize).strips_walked;
        for r in extractor.dirty_ranges() {
            copy_mapped(
                &mut self.buffer[start + r.start..start + r.end],
                &extractor.buffer()[r.clone()],
                &group.vertices,
            );
            self.dirty.push(start + r.start..start + r.end);
        }
        self.group_lod[g as usize] = lod;
        walked
    }

    fn release_group(&mut self, g: u32) {
        let start = self.group_slot[g as usize];
        self.group_slot[g as usize] = NONE;
        self.group_lod[g as usize] = NONE;
        if let Some(e) = &self.extractors[g as usize] {
            let len = e.buffer().len();
            self.release(start as usize, len + 1);
        }
    }

    fn place_cluster(&mut self, c: u32) {
        let strip = self.h.cluster_strip(c as usize);
        let start = self.allocate(strip.len() + 1);
        self.buffer[start..start + strip.len()].copy_from_slice(strip);
        self.dirty.push(start..start + strip.len() + 1);
        self.cluster_slot[c as usize] = start as u32;
    }

    fn release_cluster(&mut self, c: u32) {
        let start = self.cluster_slot[c as usize];
        self.cluster_slot[c as usize] = NONE;
        let len = self.h.cluster_strip(c as usize).len();
        self.release(start as usize, len + 1);
    }

    /// A slot of `len` indices (all restarts): the first free one that
    /// fits, else the arena's end.
    fn allocate(&mut self, len: usize) -> usize {
        if let Some(i) = self.free.iter().position(|&(_, l)| l as usize >= len) {
            let (start, l) = self.free[i];
            if l as usize == len {
                self.free.remove(i);
            } else {
                self.free[i] = (start + len as u32, l - len as u32);
            }
            return start as usize;
        }
        let start = self.buffer.len();
        self.buffer.resize(start + len, RESTART_U32);
        start
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
