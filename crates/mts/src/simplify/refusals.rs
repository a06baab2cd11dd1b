//! Targets a guard refused, per vertex, in one pool.
//!
//! Refusals are rare (about one per eight contractions on the bunny) but
//! every vertex that chooses again asks whether it has any. A `Vec` per
//! vertex answers that from a 24-byte header per vertex; here it is one
//! bit per vertex (a 1M-triangle mesh's bits fit in 64 KB, so the question
//! stays in cache), a `u32` head per vertex, and the lists are linked
//! through a shared pool whose freed entries are reused, so nothing is
//! allocated per refusal.

/// End of a list.
const NIL: u32 = u32::MAX;

/// For each vertex, an unordered set of refused targets (a target may be
/// refused twice; it is then listed twice and counted twice).
pub(crate) struct Refusals {
    /// Bit `v % 64` of word `v / 64` is set when `v`'s list is not empty.
    any: Vec<u64>,
    /// First entry of each vertex's list in `pool` ([`NIL`] when empty).
    head: Vec<u32>,
    /// `(target, next entry)`; free entries are linked from `free`.
    pool: Vec<(u32, u32)>,
    free: u32,
    /// Entries in use, over all vertices.
    count: usize,
}

impl Refusals {
    /// No refusals for `vertex_count` vertices.
    pub(crate) fn new(vertex_count: usize) -> Refusals {
        Refusals {
            any: vec![0; vertex_count.div_ceil(64)],
            head: vec![NIL; vertex_count],
            pool: Vec::new(),
            free: NIL,
            count: 0,
        }
    }

    /// Adds a vertex without refusals.
    pub(crate) fn push_vertex(&mut self) {
        self.head.push(NIL);
        if self.any.len() * 64 < self.head.len() {
            self.any.push(0);
        }
    }

    /// Refusals of all vertices.
    pub(crate) fn count(&self) -> usize {
        self.count
    }

    /// Whether `v` has no refusal.
    #[inline]
    pub(crate) fn is_empty(&self, v: u32) -> bool {
        self.any[v as usize / 64] & (1 << (v % 64)) == 0
    }

    /// Whether `v`'s contraction onto `target` was refused.
    #[inline]
    pub(crate) fn contains(&self, v: u32, target: u32) -> bool {
        let mut e = self.head[v as usize];
        while e != NIL {
            let (t, next) = self.pool[e as usize];
            if t == target {
                return true;
            }
            e = next;
        }
        false
    }

    /// Calls `f` with each target refused to `v` (a target refused twice,
    /// twice). O(their number).
    #[inline]
    pub(crate) fn for_each(&self, v: u32, mut f: impl FnMut(u32)) {
        let mut e = self.head[v as usize];
        while e != NIL {
            let (t, next) = self.pool[e as usize];
            f(t);
            e = next;
        }
    }

    /// Records that `v`'s contraction onto `target` was refused.
    pub(crate) fn add(&mut self, v: u32, target: u32) {
        let entry = (target, self.head[v as usize]);
        let e = if self.free == NIL {
            self.pool.push(entry);
            (self.pool.len() - 1) as u32
        } else {
            let e = self.free;
            self.free = self.pool[e as usize].1;
            self.pool[e as usize] = entry;
            e
        };
        self.head[v as usize] = e;
        self.any[v as usize / 64] |= 1 << (v % 64);
        self.count += 1;
    }

    /// Forgets `v`'s refusals. O(their number).
    #[inline]
    pub(crate) fn forget(&mut self, v: u32) {
        if self.is_empty(v) {
            return;
        }
        self.any[v as usize / 64] &= !(1 << (v % 64));
        let mut e = std::mem::replace(&mut self.head[v as usize], NIL);
        while e != NIL {
            let next = self.pool[e as usize].1;
            self.pool[e as usize].1 = self.free;
            self.free = e;
            self.count -= 1;
            e = next;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn refusals_are_per_vertex_and_entries_are_reused() {
        let mut r = Refusals::new(3);
        r.add(0, 7);
        r.add(0, 8);
        r.add(2, 7);
        assert!(r.contains(0, 7) && r.contains(0, 8) && r.contains(2, 7));
        assert!(!r.contains(1, 7) && !r.contains(2, 8));
        assert_eq!(r.count(), 3);
        r.forget(0);
        assert!(r.is_empty(0) && !r.is_empty(2));
        assert_eq!(r.count(), 1);
        r.push_vertex();
        r.add(3, 1);
        r.add(1, 2);
        r.add(1, 5);
        assert_eq!(r.pool.len(), 4);
        assert!(r.contains(3, 1) && r.contains(1, 5) && !r.contains(3, 2));
        assert_eq!(r.count(), 4);
        r.add(1, 5);
        let mut listed = Vec::new();
        r.for_each(1, |t| listed.push(t));
        listed.sort_unstable();
        assert_eq!(listed, [2, 5, 5]);
    }
}
