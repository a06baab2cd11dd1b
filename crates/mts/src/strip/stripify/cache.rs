//! The cache-aware local pass: strips laid in rows, each row walking
//! around the vertices the last row left on its free side, in the order a
//! vertex cache reuses them.
//!
//! After Hoppe, "Optimization of mesh locality for transparent vertex
//! caching" (SIGGRAPH 1999), whose strips run side by side in bands as wide
//! as the cache holds (followed from memory of the paper; the construction
//! below is ours, docs/experiments/vertex-work.md).
//!
//! A band starts with a strip grown greedily (no swap first, then a cached
//! new vertex, then fewest free neighbours) until it has missed the cache
//! [`FIRST_MISSES`] times; one of its sides becomes the **chain**. Each
//! next row walks the free triangles around the chain's vertices in chain
//! order: it turns around a chain vertex (the pivot) until it reaches the
//! triangle that holds the next chain vertex, then turns around that one,
//! so every triangle of the row touches the last row. Before the chain's
//! first edge it takes the first vertex's free fan (up to
//! [`MAX_BACK_FAN`] triangles): a row that starts at the edge leaves a
//! triangle behind per row where the quads' diagonals lean the other way. The vertices the row meets off the chain, in order,
//! are the next row's chain, walked the same way: a vertex then comes back
//! about one row's misses after it entered the cache, whatever its place in
//! the row (a row walked the other way, a serpentine, meets the last row's
//! first vertices two rows' misses later, and its turns cost more swaps
//! than the restarts they save).
//!
//! A row stops when it has met [`ROW_NEW`] new vertices or missed the cache
//! [`ROW_MISSES`] times; a strip ends where the turn around its pivot meets
//! a taken triangle or the border, and the row goes on from the next chain
//! vertex in a new strip. Where no chain vertex has a free triangle the
//! next band starts at the free triangle with most cached vertices, or
//! where the plain local pass would ([`Walk::pop_start`]). Consecutive
//! strips whose ends are neighbours are joined (the order the cache sees is
//! unchanged).

use super::greedy::{Cursor, Walk};
use super::path::slot_to;
use crate::mesh::TriangleAdjacency;
use crate::strip::acmr::CACHE_SIZE;

/// New vertices (off the chain) after which a row stops. Rows of 9 or
/// more let a 16-entry FIFO drop the last row's vertices before they come
/// back, and once one row misses them all every later one does; the
/// shared models' FIFO-16 gap to the ordered list, mean over the 20: 0.000
/// at 8, 0.014 at 10, 0.131 at 11 (docs/experiments/vertex-work.md).
const ROW_NEW: usize = 8;
/// Cache misses after which a row stops (the new vertices plus the last
/// row's vertices the cache had already dropped).
const ROW_MISSES: u32 = 10;
/// Most free triangles a row's first strip takes around its first chain
/// vertex before the chain's first edge. Every shared model gives the same
/// strips with 8 as with no limit (4 loses two models' FIFO figure); the
/// bound keeps a strip's start O(1) at a vertex with thousands of triangles.
const MAX_BACK_FAN: usize = 8;
/// Cache misses after which the first strip of a band stops: its chain is
/// half its vertices, which the next row meets while at most about
/// [`CACHE_SIZE`] misses came after them.
const FIRST_MISSES: u32 = 14;

/// A FIFO of the last [`CACHE_SIZE`] distinct vertices missed, as
/// [`crate::strip::acmr::fifo_acmr`] models it.
struct VertexFifo {
    /// When each vertex last entered the cache, in misses (0: never).
    stamp: Vec<u32>,
    /// Misses so far, plus `CACHE_SIZE + 1` so that stamp 0 is never held.
    now: u32,
    /// The cached vertices as a ring: slot `now % CACHE_SIZE` holds the
    /// oldest (or `u32::MAX` before the cache fills).
    ring: [u32; CACHE_SIZE as usize],
}

