//! Vertex → triangle lists ("fans") in one flat array.
//!
//! The contraction loop reads the fans of a handful of vertices per step
//! and merges two of them. A `Vec` per vertex puts every list behind its
//! own pointer, so each read waits for the header and then for the list:
//! here a vertex's `Span` (start, length, capacity) indexes one shared
//! `items` array, the lists of nearby vertices start out next to each other,
//! and no list is allocated on its own.
//!
//! A list that outgrows its block moves to the end of `items` (or into the
//! merged list's block when that is larger); the blocks left behind are
//! garbage, and `items` is compacted once the garbage outweighs the live
//! blocks, so it stays within about twice the live capacity (amortised
//! O(1) per item moved). Relocated blocks get half their length again as
//! room, so a growing list moves O(log) times.
//!
//! A wide fan (more than [`WIDE`] triangles: a dense or non-manifold input,
//! thousands of triangles over a few hundred vertices) also gets a
//! [`Star`]: its distinct neighbours and the triangles on each edge, built
//! once per change of the fan instead of scanned per question. The guards
//! and the choices ask such a vertex a question per neighbour, and a scan
//! of the fan per question made them cost the fan's width times its
//! valence (20,000 random triangles over 256 vertices: 12 s, now 0.14 s;
//! `docs/experiments/simplify-dense.md`).

/// Where a vertex's list lies in [`Fans::items`].
#[derive(Clone, Copy, Default)]
struct Span {
    start: u32,
    len: u32,
    cap: u32,
}

/// For each vertex, a list of triangle indices (the triangles that use it,
/// in increasing order at construction). Lists keep their order through
/// [`Fans::retain`] and [`Fans::move_into`].
pub(crate) struct Fans {
    spans: Vec<Span>,
    items: Vec<u32>,
    /// Items of `items` inside no span's capacity.
    garbage: usize,
}

impl Fans {
    /// The triangles around each of `vertex_count` vertices, each list in
    /// increasing triangle order. O(V + T), one allocation of `3T` items.
    ///
    /// # Panics
    /// If a triangle names a vertex `>= vertex_count`, or `3T` exceeds
    /// `u32::MAX`.
    pub(crate) fn new(vertex_count: usize, triangles: &[[u32; 3]]) -> Fans {
        assert!(
            triangles.len() * 3 <= u32::MAX as usize,
            "too many triangles for u32 fan offsets"
        );
        let mut spans = vec![Span::default(); vertex_count];
        for t in triangles {
            for &v in t {
                spans[v as usize].cap += 1;
            }
        }
        let mut start = 0;
        for s in &mut spans {
            s.start = start;
            start += s.cap;
        }
        let mut items = vec![0u32; start as usize];
        for (i, t) in triangles.iter().enumerate() {
            for &v in t {
                let s = &mut spans[v as usize];
                items[(s.start + s.len) as usize] = i as u32;
                s.len += 1;
            }
        }
        Fans {
            spans,
            items,
            garbage: 0,
        }
    }

    /// Number of vertices (lists).
    pub(crate) fn vertex_count(&self) -> usize {
        self.spans.len()
    }

    /// The list of `v`.
    #[inline]
    pub(crate) fn get(&self, v: u32) -> &[u32] {
        let s = self.spans[v as usize];
        &self.items[s.start as usize..(s.start + s.len) as usize]
    }

    /// Asks the cache for `v`'s span (not its items: their address is in
    /// the span).
    #[inline]
    pub(crate) fn prefetch_span(&self, v: u32) {
        super::prefetch(&self.spans[v as usize]);
    }

    /// Adds a vertex with an empty list; returns its index.
    pub(crate) fn push_vertex(&mut self) -> u32 {
        self.spans.push(Span::default());
        (self.spans.len() - 1) as u32
    }

    /// Keeps the items of `v`'s list for which `keep` holds, in order.
    /// Allocation-free.
    #[inline]
    pub(crate) fn retain(&mut self, v: u32, mut keep: impl FnMut(u32) -> bool) {
        let s = &mut self.spans[v as usize];
        let block = &mut self.items[s.start as usize..(s.start + s.len) as usize];
        let mut kept = 0;
        for i in 0..block.len() {
            let t = block[i];
            if keep(t) {
                block[kept] = t;
                kept += 1;
            }
        }
        s.len = kept as u32;
    }

