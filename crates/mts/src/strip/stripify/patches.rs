//! The global pass of the hybrid search: rectangular patches of
//! quadrilaterals, stripped along their rows.
//!
//! STRIPE looks for large rectangular regions of quadrilateral faces, whose
//! rows make long swap-free strips. A triangle mesh has no quadrilaterals,
//! so they are made first: two triangles are paired across an edge when that
//! edge is the longest of both (the diagonal of a well-shaped quad, which is
//! what a triangulated quad grid looks like). Then, from each free quad in
//! turn and along both of its axes, the pass walks the quad's row through
//! opposite edges, stacks neighbouring rows on both sides while each quad of
//! the row has a free quad across its side edge and those quads form a row
//! of their own, and keeps the larger rectangle if it holds at least
//! `min_patch_quads` quads. Each row becomes one strip; after all patches
//! are found, each row strip grows at both ends by the local pass's rule.

use super::greedy::Walk;
use crate::mesh::NO_NEIGHBOUR;
use glam::Vec3;

const NO_QUAD: u32 = u32::MAX;

/// A quadrilateral: two triangles and its four outer edges in
/// counter-clockwise order, each as (triangle, edge slot). Outer edge `i` is
/// opposite edge `(i + 2) % 4`; each opposite pair has one edge in each
/// triangle, so a row crossing the quad draws both.
///
/// Stored as 12 bytes (edges 0 and 1 are in the first triangle, 2 and 3 in
/// the second): the pass is bound by cache misses, so its arrays are kept
/// small.
#[derive(Clone, Copy)]
struct Quad {
    triangles: [u32; 2],
    slots: [u8; 4],
}

impl Quad {
    /// Outer edge `i` as (triangle, edge slot).
    fn edge(&self, i: usize) -> (u32, usize) {
        (self.triangles[i / 2], self.slots[i] as usize)
    }
}

/// A quad entered through outer edge `entry` (leaving through `entry + 2`).
type Step = (u32, usize);

struct Quads<'w, 'a> {
    walk: &'w mut Walk<'a>,
    quads: Vec<Quad>,
    /// For each quad and outer edge: `4 × quad + edge index` of the same
    /// edge in the quad across it, or `NO_QUAD`.
    links: Vec<[u32; 4]>,
    /// Quads already stripped by an accepted patch.
    taken: Vec<bool>,
    /// `stamp[q] == current` marks quads already in the patch being built.
    stamp: Vec<u32>,
    current: u32,
}

impl Quads<'_, '_> {
    fn is_free(&self, q: u32) -> bool {
        !self.taken[q as usize] && self.stamp[q as usize] != self.current
    }

    /// The free quad across outer edge `e` of `q`, and the index of that
    /// edge in it.
    fn across(&self, q: u32, e: usize) -> Option<(u32, usize)> {
        let (n, j) = self.link(q, e)?;
        self.is_free(n).then_some((n, j))
    }

    /// The quad across outer edge `e` of `q`, free or not, and the index of
    /// that edge in it.
    fn link(&self, q: u32, e: usize) -> Option<(u32, usize)> {
        let l = self.links[q as usize][e];
        (l != NO_QUAD).then_some((l / 4, l as usize % 4))
    }

    /// Length of the row through every quad along each axis (axis `a` is
    /// entering through outer edge `a` or `a + 2`), before any quad is
    /// taken; an upper bound later, since quads are only ever taken.
    ///
    /// (quad, axis) pairs with their links form a graph of degree at most 2
    /// whose components are the rows (paths or cycles), so each component
    /// is walked once, its members kept in a scratch list to be written.
    ///
    /// Cost: O(quads).
    fn row_lengths(&self) -> Vec<[u32; 2]> {
        let mut lengths = vec![[0u32; 2]; self.quads.len()];
        let mut members: Vec<(u32, usize)> = Vec::new();
        for axis in 0..2 {
            for q in 0..self.quads.len() as u32 {
                if lengths[q as usize][axis] != 0 {
                    continue;
                }
                // Forward through edge entry + 2, then (unless that closed a
                // cycle) backward through the entry edge.
                members.clear();
                members.push((q, axis));
                let mut at = (q, axis);
                let mut cycle = false;
                while let Some((n, j)) = self.link(at.0, (at.1 + 2) % 4) {
                    if (n, j % 2) == (q, axis) {
                        cycle = true;
                        break;
                    }
                    members.push((n, j % 2));
                    at = (n, j);
                }
                if !cycle {
                    let mut at = (q, axis);
                    while let Some((n, j)) = self.link(at.0, at.1) {
                        members.push((n, j % 2));
                        at = (n, (j + 2) % 4);
                    }
                }
                let count = members.len() as u32;
                for &(m, a) in &members {
                    lengths[m as usize][a] = count;
                }
            }
        }
        lengths
    }