impl VertexFifo {
    fn new(vertex_count: usize) -> VertexFifo {
        VertexFifo {
            stamp: vec![0; vertex_count],
            now: CACHE_SIZE + 1,
            ring: [u32::MAX; CACHE_SIZE as usize],
        }
    }

    /// Misses since `v` entered the cache (1: the newest), if it is cached.
    fn age(&self, v: u32) -> Option<u32> {
        let a = self.now - self.stamp[v as usize];
        (a <= CACHE_SIZE).then_some(a)
    }

    /// Whether `v` is cached.
    fn holds(&self, v: u32) -> bool {
        self.age(v).is_some()
    }

    /// References `v`: a miss enters it (pushing out the oldest).
    fn touch(&mut self, v: u32) {
        if !self.holds(v) {
            self.stamp[v as usize] = self.now;
            self.ring[(self.now % CACHE_SIZE) as usize] = v;
            self.now += 1;
        }
    }
}

/// Vertex → triangles table (compressed rows).
struct VertexTriangles {
    offsets: Vec<u32>,
    triangles: Vec<u32>,
}

impl VertexTriangles {
    fn new(tris: &[[u32; 3]], vertex_count: usize) -> VertexTriangles {
        let mut offsets = vec![0u32; vertex_count + 1];
        for &v in tris.iter().flatten() {
            offsets[v as usize + 1] += 1;
        }
        for i in 0..vertex_count {
            offsets[i + 1] += offsets[i];
        }
        let mut fill = offsets.clone();
        let mut triangles = vec![0u32; 3 * tris.len()];
        for (t, tri) in tris.iter().enumerate() {
            for &v in tri {
                triangles[fill[v as usize] as usize] = t as u32;
                fill[v as usize] += 1;
            }
        }
        VertexTriangles { offsets, triangles }
    }

    fn of(&self, v: u32) -> &[u32] {
        &self.triangles[self.offsets[v as usize] as usize..self.offsets[v as usize + 1] as usize]
    }
}

/// The free triangle touching the cache with most cached vertices, then
/// the oldest ones (largest sum of ages), then fewest free neighbours.
fn cached_start(walk: &Walk<'_>, fifo: &VertexFifo, by_vertex: &VertexTriangles) -> Option<u32> {
    let mut best: Option<((u32, u32, u8), u32)> = None;
    for &v in &fifo.ring {
        if v == u32::MAX || !fifo.holds(v) {
            continue;
        }
        for &t in by_vertex.of(v) {
            if !walk.is_free(t) {
                continue;
            }
            let (count, ages) = walk.tris[t as usize]
                .iter()
                .filter_map(|&u| fifo.age(u))
                .fold((0, 0), |(c, s), a| (c + 1, s + a));
            let key = (count, ages, u8::MAX - walk.free_neighbours(t));
            if best.is_none_or(|(k, _)| key > k) {
                best = Some((key, t));
            }
        }
    }
    best.map(|(_, t)| t)
}

/// The pass's state beside the walk.
struct Rows<'w, 'a> {
    walk: &'w mut Walk<'a>,
    by_vertex: VertexTriangles,
    fifo: VertexFifo,
    /// Row number (from 1) whose chain each vertex is in.
    in_chain: Vec<u32>,
    /// Row number (from 1) whose new vertices each vertex is in.
    in_next: Vec<u32>,
    /// The current row's number.
    row: u32,
    /// Cache misses before the current row.
    row_since: u32,
    /// The current row's new vertices, in the order met: the next chain.
    next: Vec<u32>,
}

/// How a row's strip ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum End {
    /// The turn around the pivot met a taken triangle or the border.
    Blocked,
    /// The row met its limit of new vertices or misses.
    Full,
}

impl Rows<'_, '_> {
    /// Whether `v` has a free triangle.
    fn has_free(&self, v: u32) -> bool {
        self.by_vertex.of(v).iter().any(|&t| self.walk.is_free(t))
    }