    /// Appends the items of `from`'s list for which `keep` holds to
    /// `into`'s list (in order) and empties `from`'s. `into`'s list stays
    /// in place when it has room, moves into `from`'s block when that has
    /// room, and to the end of the array otherwise (with half its length
    /// again as room to grow). O(length of both lists), amortised.
    pub(crate) fn move_into(&mut self, from: u32, into: u32, mut keep: impl FnMut(u32) -> bool) {
        debug_assert_ne!(from, into);
        // Filter `from` in place first: the room needed is then known.
        self.retain(from, &mut keep);
        let f = std::mem::take(&mut self.spans[from as usize]);
        let d = self.spans[into as usize];
        let (fs, ds) = (f.start as usize, d.start as usize);
        let (fl, dl) = (f.len as usize, d.len as usize);
        let len = (f.len + d.len) as usize;
        let merged = if len <= d.cap as usize {
            self.items.copy_within(fs..fs + fl, ds + dl);
            self.garbage += f.cap as usize;
            Span {
                len: len as u32,
                ..d
            }
        } else if len <= f.cap as usize {
            self.items.copy_within(fs..fs + fl, fs + dl);
            self.items.copy_within(ds..ds + dl, fs);
            self.garbage += d.cap as usize;
            Span {
                len: len as u32,
                ..f
            }
        } else {
            self.garbage += (f.cap + d.cap) as usize;
            let start = self.items.len();
            let cap = len + len / 2;
            assert!(start + cap <= u32::MAX as usize, "fan array overflow");
            self.items.extend_from_within(ds..ds + dl);
            self.items.extend_from_within(fs..fs + fl);
            self.items.resize(start + cap, 0);
            Span {
                start: start as u32,
                len: len as u32,
                cap: cap as u32,
            }
        };
        self.spans[into as usize] = merged;
        if self.garbage > self.items.len() / 2 {
            self.compact();
        }
    }

    /// Moves every list to the front of a fresh array, in vertex order,
    /// keeping each one's capacity. O(live capacity).
    fn compact(&mut self) {
        let live: usize = self.spans.iter().map(|s| s.cap as usize).sum();
        let mut items = Vec::with_capacity(live);
        for s in &mut self.spans {
            let start = items.len();
            items.extend_from_slice(&self.items[s.start as usize..(s.start + s.cap) as usize]);
            s.start = start as u32;
        }
        self.items = items;
        self.garbage = 0;
    }
}

/// Fans of more than this many triangles are read through their [`Star`].
/// Ordinary meshes stay below it (the icosphere's fans hold 6 triangles)
/// but for a few survivors late in the sequence (fandisk's, teapot's), so
/// their loop is the scan it always was; at this width building a star
/// costs about what one scan of the fan does. Either way the answers are
/// the same (`contract::tests::stars_answer_as_the_scans_do`).
pub(crate) const WIDE: usize = 32;

/// "No star" in [`Stars::slot`], and not yet placed in [`Stars::place`].
const NO_STAR: u32 = u32::MAX;

/// The live neighbours of one vertex `v` as its fan stood when the star
/// was built: each distinct neighbour, and the triangles on the edge to it
/// by their third corners.
#[derive(Default)]
pub(crate) struct Star {
    /// Whether the fan is as it was at the build ([`Stars::invalidate`]
    /// clears it when a contraction changes a triangle of the fan).
    current: bool,
    /// Distinct neighbours in the order a scan of the fan meets them
    /// (triangle by triangle, corner by corner).
    order: Vec<u32>,
    /// `(neighbour w, end)` sorted by neighbour: the live triangles on edge
    /// `(v, w)` are `(v, w, x)` for `x` in `thirds[previous end..end]`.
    edges: Vec<(u32, u32)>,
    /// Third corners of the triangles on each edge, sorted within each
    /// edge's run (a third corner repeats once per triangle).
    thirds: Vec<u32>,
    /// Some edge holds other than two triangles.
    border: bool,
    /// Some edge holds one triangle, or four or more.
    slides: bool,
    /// The neighbours as the contractor ranks them, `(cost, neighbour)`:
    /// its to fill once per build (`ranked` false until then). They stay
    /// valid as long as the star, since nothing else changes a cost.
    pub(crate) ranking: Vec<(f64, u32)>,
    pub(crate) ranked: bool,
}

impl Star {
    /// Distinct neighbours, in the order a scan of the fan meets them.
    pub(crate) fn neighbours(&self) -> &[u32] {
        &self.order
    }

