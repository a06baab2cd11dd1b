//! The cache-aware local pass: short strips laid side by side, in the order
//! a vertex cache reuses.
//!
//! After the strip growing of Hoppe, "Optimization of mesh locality for
//! transparent vertex caching" (SIGGRAPH 1999): strips grown against a
//! simulated FIFO, each next strip begun beside the previous one's first
//! face (followed from memory of the paper, which is not in
//! `../shared/papers`; the stopping rules are ours). The
//! pass simulates a FIFO of [`CACHE_SIZE`] vertices over the triangles in the
//! order it takes them. A strip grows forward only (its run is encoded front
//! first), prefers a neighbour whose new vertex is cached, and stops when it
//! leaves the strip it runs along or has brought too many new vertices
//! ([`VertexFifo::step`]), so that the next strip, begun beside the last
//! strip's first triangles, runs along it the same way while the FIFO still
//! holds their shared row. Where the last strip has no free neighbour the
//! next starts at the free triangle with most cached vertices, oldest
//! first, and where none touches the cache, where the plain local pass
//! would ([`Walk::pop_start`]).
//!
//! On a regular grid this lays strips of seven quads side by side (ACMR
//! about 0.57 away from band ends); on scanned meshes it falls short of a
//! cache-ordered list (docs/experiments/vertex-work.md).

use super::greedy::Walk;
use crate::strip::acmr::CACHE_SIZE;

/// A FIFO of the last [`CACHE_SIZE`] distinct vertices missed, as
/// [`crate::strip::acmr::fifo_acmr`] models it, and the misses of the
/// strip being grown.
pub(super) struct VertexFifo {
    /// When each vertex last entered the cache, in misses (0: never).
    stamp: Vec<u32>,
    /// Misses so far, plus `CACHE_SIZE + 1` so that stamp 0 is never held.
    now: u32,
    /// The cached vertices as a ring: slot `now % CACHE_SIZE` holds the
    /// oldest (or `u32::MAX` before the cache fills).
    ring: [u32; CACHE_SIZE as usize],
    /// Misses since the current strip started.
    strip_misses: u32,
    /// Hits since the current strip started.
    strip_hits: u32,
    /// Misses in a row at the strip's end.
    miss_run: u32,
}

impl VertexFifo {
    /// New vertices after which a strip that reuses stops. A strip of `w`
    /// quads along the previous one brings about `w + 1` new vertices.
    const STRIP_MISSES: u32 = 20;
    /// New vertices after which a strip that has reused none (the first of
    /// a band) stops: it brings two per quad, and the next strip finds its
    /// first row cached only if fewer than [`CACHE_SIZE`] came after it.
    const FIRST_STRIP_MISSES: u32 = 12;
    /// Misses in a row after which a strip that reuses stops: it has left
    /// the strip it was laid along.
    const MISS_RUN: u32 = 3;
    /// Score bonus (in free neighbours, as the swap penalty) of a candidate
    /// whose new vertex is cached.
    pub(super) const HIT_BONUS: f32 = 1.0;
    /// Swap penalty of the cache-aware pass (see
    /// [`super::StripifyOptions::swap_penalties`]).
    pub(super) const SWAP_PENALTY: f32 = 1.5;

    fn new(vertex_count: usize) -> VertexFifo {
        VertexFifo {
            stamp: vec![0; vertex_count],
            now: CACHE_SIZE + 1,
            ring: [u32::MAX; CACHE_SIZE as usize],
            strip_misses: 0,
            strip_hits: 0,
            miss_run: 0,
        }
    }

    /// Misses since `v` entered the cache (1: the newest), if it is cached.
    fn age(&self, v: u32) -> Option<u32> {
        let a = self.now - self.stamp[v as usize];
        (a <= CACHE_SIZE).then_some(a)
    }

    /// Whether `v` is cached.
    pub(super) fn holds(&self, v: u32) -> bool {
        self.age(v).is_some()
    }

    /// References `v`: a miss enters it (pushing out the oldest). Returns
    /// whether it was a hit.
    fn touch(&mut self, v: u32) -> bool {
        if self.holds(v) {
            return true;
        }
        self.stamp[v as usize] = self.now;
        self.ring[(self.now % CACHE_SIZE) as usize] = v;
        self.now += 1;
        self.strip_misses += 1;
        false
    }

    /// Starts a strip with triangle `t`.
    fn start(&mut self, t: &[u32; 3]) {
        self.strip_misses = 0;
        self.strip_hits = 0;
        self.miss_run = 0;
        for &v in t {
            self.touch(v);
        }
    }

    /// References the new vertex `v` of the strip's next triangle; returns
    /// whether the strip should stop there.
    pub(super) fn step(&mut self, v: u32) -> bool {
        if self.touch(v) {
            self.strip_hits += 1;
            self.miss_run = 0;
        } else {
            self.miss_run += 1;
        }
        if self.strip_hits > 0 {
            self.miss_run >= Self::MISS_RUN || self.strip_misses >= Self::STRIP_MISSES
        } else {
            self.strip_misses >= Self::FIRST_STRIP_MISSES
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

/// The first free neighbour of the last strip's triangles, from its first
/// triangle on: where a strip laid along it starts.
fn beside_start(walk: &Walk<'_>, last: &[u32]) -> Option<u32> {
    last.iter()
        .flat_map(|&t| walk.adj.neighbours[t as usize])
        .find(|&n| walk.is_free(n))
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

/// Strips every free triangle in cache order, appending one path per strip
/// (each to be encoded front first: the cache was simulated in that order).
///
/// Cost: O(T + V) time and memory; each strip start scans the triangles
/// around the [`CACHE_SIZE`] cached vertices.
pub(super) fn strip_cache_aware(
    walk: &mut Walk<'_>,
    vertex_count: usize,
    paths: &mut Vec<Vec<u32>>,
) {
    let by_vertex = VertexTriangles::new(walk.tris, vertex_count);
    let mut fifo = VertexFifo::new(vertex_count);
    walk.swap_penalty = VertexFifo::SWAP_PENALTY;
    let mut last: Vec<u32> = Vec::new();
    while let Some(start) = beside_start(walk, &last)
        .or_else(|| cached_start(walk, &fifo, &by_vertex))
        .or_else(|| walk.pop_start())
    {
        walk.take(start);
        fifo.start(&walk.tris[start as usize]);
        let mut path = vec![start];
        walk.grow_back(&mut path, Some(&mut fifo));
        last.clone_from(&path);
        paths.push(path);
    }
}