    /// The free triangle holding both `a` and `b`, if any.
    fn free_across(&self, a: u32, b: u32) -> Option<u32> {
        self.by_vertex
            .of(a)
            .iter()
            .copied()
            .find(|&t| self.walk.is_free(t) && self.walk.tris[t as usize].contains(&b))
    }

    /// Starts a new row along `chain`.
    fn begin_row(&mut self, chain: &[u32]) {
        self.row_since = self.fifo.now;
        self.row += 1;
        self.next.clear();
        for &v in chain {
            self.in_chain[v as usize] = self.row;
        }
    }

    /// Records the vertices of a strip's first triangle `t`, which leaves
    /// through slot `exit` (if any), in run order (the vertex off the exit
    /// edge first).
    fn record_start(&mut self, t: u32, exit: Option<usize>) {
        let tri = self.walk.tris[t as usize];
        let x = exit.unwrap_or(0);
        for k in [2, 0, 1] {
            self.record(tri[(x + k) % 3]);
        }
    }

    /// `v` as the strip meets it: through the cache and, off the chain,
    /// into the next chain.
    fn record(&mut self, v: u32) {
        self.fifo.touch(v);
        if self.in_chain[v as usize] != self.row && self.in_next[v as usize] != self.row {
            self.in_next[v as usize] = self.row;
            self.next.push(v);
        }
    }

    /// Takes `cursor`'s neighbour through slot `s` into `path` and records
    /// its new vertex.
    fn extend(&mut self, cursor: &mut Cursor, s: usize, path: &mut Vec<u32>) {
        let v = self.walk.apex(cursor.cur, s);
        let n = cursor.advance(self.walk.adj, s);
        self.walk.take(n);
        self.record(v);
        path.push(n);
    }

    /// Whether meeting `v` would pass the row's limits.
    fn over(&self, v: u32) -> bool {
        let new = self.in_chain[v as usize] != self.row && self.in_next[v as usize] != self.row;
        (new && self.next.len() >= ROW_NEW)
            || (!self.fifo.holds(v) && self.fifo.now - self.row_since >= ROW_MISSES)
    }

    /// A new strip along `chain` from chain vertex `i` (which has a free
    /// triangle): it starts at the free triangle across the chain's edge
    /// at `i`, turned back around the vertex through its free fan, or at any
    /// free triangle around it.
    fn fan_strip(&mut self, chain: &[u32], i: usize) -> (Vec<u32>, usize, End) {
        let walk = &*self.walk;
        let c = chain[i];
        let fan = self.by_vertex.of(c);
        let across = chain.get(i + 1).and_then(|&d| self.free_across(c, d));
        let mut start = match across {
            Some(t) => t,
            None => *fan
                .iter()
                .find(|&&t| walk.is_free(t))
                .expect("a row starts a strip at a vertex with a free triangle"),
        };
        // Turn back around `c`, away from the next chain vertex, while the
        // fan is free (at most once around it, and at most MAX_BACK_FAN).
        let mut from = chain.get(i + 1).copied();
        for _ in 0..fan.len().min(MAX_BACK_FAN) {
            let tri = walk.tris[start as usize];
            let k = tri.iter().position(|&v| v == c).expect("c is in its fan");
            let (s, far) = if Some(tri[(k + 1) % 3]) == from {
                ((k + 2) % 3, tri[(k + 2) % 3])
            } else if Some(tri[(k + 2) % 3]) == from {
                (k, tri[(k + 1) % 3])
            } else {
                break;
            };
            let n = walk.adj.neighbours[start as usize][s];
            if !walk.is_free(n) || n == across.unwrap_or(u32::MAX) {
                break;
            }
            from = Some(far);
            start = n;
        }
        self.walk.take(start);
        self.fan_walk(chain, i, start)
    }