    /// `(w, third corners)` per neighbour `w`, by increasing `w`: the
    /// triangles on edge `(v, w)`, each by its third corner (sorted).
    pub(crate) fn edges(&self) -> impl Iterator<Item = (u32, &[u32])> + '_ {
        let mut start = 0;
        self.edges.iter().map(move |&(w, end)| {
            let thirds = &self.thirds[start as usize..end as usize];
            start = end;
            (w, thirds)
        })
    }

    /// Third corners of the live triangles on edge `(v, w)`, sorted
    /// (empty when `w` is no neighbour). O(log valence).
    pub(crate) fn thirds(&self, w: u32) -> &[u32] {
        let i = self.edges.partition_point(|&(x, _)| x < w);
        match self.edges.get(i) {
            Some(&(x, end)) if x == w => {
                let start = if i == 0 { 0 } else { self.edges[i - 1].1 };
                &self.thirds[start as usize..end as usize]
            }
            _ => &[],
        }
    }

    /// Live triangles on edge `(v, w)`. O(log valence).
    pub(crate) fn count(&self, w: u32) -> usize {
        self.thirds(w).len()
    }

    /// Whether some edge holds other than two triangles.
    pub(crate) fn border(&self) -> bool {
        self.border
    }

    /// Whether some edge holds one triangle, or four or more.
    pub(crate) fn slides(&self) -> bool {
        self.slides
    }
}

/// The [`Star`]s of the vertices that needed one. Nothing is allocated
/// until the first star is built, so a mesh without wide fans pays a
/// length test per question and nothing else.
pub(crate) struct Stars {
    vertex_count: usize,
    /// Each vertex's index in `stars` ([`NO_STAR`] for none); empty until
    /// the first star.
    slot: Vec<u32>,
    stars: Vec<Star>,
    /// Scratch of [`Stars::update`]: a neighbour's index in the star being
    /// built, valid where `order` holds the neighbour back (a sparse set:
    /// never cleared).
    place: Vec<u32>,
    /// Scratch of [`Stars::update`]: per neighbour of the star being built,
    /// its count, then its next free place in `thirds`.
    cursor: Vec<u32>,
    /// Scratch of [`Stars::update`]: `(neighbour, third corner)` twice per
    /// triangle of the fan, so the triangles are read once.
    pairs: Vec<(u32, u32)>,
}

impl Stars {
    /// No stars, for `vertex_count` vertices.
    pub(crate) fn new(vertex_count: usize) -> Stars {
        Stars {
            vertex_count,
            slot: Vec::new(),
            stars: Vec::new(),
            place: Vec::new(),
            cursor: Vec::new(),
            pairs: Vec::new(),
        }
    }

    /// Adds a vertex without a star.
    pub(crate) fn push_vertex(&mut self) {
        self.vertex_count += 1;
        if !self.slot.is_empty() {
            self.slot.push(NO_STAR);
            self.place.push(NO_STAR);
        }
    }

    /// Whether no star was ever built (then [`Stars::invalidate`] has
    /// nothing to do).
    #[inline]
    pub(crate) fn is_empty(&self) -> bool {
        self.stars.is_empty()
    }

    /// `v`'s star if it is current.
    #[inline]
    pub(crate) fn get(&self, v: u32) -> Option<&Star> {
        let s = *self.slot.get(v as usize)?;
        self.stars.get(s as usize).filter(|star| star.current)
    }

    /// `v`'s star, which [`Stars::update`] made current.
    ///
    /// # Panics
    /// If it is not current.
    pub(crate) fn current(&self, v: u32) -> &Star {
        self.get(v).expect("the star was updated before it is read")
    }

    /// [`Stars::current`], to write its ranking.
    ///
    /// # Panics
    /// If it is not current.
    pub(crate) fn current_mut(&mut self, v: u32) -> &mut Star {
        let s = self.slot.get(v as usize).copied().unwrap_or(NO_STAR);
        self.stars
            .get_mut(s as usize)
            .filter(|star| star.current)
            .expect("the star was updated before it is read")
    }

    /// Marks `v`'s star out of date: call it for every vertex a triangle
    /// of whose fan changes (its corners, or its death).
    #[inline]
    pub(crate) fn invalidate(&mut self, v: u32) {
        if let Some(&s) = self.slot.get(v as usize) {
            if let Some(star) = self.stars.get_mut(s as usize) {
                star.current = false;
            }
        }
    }

