//! The local pass of the hybrid search: greedy strip growth.
//!
//! As in STRIPE's local phase (itself after the SGI `tomesh` heuristic): a
//! strip starts at the free triangle with fewest free neighbours (so that
//! triangles about to be isolated are taken first), grows through the
//! neighbour with fewest free neighbours, avoids a swap whenever the other
//! side allows it, and when it cannot go on it grows again from its start in
//! the other direction.

use super::path::{pivot, slot_to};
use crate::mesh::{TriangleAdjacency, NO_NEIGHBOUR};

/// Which triangles are taken, and a bucket queue of the free ones by their
/// number of free neighbours (0–3). Entries are lazy: a triangle is pushed
/// again when its count drops, and stale entries are skipped when popped,
/// so each triangle is pushed at most four times.
#[derive(Clone)]
pub(super) struct Walk<'a> {
    pub(super) tris: &'a [[u32; 3]],
    pub(super) adj: &'a TriangleAdjacency,
    pub(super) used: Vec<bool>,
    free_deg: Vec<u8>,
    buckets: [Vec<u32>; 4],
    pub(super) swap_penalty: f32,
}

impl<'a> Walk<'a> {
    pub(super) fn new(tris: &'a [[u32; 3]], adj: &'a TriangleAdjacency) -> Walk<'a> {
        let free_deg: Vec<u8> = adj
            .neighbours
            .iter()
            .map(|ns| ns.iter().filter(|&&n| n != NO_NEIGHBOUR).count() as u8)
            .collect();
        let mut buckets: [Vec<u32>; 4] = Default::default();
        // Pushed in reverse so that pops (LIFO) start from the first triangle.
        for t in (0..tris.len()).rev() {
            buckets[free_deg[t] as usize].push(t as u32);
        }
        Walk {
            tris,
            adj,
            used: vec![false; tris.len()],
            free_deg,
            buckets,
            swap_penalty: 0.5,
        }
    }

    pub(super) fn is_free(&self, t: u32) -> bool {
        t != NO_NEIGHBOUR && !self.used[t as usize]
    }

    /// Marks `t` as taken and updates its free neighbours' counts.
    pub(super) fn take(&mut self, t: u32) {
        debug_assert!(!self.used[t as usize], "triangle taken twice");
        self.used[t as usize] = true;
        for &n in &self.adj.neighbours[t as usize] {
            if self.is_free(n) {
                let d = &mut self.free_deg[n as usize];
                *d -= 1;
                self.buckets[*d as usize].push(n);
            }
        }
    }

    /// The free triangle with fewest free neighbours; the most recently
    /// updated one on a tie, which keeps new strips next to the last.
    fn pop_start(&mut self) -> Option<u32> {
        for d in 0..4 {
            while let Some(t) = self.buckets[d].pop() {
                if !self.used[t as usize] && self.free_deg[t as usize] as usize == d {
                    return Some(t);
                }
            }
        }
        None
    }

    /// Extends `path` at its back until no free neighbour is left.
    ///
    /// The candidate score is the candidate's free-neighbour count plus the
    /// swap penalty if entering it needs a swap (see the `path` module:
    /// a swap is three consecutive shared edges around one vertex).
    pub(super) fn grow_back(&mut self, path: &mut Vec<u32>) {
        let n = path.len();
        let mut cur = path[n - 1];
        // Entry slot of `cur` and the pivot at the previous triangle, carried
        // from step to step.
        let mut entry = (n >= 2).then(|| slot_to(self.adj, cur, path[n - 2]));
        let mut last_pivot = (n >= 3).then(|| {
            let prev = path[n - 2];
            let a = slot_to(self.adj, prev, path[n - 3]);
            let b = slot_to(self.adj, prev, cur);
            pivot(&self.tris[prev as usize], a, b)
        });
        loop {
            let t = &self.tris[cur as usize];
            let ns = &self.adj.neighbours[cur as usize];
            let mut best: Option<(f32, usize)> = None;
            for (s, &cand) in ns.iter().enumerate() {
                if Some(s) == entry || !self.is_free(cand) {
                    continue;
                }
                let swap = match (entry, last_pivot) {
                    (Some(e), Some(p)) => pivot(t, e, s) == p,
                    _ => false,
                };
                let score = f32::from(self.free_deg[cand as usize])
                    + if swap { self.swap_penalty } else { 0.0 };
                if best.is_none_or(|(b, _)| score < b) {
                    best = Some((score, s));
                }
            }
            let Some((_, s)) = best else { return };
            let next = ns[s];
            last_pivot = entry.map(|e| pivot(t, e, s));
            entry = Some(self.adj.mate(cur, s));
            self.take(next);
            path.push(next);
            cur = next;
        }
    }
}

/// Strips every free triangle, appending one path per strip.
///
/// Cost: O(T) (each triangle is taken once; each step looks at 3 slots).
pub(super) fn strip_rest(walk: &mut Walk<'_>, paths: &mut Vec<Vec<u32>>) {
    while let Some(start) = walk.pop_start() {
        walk.take(start);
        let mut path = vec![start];
        walk.grow_back(&mut path);
        path.reverse();
        walk.grow_back(&mut path);
        paths.push(path);
    }
}