    /// Grows a strip from its just taken first triangle `start` around the
    /// chain's vertices from `i` on. Returns its path, the chain index it
    /// stopped at and why.
    fn fan_walk(&mut self, chain: &[u32], mut i: usize, start: u32) -> (Vec<u32>, usize, End) {
        let mut path = vec![start];
        let mut cursor = Cursor::at_back(self.walk, &path);
        loop {
            let walk = &*self.walk;
            let tri = walk.tris[cursor.cur as usize];
            while i + 1 < chain.len() && tri.contains(&chain[i]) && tri.contains(&chain[i + 1]) {
                i += 1;
            }
            let pivot = chain[i];
            // Free exits through the pivot: one off the chain first, then
            // one without a swap.
            let mut best: Option<((bool, bool), usize)> = None;
            for s in 0..3 {
                let (a, b) = (tri[s], tri[(s + 1) % 3]);
                if Some(s) == cursor.entry || (a != pivot && b != pivot) {
                    continue;
                }
                if !walk.is_free(walk.adj.neighbours[cursor.cur as usize][s]) {
                    continue;
                }
                let far = if a == pivot { b } else { a };
                let key = (
                    self.in_chain[far as usize] == self.row,
                    cursor.swaps_through(s),
                );
                if best.is_none_or(|(k, _)| key < k) {
                    best = Some((key, s));
                }
            }
            if path.len() == 1 {
                self.record_start(start, best.map(|(_, s)| s));
            }
            let Some((_, s)) = best else {
                return (path, i, End::Blocked);
            };
            let v = self.walk.apex(cursor.cur, s);
            if self.over(v) {
                return (path, i, End::Full);
            }
            self.extend(&mut cursor, s, &mut path);
        }
    }

    /// The first strip of a band, grown greedily from `start` until it has
    /// missed the cache [`FIRST_MISSES`] times.
    fn first_strip(&mut self, start: u32) -> Vec<u32> {
        self.walk.take(start);
        let mut path = vec![start];
        let mut cursor = Cursor::at_back(self.walk, &path);
        loop {
            let walk = &*self.walk;
            let ns = walk.adj.neighbours[cursor.cur as usize];
            let mut best: Option<((bool, bool, u8), usize)> = None;
            for (s, &n) in ns.iter().enumerate() {
                if Some(s) == cursor.entry || !walk.is_free(n) {
                    continue;
                }
                let v = walk.apex(cursor.cur, s);
                let key = (
                    cursor.swaps_through(s),
                    !self.fifo.holds(v),
                    walk.free_neighbours(n),
                );
                if best.is_none_or(|(k, _)| key < k) {
                    best = Some((key, s));
                }
            }
            if path.len() == 1 {
                self.record_start(start, best.map(|(_, s)| s));
            }
            let Some((_, s)) = best else { return path };
            let v = self.walk.apex(cursor.cur, s);
            if !self.fifo.holds(v) && self.fifo.now - self.row_since >= FIRST_MISSES {
                return path;
            }
            self.extend(&mut cursor, s, &mut path);
        }
    }

