//! The contraction queue: a 4-ary min-heap of packed `(cost, vertex)` keys.
//!
//! A key is 8 bytes (the cost's order-preserving bits above the vertex
//! index), so four children share half a cache line and a pop on a queue
//! that has left the cache touches about half the lines a binary heap of
//! 16-byte entries would. The target is not stored: an entry is current
//! when its cost equals the vertex's queued cost (see
//! `Contractor::queued`), and the target is read there.
//!
//! A pop on a large queue waits on one cache miss per level (its children
//! decide where to go next). The 16 grandchildren of a node are contiguous
//! and their place needs no load, so each level asks for them before it
//! compares its children, and the next level's miss overlaps this one's
//! (1M-triangle icosphere: pops were 18% of the sequence's time, nearly
//! all of it on the load of the first child).

/// Packs `cost` and `vertex` so that `u64` order is `f32::total_cmp` on
/// the cost, then the vertex index.
#[inline]
pub(crate) fn key(cost: f32, vertex: u32) -> u64 {
    (u64::from(cost_bits(cost)) << 32) | u64::from(vertex)
}

/// `cost`'s bits, mapped so that unsigned order is `f32::total_cmp`.
#[inline]
pub(crate) fn cost_bits(cost: f32) -> u32 {
    let b = cost.to_bits();
    if b >> 31 == 1 {
        !b
    } else {
        b | 0x8000_0000
    }
}

/// A min-heap of keys with four children per node.
#[derive(Default)]
pub(crate) struct Queue {
    keys: Vec<u64>,
}

impl Queue {
    pub(crate) fn with_capacity(n: usize) -> Queue {
        Queue {
            keys: Vec::with_capacity(n),
        }
    }

    pub(crate) fn push(&mut self, key: u64) {
        let keys = &mut self.keys;
        let mut i = keys.len();
        keys.push(key);
        while i > 0 {
            let parent = (i - 1) / 4;
            let p = keys[parent];
            if p <= key {
                break;
            }
            keys[i] = p;
            i = parent;
        }
        keys[i] = key;
    }

    /// The smallest key, left in place.
    #[inline]
    pub(crate) fn peek(&self) -> Option<u64> {
        self.keys.first().copied()
    }

    /// Removes and returns the smallest key.
    pub(crate) fn pop(&mut self) -> Option<u64> {
        let last = self.keys.pop()?;
        let keys = &mut self.keys[..];
        let n = keys.len();
        if n == 0 {
            return Some(last);
        }
        let top = keys[0];
        let mut i = 0;
        loop {
            let first = 4 * i + 1;
            if first >= n {
                break;
            }
            let grandchildren = 4 * first + 1;
            if grandchildren < n {
                // 128 bytes: three lines at most, reached from 64 bytes apart.
                let last = (grandchildren + 15).min(n - 1);
                super::prefetch(&keys[grandchildren]);
                super::prefetch(&keys[(grandchildren + 8).min(last)]);
                super::prefetch(&keys[last]);
            }
            let (mut m, mut mk) = (first, keys[first]);
            let end = (first + 4).min(n);
            for (j, &k) in keys[first + 1..end].iter().enumerate() {
                if k < mk {
                    (m, mk) = (first + 1 + j, k);
                }
            }
            if mk >= last {
                break;
            }
            keys[i] = mk;
            i = m;
        }
        keys[i] = last;
        Some(top)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pops_in_cost_then_vertex_order() {
        let costs = [3.0f32, 0.0, -0.0, 1.5, f32::INFINITY, 1e-30, 2.0, 0.0, 7.0];
        let mut q = Queue::default();
        let mut want = Vec::new();
        for (round, v) in (0..40u32).enumerate() {
            let c = costs[(round * 7) % costs.len()];
            q.push(key(c, v));
            want.push((c, v));
        }
        want.sort_by(|x, y| x.0.total_cmp(&y.0).then(x.1.cmp(&y.1)));
        let got: Vec<u64> = std::iter::from_fn(|| q.pop()).collect();
        let want: Vec<u64> = want.iter().map(|&(c, v)| key(c, v)).collect();
        assert_eq!(got, want);
    }
}