    /// Appends the maximal row of free quads through `(q, entry)` to
    /// `out`, in walking order.
    fn row(&mut self, q: u32, entry: usize, out: &mut Vec<Step>) {
        let first = out.len();
        self.stamp[q as usize] = self.current;
        let mut at = (q, entry);
        while let Some((n, j)) = self.across(at.0, at.1) {
            self.stamp[n as usize] = self.current;
            out.push((n, (j + 2) % 4));
            at = (n, j);
        }
        out[first..].reverse();
        out.push((q, entry));
        let mut at = (q, entry);
        while let Some((n, j)) = self.across(at.0, (at.1 + 2) % 4) {
            self.stamp[n as usize] = self.current;
            out.push((n, j));
            at = (n, j);
        }
    }

    /// Appends to `rows` the row next to `rows[row..row + len]` across side
    /// `side` (1 or 3, relative to each quad's entry), if every quad there
    /// is free and they form a row; returns whether it did. Stamps the new
    /// row's quads when it succeeds.
    fn next_row(&mut self, rows: &mut Vec<Step>, row: usize, len: usize, side: usize) -> bool {
        let first = rows.len();
        for i in row..row + len {
            let (q, entry) = rows[i];
            let Some((n, j)) = self.across(q, (entry + side) % 4) else {
                break;
            };
            // Stamped at once, so a quad reached twice fails `across`.
            self.stamp[n as usize] = self.current;
            // Keep the walking direction: the new entry edge meets the
            // shared edge at the vertex the old entry edge meets it.
            let e = if side == 1 { (j + 1) % 4 } else { (j + 3) % 4 };
            rows.push((n, e));
        }
        let next = &rows[first..];
        let is_row = next.len() == len
            && next
                .windows(2)
                .all(|w| self.link(w[0].0, (w[0].1 + 2) % 4).map(|(n, _)| n) == Some(w[1].0));
        if !is_row {
            for &(n, _) in next {
                self.stamp[n as usize] = 0;
            }
            rows.truncate(first);
        }
        is_row
    }

    /// The largest rectangle of rows through `(q, entry)`, written to
    /// `rows` back to back (the buffer is reused from seed to seed: most
    /// attempts are rejected); returns the row length.
    /// `rows_bound` bounds the number of rows (the length of the
    /// perpendicular row through `q`); when the middle row is too short for
    /// `min_area` even with that many rows, no row is stacked.
    fn patch(
        &mut self,
        q: u32,
        entry: usize,
        rows_bound: u32,
        min_area: usize,
        rows: &mut Vec<Step>,
    ) -> usize {
        self.current += 1;
        rows.clear();
        self.row(q, entry, rows);
        let len = rows.len();
        if len * (rows_bound as usize) < min_area {
            return len;
        }
        for side in [1, 3] {
            let mut last = 0;
            while self.next_row(rows, last, len, side) {
                last = rows.len() - len;
            }
        }
        len
    }
}

/// The quad across each outer edge of each quad (see [`Quads::links`]).
fn link_quads(walk: &Walk<'_>, quads: &[Quad], half_of: &[u32], longest: &[u8]) -> Vec<[u32; 4]> {
    // 4 × quad + 3 stays below NO_QUAD: quads are at most half the
    // triangles, which the adjacency keeps below u32::MAX / 3.
    quads
        .iter()
        .zip(0u32..)
        .map(|(quad, qi)| {
            std::array::from_fn(|i| {
                let (t, s) = quad.edge(i);
                let n = walk.adj.neighbours[t as usize][s];
                if n == NO_NEIGHBOUR {
                    return NO_QUAD;
                }
                let h = half_of[n as usize];
                if h == NO_QUAD || h / 2 == qi {
                    return NO_QUAD;
                }
                // Outer edges 2h, 2h + 1 of the quad follow the diagonal
                // (the longest edge) in the triangle's slot order.
                let slot = walk.adj.mate(t, s) as u32;
                let edge = 2 * (h % 2) + (slot + 2 - u32::from(longest[n as usize])) % 3;
                4 * (h / 2) + edge
            })
        })
        .collect()
}

/// The slot of each triangle's longest edge (the lowest slot on a tie).
///
/// Cost: O(T); needs only positions, so it can run while the adjacency is
/// built.
pub(super) fn longest_edges(tris: &[[u32; 3]], positions: &[Vec3]) -> Vec<u8> {
    tris.iter()
        .map(|t| {
            let [a, b, c] = t.map(|v| positions[v as usize]);
            let l = [
                a.distance_squared(b),
                b.distance_squared(c),
                c.distance_squared(a),
            ];
            if l[0] >= l[1] && l[0] >= l[2] {
                0
            } else if l[1] >= l[2] {
                1
            } else {
                2
            }
        })
        .collect()
}

