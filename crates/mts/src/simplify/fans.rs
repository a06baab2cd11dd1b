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