    /// Makes `v`'s star current: drops from `v`'s list the triangles for
    /// which `live` fails (as [`Fans::retain`]) and, unless the star is
    /// current already (then no triangle of the fan died either), builds
    /// it from the rest. O(fan · log(most triangles on an edge) + valence
    /// · log valence), reading each triangle once; allocation-free once
    /// the buffers have grown.
    pub(crate) fn update(
        &mut self,
        v: u32,
        fans: &mut Fans,
        tris: &[[u32; 3]],
        live: impl FnMut(u32) -> bool,
    ) {
        if self.slot.is_empty() {
            self.slot = vec![NO_STAR; self.vertex_count];
            self.place = vec![NO_STAR; self.vertex_count];
        }
        let s = match self.slot[v as usize] {
            NO_STAR => {
                self.stars.push(Star::default());
                self.slot[v as usize] = (self.stars.len() - 1) as u32;
                self.stars.len() - 1
            }
            s => s as usize,
        };
        if self.stars[s].current {
            return;
        }
        fans.retain(v, live);
        let star = &mut self.stars[s];
        let (place, cursor, pairs) = (&mut self.place, &mut self.cursor, &mut self.pairs);
        star.order.clear();
        star.ranked = false;
        cursor.clear();
        pairs.clear();
        for &t in fans.get(v) {
            let tri = tris[t as usize];
            let k = tri.iter().position(|&w| w == v).unwrap_or(0);
            let (x, y) = (tri[(k + 1) % 3], tri[(k + 2) % 3]);
            // In corner order, as a scan meets them.
            let (first, second) = if k == 1 { (y, x) } else { (x, y) };
            for w in [first, second] {
                let i = place[w as usize];
                if star.order.get(i as usize) == Some(&w) {
                    cursor[i as usize] += 1;
                } else {
                    place[w as usize] = star.order.len() as u32;
                    star.order.push(w);
                    cursor.push(1);
                }
            }
            pairs.extend([(x, y), (y, x)]);
        }
        star.edges.clear();
        star.edges
            .extend(star.order.iter().zip(cursor.iter()).map(|(&w, &c)| (w, c)));
        star.edges.sort_unstable();
        let (mut border, mut slides, mut end) = (false, false, 0);
        for (w, count) in &mut star.edges {
            border |= *count != 2;
            slides |= *count != 2 && *count != 3;
            // Each neighbour's run starts where the previous one ends.
            cursor[place[*w as usize] as usize] = end;
            end += *count;
            *count = end;
        }
        (star.border, star.slides) = (border, slides);
        star.thirds.clear();
        star.thirds.resize(end as usize, 0);
        for &(w, x) in pairs.iter() {
            let c = &mut cursor[place[w as usize] as usize];
            star.thirds[*c as usize] = x;
            *c += 1;
        }
        let mut start = 0;
        for &(_, end) in &star.edges {
            star.thirds[start as usize..end as usize].sort_unstable();
            start = end;
        }
        star.current = true;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lists_keep_their_order_through_moves_and_compaction() {
        // Vertex 0 is in every triangle, 1..=4 in some.
        let triangles = [[0, 1, 2], [0, 2, 3], [0, 3, 4], [4, 1, 0]];
        let mut fans = Fans::new(5, &triangles);
        assert_eq!(fans.get(0), &[0, 1, 2, 3]);
        assert_eq!(fans.get(4), &[2, 3]);
        fans.retain(0, |t| t != 1);
        assert_eq!(fans.get(0), &[0, 2, 3]);
        // Into a list with room (0 lost an item): stays in place.
        fans.move_into(1, 0, |t| t == 3);
        assert_eq!(fans.get(0), &[0, 2, 3, 3]);
        assert!(fans.get(1).is_empty());
        // Into a shorter list from a longer block.
        fans.move_into(0, 2, |_| true);
        assert_eq!(fans.get(2), &[0, 1, 0, 2, 3, 3]);
        // Growth past both blocks goes to the end, and compaction (after
        // enough garbage) keeps every list.
        for v in [3, 4] {
            fans.move_into(v, 2, |_| true);
        }
        assert_eq!(fans.get(2), &[0, 1, 0, 2, 3, 3, 1, 2, 2, 3]);
        let v = fans.push_vertex();
        fans.move_into(2, v, |t| t != 0);
        assert_eq!(fans.get(v), &[1, 2, 3, 3, 1, 2, 2, 3]);
        fans.compact();
        assert_eq!(fans.get(v), &[1, 2, 3, 3, 1, 2, 2, 3]);
        assert_eq!(fans.vertex_count(), 6);
        assert!((0..5).all(|u| fans.get(u).is_empty()));
    }
}