    /// The side of `path` with more vertices that have a free triangle, as
    /// a chain: the vertices of that side's outer edges in path order.
    ///
    /// Each inner triangle of a path has one edge shared with neither
    /// neighbour in the path; it lies on the left when the exit slot
    /// follows the entry slot, on the right otherwise. The end triangles
    /// have one outer edge on each side.
    fn side_chain(&self, path: &[u32]) -> Vec<u32> {
        let walk = &*self.walk;
        let n = path.len();
        if n == 1 {
            return walk.tris[path[0] as usize].to_vec();
        }
        let mut sides: [Vec<u32>; 2] = Default::default();
        let mut push = |side: usize, first: u32, second: u32| {
            let c = &mut sides[side];
            for v in [first, second] {
                if !c.contains(&v) {
                    c.push(v);
                }
            }
        };
        for k in 0..n {
            let t = path[k];
            let tri = walk.tris[t as usize];
            let entry = (k > 0).then(|| slot_to(walk.adj, t, path[k - 1]));
            let exit = (k + 1 < n).then(|| slot_to(walk.adj, t, path[k + 1]));
            match (entry, exit) {
                (Some(e), Some(x)) => {
                    let o = 3 - e - x;
                    // The outer edge's vertex on the entry edge comes first.
                    let (a, b) = if o == (e + 1) % 3 {
                        (tri[(e + 1) % 3], tri[(o + 1) % 3])
                    } else {
                        (tri[e], tri[o])
                    };
                    push(usize::from(x == (e + 1) % 3), a, b);
                }
                (None, Some(x)) => {
                    // Left outer edge: slot x + 1, right: slot x + 2; the
                    // vertex off the exit edge comes first.
                    push(1, tri[(x + 2) % 3], tri[(x + 1) % 3]);
                    push(0, tri[(x + 2) % 3], tri[x]);
                }
                (Some(e), None) => {
                    // Left outer edge: slot e + 2, right: slot e + 1; the
                    // vertex on the entry edge comes first.
                    push(1, tri[e], tri[(e + 2) % 3]);
                    push(0, tri[(e + 1) % 3], tri[(e + 2) % 3]);
                }
                (None, None) => unreachable!("paths of one triangle return early"),
            }
        }
        let free = |c: &Vec<u32>| c.iter().filter(|&&v| self.has_free(v)).count();
        let [left, right] = sides;
        if free(&left) >= free(&right) {
            left
        } else {
            right
        }
    }
}

/// Strips every free triangle in cache order, appending one path per strip
/// (each to be encoded front first: the cache was simulated in that order).
///
/// Cost: O(T + V) time and memory, plus O(valence) per chain vertex and
/// O(first strip²) per band for its side chain (at most a few dozen
/// triangles).
pub(super) fn strip_cache_aware(
    walk: &mut Walk<'_>,
    vertex_count: usize,
    paths: &mut Vec<Vec<u32>>,
) {
    let by_vertex = VertexTriangles::new(walk.tris, vertex_count);
    let mut rows = Rows {
        walk,
        by_vertex,
        fifo: VertexFifo::new(vertex_count),
        in_chain: vec![0; vertex_count],
        in_next: vec![0; vertex_count],
        row: 0,
        row_since: 0,
        next: Vec::new(),
    };
    let mut chain: Vec<u32> = Vec::new();
    loop {
        if chain.iter().any(|&v| rows.has_free(v)) {
            rows.begin_row(&chain);
            let mut i = 0;
            while i < chain.len() {
                if !rows.has_free(chain[i]) {
                    i += 1;
                    continue;
                }
                let (path, end, why) = rows.fan_strip(&chain, i);
                paths.push(path);
                if why == End::Full {
                    break;
                }
                i = end + 1;
            }
            chain = std::mem::take(&mut rows.next);
            continue;
        }
        let Some(start) =
            cached_start(rows.walk, &rows.fifo, &rows.by_vertex).or_else(|| rows.walk.pop_start())
        else {
            break;
        };
        rows.begin_row(&[]);
        let path = rows.first_strip(start);
        chain = rows.side_chain(&path);
        paths.push(path);
    }
    join_consecutive(rows.walk.adj, paths);
}

/// Joins each path to the next where the first's last triangle is a
/// neighbour of the next's first: the order the cache sees is unchanged,
/// and a restart and two starting vertices are saved for at most a swap.
fn join_consecutive(adj: &TriangleAdjacency, paths: &mut Vec<Vec<u32>>) {
    let mut out: Vec<Vec<u32>> = Vec::with_capacity(paths.len());
    for p in paths.drain(..) {
        if let Some(last) = out.last_mut() {
            let back = *last.last().expect("paths are not empty");
            if adj.neighbours[back as usize].contains(&p[0]) {
                last.extend_from_slice(&p);
                continue;
            }
        }
        out.push(p);
    }
    *paths = out;
}