/// The quads, and for each triangle `2 × quad + 0 or 1` (the first or
/// second triangle of its quad) or `NO_QUAD`.
fn pair_quads(walk: &Walk<'_>, longest: &[u8]) -> (Vec<Quad>, Vec<u32>) {
    let tris = walk.tris;
    let mut quads = Vec::new();
    let mut half_of = vec![NO_QUAD; tris.len()];
    for t in 0..tris.len() as u32 {
        if half_of[t as usize] != NO_QUAD || !walk.is_free(t) {
            continue;
        }
        let s = longest[t as usize] as usize;
        let u = walk.adj.neighbours[t as usize][s];
        if !walk.is_free(u) || half_of[u as usize] != NO_QUAD {
            continue;
        }
        let su = longest[u as usize] as usize;
        if walk.adj.neighbours[u as usize][su] != t {
            continue;
        }
        half_of[t as usize] = 2 * quads.len() as u32;
        half_of[u as usize] = 2 * quads.len() as u32 + 1;
        quads.push(Quad {
            triangles: [t, u],
            slots: [(s + 1) % 3, (s + 2) % 3, (su + 1) % 3, (su + 2) % 3].map(|x| x as u8),
        });
    }
    (quads, half_of)
}

/// Runs the global pass, appending one path per patch row.
///
/// Cost: O(T · min_patch_quads) in the worst case (each rejected attempt
/// looks at fewer than `min_patch_quads` quads per row stack), O(T) on
/// quad-grid meshes where patches are accepted.
pub(super) fn strip_patches(
    walk: &mut Walk<'_>,
    longest: &[u8],
    min_patch_quads: usize,
    paths: &mut Vec<Vec<u32>>,
) {
    let (quads, half_of) = pair_quads(walk, longest);
    let quad_count = quads.len();
    let first_row = paths.len();
    let links = link_quads(walk, &quads, &half_of, longest);
    let mut q = Quads {
        walk,
        quads,
        links,
        taken: vec![false; quad_count],
        stamp: vec![0; quad_count],
        current: 1,
    };
    // Quads inside a rejected attempt are not tried as seeds again: their
    // rows were just measured and are shorter than the threshold allows.
    // This keeps the pass O(T) in practice (bunny: 283 ms without it).
    let mut tried = vec![false; quad_count];
    let lengths = q.row_lengths();
    // Largest possible patches first, as STRIPE does.
    // Sorted as one u64 per seed, (u32::MAX - bound) << 32 | seed: a third
    // of the time of sorting (bound, seed) pairs and a fifth of sorting by
    // a key looked up per comparison (bunny: 18K seeds, 0.25 against 0.65
    // and 1.1 ms). A bound is saturated at u32::MAX, which changes nothing
    // on a real mesh: it takes two crossing rows of 65,536 quads.
    let mut seeds: Vec<u64> = lengths
        .iter()
        .zip(0u32..)
        .filter_map(|(&[l0, l1], s)| {
            let bound = (u64::from(l0) * u64::from(l1)).min(u64::from(u32::MAX));
            (bound >= min_patch_quads as u64)
                .then(|| (u64::from(u32::MAX) - bound) << 32 | u64::from(s))
        })
        .collect();
    seeds.sort_unstable();
    let (mut a, mut b) = (Vec::new(), Vec::new());
    for seed in seeds.into_iter().map(|key| key as u32) {
        let [l0, l1] = lengths[seed as usize];
        // The rows of a patch cross the perpendicular row through the seed,
        // so its area is at most the product of the two row lengths.
        if tried[seed as usize]
            || (l0 as usize) * (l1 as usize) < min_patch_quads
            || !q.is_free(seed)
        {
            continue;
        }
        let len_a = q.patch(seed, 0, l1, min_patch_quads, &mut a);
        let len_b = q.patch(seed, 1, l0, min_patch_quads, &mut b);
        // A patch's area is its number of steps.
        if a.len().max(b.len()) < min_patch_quads {
            for &(quad, _) in a.iter().chain(&b) {
                tried[quad as usize] = true;
            }
            continue;
        }
        let (best, len) = if b.len() > a.len() {
            (&b, len_b)
        } else {
            (&a, len_a)
        };
        for row in best.chunks(len) {
            for &(quad, _) in row {
                q.taken[quad as usize] = true;
            }
            let mut path = Vec::with_capacity(2 * row.len());
            for &(quad, entry) in row {
                let quad = q.quads[quad as usize];
                let first = quad.edge(entry).0;
                let second = quad.edge((entry + 2) % 4).0;
                path.extend([first, second]);
            }
            for &t in &path {
                q.walk.take(t);
            }
            paths.push(path);
        }
    }
    let mut rows = paths.split_off(first_row);
    super::path::join_ends(&mut rows, walk.adj);
    paths.extend(rows);
    for path in &mut paths[first_row..] {
        walk.grow_back(path);
        path.reverse();
        walk.grow_back(path);
    }
}
