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

/// `free_deg` of a taken triangle.
const TAKEN: u8 = u8::MAX;

/// Which triangles are taken, and a bucket queue of the free ones by their
/// number of free neighbours (0–3). Entries are lazy: a triangle is pushed
/// again when its count drops, and stale entries are skipped when popped,
/// so each triangle is pushed at most four times.
#[derive(Clone)]
pub(super) struct Walk<'a> {
    pub(super) tris: &'a [[u32; 3]],
    pub(super) adj: &'a TriangleAdjacency,
    /// Free neighbours of each free triangle, or [`TAKEN`]: one array, so
    /// that testing a candidate and reading its count touch one cache line
    /// (the walk is bound by cache misses on large meshes).
    free_deg: Vec<u8>,
    buckets: [Vec<u32>; 4],
    pub(super) swap_penalty: f32,
    /// Strips laid along the contraction sequence (an experiment,
    /// [`super::stripify_along`]): each triangle's death LoD, and the
    /// weight of `|death(next) - death(current)| / (max death + 1)` added
    /// to a candidate's score; `None` for the plain pass.
    pub(super) death: Option<(&'a [u32], f32)>,
    /// The largest death LoD plus one (the term's scale).
    pub(super) death_span: u32,
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
            free_deg,
            buckets,
            swap_penalty: 0.5,
            death: None,
            death_span: 1,
        }
    }

    /// Free neighbours of the free triangle `t`.
    pub(super) fn free_neighbours(&self, t: u32) -> u8 {
        self.free_deg[t as usize]
    }

    pub(super) fn is_free(&self, t: u32) -> bool {
        t != NO_NEIGHBOUR && self.free_deg[t as usize] != TAKEN
    }

    /// Marks `t` as taken and updates its free neighbours' counts.
    pub(super) fn take(&mut self, t: u32) {
        debug_assert_ne!(self.free_deg[t as usize], TAKEN, "triangle taken twice");
        self.free_deg[t as usize] = TAKEN;
        for &n in &self.adj.neighbours[t as usize] {
            if self.is_free(n) {
                let d = &mut self.free_deg[n as usize];
                *d -= 1;
                self.buckets[*d as usize].push(n);
            }
        }
    }

    /// The vertex of `t`'s neighbour through slot `s` that is not on their
    /// shared edge.
    pub(super) fn apex(&self, t: u32, s: usize) -> u32 {
        let n = self.adj.neighbours[t as usize][s];
        self.tris[n as usize][(self.adj.mate(t, s) + 2) % 3]
    }

    /// The free triangle with fewest free neighbours; the most recently
    /// updated one on a tie, which keeps new strips next to the last.
    pub(super) fn pop_start(&mut self) -> Option<u32> {
        for d in 0..4 {
            while let Some(t) = self.buckets[d].pop() {
                if self.free_deg[t as usize] as usize == d {
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
        match self.death {
            // The plain pass compiles without the death term.
            None => self.grow_back_with(path, |_, _| 0.0),
            Some((death, weight)) => {
                let span = self.death_span as f32;
                self.grow_back_with(path, move |cur: u32, cand: u32| {
                    weight * death[cur as usize].abs_diff(death[cand as usize]) as f32 / span
                });
            }
        }
    }

    /// [`Walk::grow_back`] with `extra(current, candidate)` added to each
    /// candidate's score.
    #[inline(always)]
    fn grow_back_with(&mut self, path: &mut Vec<u32>, extra: impl Fn(u32, u32) -> f32) {
        let mut cursor = Cursor::at_back(self, path);
        loop {
            let ns = &self.adj.neighbours[cursor.cur as usize];
            let mut best: Option<(f32, usize)> = None;
            for (s, &cand) in ns.iter().enumerate() {
                if Some(s) == cursor.entry || !self.is_free(cand) {
                    continue;
                }
                let score = f32::from(self.free_deg[cand as usize])
                    + if cursor.swaps_through(s) {
                        self.swap_penalty
                    } else {
                        0.0
                    }
                    + extra(cursor.cur, cand);
                if best.is_none_or(|(b, _)| score < b) {
                    best = Some((score, s));
                }
            }
            let Some((_, s)) = best else { return };
            let next = cursor.advance(self.adj, s);
            self.take(next);
            path.push(next);
        }
    }
}

/// The back of a growing path: its last triangle and what deciding the
/// next one's swap needs.
pub(super) struct Cursor {
    /// The path's last triangle.
    pub(super) cur: u32,
    /// Slot of `cur` it was entered through (none for a path of one).
    pub(super) entry: Option<usize>,
    /// Where the pivot at the previous triangle lies in `cur`: the start
    /// or the end of the entry edge (slot `entry` or `entry + 1`), or
    /// neither. A swap is needed when the pivot at `cur` is that vertex.
    /// Positions instead of vertex ids keep the loop off the triangle
    /// array (one cache miss fewer per step; vertices and positions
    /// correspond one to one in a non-degenerate triangle).
    pivot_at: Option<usize>,
}

impl Cursor {
    /// The cursor at the back of `path` (not empty).
    pub(super) fn at_back(walk: &Walk<'_>, path: &[u32]) -> Cursor {
        let n = path.len();
        let cur = path[n - 1];
        let entry = (n >= 2).then(|| slot_to(walk.adj, cur, path[n - 2]));
        let pivot_at = if n >= 3 {
            let prev = path[n - 2];
            let a = slot_to(walk.adj, prev, path[n - 3]);
            let b = slot_to(walk.adj, prev, cur);
            let p = pivot(&walk.tris[prev as usize], a, b);
            walk.tris[cur as usize].iter().position(|&v| v == p)
        } else {
            None
        };
        Cursor {
            cur,
            entry,
            pivot_at,
        }
    }

    /// Whether leaving `cur` through slot `s` costs a swap.
    pub(super) fn swaps_through(&self, s: usize) -> bool {
        match (self.entry, self.pivot_at) {
            (Some(e), Some(p)) => pivot_slot(e, s) == p,
            _ => false,
        }
    }

    /// Moves to `cur`'s neighbour through slot `s` and returns it.
    pub(super) fn advance(&mut self, adj: &TriangleAdjacency, s: usize) -> u32 {
        let next = adj.neighbours[self.cur as usize][s];
        let next_entry = adj.mate(self.cur, s);
        // Exit edge `s` is `next`'s edge `next_entry` reversed: its
        // start is at `next_entry + 1`, its end at `next_entry`.
        self.pivot_at = self.entry.map(|e| {
            if pivot_slot(e, s) == s {
                (next_entry + 1) % 3
            } else {
                next_entry
            }
        });
        self.entry = Some(next_entry);
        self.cur = next;
        next
    }
}

/// The position in a triangle of the vertex shared by its edge slots `a`
/// and `b` (distinct): [`pivot`] without reading the vertices.
fn pivot_slot(a: usize, b: usize) -> usize {
    if b == (a + 1) % 3 {
        b
    } else {
        a
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pivot_slot_is_the_position_of_the_pivot() {
        let t = [7, 8, 9];
        for a in 0..3 {
            for b in (0..3).filter(|&b| b != a) {
                assert_eq!(t[pivot_slot(a, b)], pivot(&t, a, b));
            }
        }
    }
}
