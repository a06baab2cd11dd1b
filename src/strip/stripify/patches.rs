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
#[derive(Clone, Copy)]
struct Quad {
    edges: [(u32, usize); 4],
}

/// A quad entered through outer edge `entry` (leaving through `entry + 2`).
type Step = (u32, usize);

struct Quads<'w, 'a> {
    walk: &'w mut Walk<'a>,
    quads: Vec<Quad>,
    /// For each quad and outer edge: the quad across it and that edge's
    /// index there, or `(NO_QUAD, 0)`.
    links: Vec<[(u32, u8); 4]>,
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
        let (n, j) = self.links[q as usize][e];
        (n != NO_QUAD && self.is_free(n)).then_some((n, j as usize))
    }

    /// Length of the row through every quad along each axis (axis `a` is
    /// entering through outer edge `a` or `a + 2`), before any quad is
    /// taken; an upper bound later, since quads are only ever taken.
    ///
    /// (quad, axis) pairs with their links form a graph of degree at most 2
    /// whose components are the rows (paths or cycles), so each component
    /// is walked twice, to count and to write, without allocating.
    ///
    /// Cost: O(quads).
    fn row_lengths(&self) -> Vec<[u32; 2]> {
        let links = &self.links;
        let mut lengths = vec![[0u32; 2]; self.quads.len()];
        // Walks the row through (q, axis): forward through edge entry + 2,
        // then (unless it closed a cycle) backward through the entry edge,
        // calling `visit` on every other member.
        let walk = |q: u32, axis: usize, visit: &mut dyn FnMut(u32, usize)| {
            let mut at = (q, axis);
            loop {
                let (n, j) = links[at.0 as usize][(at.1 + 2) % 4];
                if n == NO_QUAD {
                    break;
                }
                if (n, j as usize % 2) == (q, axis) {
                    return;
                }
                visit(n, j as usize % 2);
                at = (n, j as usize);
            }
            let mut at = (q, axis);
            loop {
                let (n, j) = links[at.0 as usize][at.1];
                if n == NO_QUAD {
                    break;
                }
                visit(n, j as usize % 2);
                at = (n, (j as usize + 2) % 4);
            }
        };
        for axis in 0..2 {
            for q in 0..self.quads.len() as u32 {
                if lengths[q as usize][axis] != 0 {
                    continue;
                }
                let mut count = 1u32;
                walk(q, axis, &mut |_, _| count += 1);
                lengths[q as usize][axis] = count;
                walk(q, axis, &mut |m, a| lengths[m as usize][a] = count);
            }
        }
        lengths
    }

    /// The maximal row of free quads through `(q, entry)`, in walking order.
    fn row(&mut self, q: u32, entry: usize) -> Vec<Step> {
        self.stamp[q as usize] = self.current;
        let mut back = Vec::new();
        let mut at = (q, entry);
        while let Some((n, j)) = self.across(at.0, at.1) {
            self.stamp[n as usize] = self.current;
            back.push((n, (j + 2) % 4));
            at = (n, j);
        }
        back.reverse();
        back.push((q, entry));
        let mut at = (q, entry);
        while let Some((n, j)) = self.across(at.0, (at.1 + 2) % 4) {
            self.stamp[n as usize] = self.current;
            back.push((n, j));
            at = (n, j);
        }
        back
    }

    /// The row next to `row` across side `side` (1 or 3, relative to each
    /// quad's entry), if every quad there is free and they form a row.
    /// Stamps the new row's quads when it succeeds.
    fn next_row(&mut self, row: &[Step], side: usize) -> Option<Vec<Step>> {
        let mut next = Vec::with_capacity(row.len());
        for &(q, entry) in row {
            let Some((n, j)) = self.across(q, (entry + side) % 4) else {
                break;
            };
            // Stamped at once, so a quad reached twice fails `across`.
            self.stamp[n as usize] = self.current;
            // Keep the walking direction: the new entry edge meets the
            // shared edge at the vertex the old entry edge meets it.
            let e = if side == 1 { (j + 1) % 4 } else { (j + 3) % 4 };
            next.push((n, e));
        }
        let is_row = next.len() == row.len()
            && next
                .windows(2)
                .all(|w| self.links[w[0].0 as usize][(w[0].1 + 2) % 4].0 == w[1].0);
        if !is_row {
            for &(n, _) in &next {
                self.stamp[n as usize] = 0;
            }
            return None;
        }
        Some(next)
    }

    /// The largest rectangle of rows through `(q, entry)`.
    /// `rows_bound` bounds the number of rows (the length of the
    /// perpendicular row through `q`); when the middle row is too short for
    /// `min_area` even with that many rows, no row is stacked.
    fn patch(&mut self, q: u32, entry: usize, rows_bound: u32, min_area: usize) -> Vec<Vec<Step>> {
        self.current += 1;
        let mut rows = vec![self.row(q, entry)];
        if rows[0].len() * (rows_bound as usize) < min_area {
            return rows;
        }
        for side in [1, 3] {
            let mut last = 0;
            while let Some(next) = self.next_row(&rows[last], side) {
                rows.push(next);
                last = rows.len() - 1;
            }
        }
        rows
    }
}

/// The quad across each outer edge of each quad (see [`Quads::links`]).
fn link_quads(
    walk: &Walk<'_>,
    quads: &[Quad],
    quad_of: &[u32],
    edge_of: &[[u8; 3]],
) -> Vec<[(u32, u8); 4]> {
    quads
        .iter()
        .enumerate()
        .map(|(qi, quad)| {
            quad.edges.map(|(t, s)| {
                let n = walk.adj.neighbours[t as usize][s];
                if n == NO_NEIGHBOUR {
                    return (NO_QUAD, 0);
                }
                let qn = quad_of[n as usize];
                if qn == NO_QUAD || qn == qi as u32 {
                    return (NO_QUAD, 0);
                }
                (qn, edge_of[n as usize][walk.adj.mate(t, s)])
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

fn pair_quads(walk: &Walk<'_>, longest: &[u8]) -> (Vec<Quad>, Vec<u32>, Vec<[u8; 3]>) {
    let tris = walk.tris;
    let mut quads = Vec::new();
    let mut quad_of = vec![NO_QUAD; tris.len()];
    // Outer edge index of each triangle slot in its quad (the diagonal's
    // slot is never looked up).
    let mut edge_of = vec![[0u8; 3]; tris.len()];
    for t in 0..tris.len() as u32 {
        if quad_of[t as usize] != NO_QUAD || !walk.is_free(t) {
            continue;
        }
        let s = longest[t as usize] as usize;
        let u = walk.adj.neighbours[t as usize][s];
        if !walk.is_free(u) || quad_of[u as usize] != NO_QUAD {
            continue;
        }
        let su = longest[u as usize] as usize;
        if walk.adj.neighbours[u as usize][su] != t {
            continue;
        }
        quad_of[t as usize] = quads.len() as u32;
        quad_of[u as usize] = quads.len() as u32;
        quads.push(Quad {
            edges: [
                (t, (s + 1) % 3),
                (t, (s + 2) % 3),
                (u, (su + 1) % 3),
                (u, (su + 2) % 3),
            ],
        });
        edge_of[t as usize][(s + 1) % 3] = 0;
        edge_of[t as usize][(s + 2) % 3] = 1;
        edge_of[u as usize][(su + 1) % 3] = 2;
        edge_of[u as usize][(su + 2) % 3] = 3;
    }
    (quads, quad_of, edge_of)
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
    let (quads, quad_of, edge_of) = pair_quads(walk, longest);
    let quad_count = quads.len();
    let first_row = paths.len();
    let links = link_quads(walk, &quads, &quad_of, &edge_of);
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
    let bound = |seed: u32| {
        let [l0, l1] = lengths[seed as usize];
        l0 as usize * l1 as usize
    };
    let mut seeds: Vec<u32> = (0..quad_count as u32)
        .filter(|&s| bound(s) >= min_patch_quads)
        .collect();
    seeds.sort_unstable_by_key(|&s| (std::cmp::Reverse(bound(s)), s));
    for seed in seeds {
        let [l0, l1] = lengths[seed as usize];
        // The rows of a patch cross the perpendicular row through the seed,
        // so its area is at most the product of the two row lengths.
        if tried[seed as usize]
            || (l0 as usize) * (l1 as usize) < min_patch_quads
            || !q.is_free(seed)
        {
            continue;
        }
        let a = q.patch(seed, 0, l1, min_patch_quads);
        let b = q.patch(seed, 1, l0, min_patch_quads);
        let area = |rows: &Vec<Vec<Step>>| rows.len() * rows[0].len();
        if area(&a).max(area(&b)) < min_patch_quads {
            for &(quad, _) in a.iter().chain(&b).flatten() {
                tried[quad as usize] = true;
            }
            continue;
        }
        let best = if area(&b) > area(&a) { b } else { a };
        for row in best {
            for &(quad, _) in &row {
                q.taken[quad as usize] = true;
            }
            let mut path = Vec::with_capacity(2 * row.len());
            for (quad, entry) in row {
                let edges = q.quads[quad as usize].edges;
                let first = edges[entry].0;
                let second = edges[(entry + 2) % 4].0;
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
