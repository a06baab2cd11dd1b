//! Modelled vertex-shader invocations of an index buffer as the GPU reads
//! it, under three post-transform cache models:
//!
//! - **FIFO** of `n` entries (Hoppe 1999, "Optimization of mesh locality
//!   for transparent vertex caching"): the model behind every ACMR figure
//!   ([`super::acmr::fifo_acmr`] over triangles; here over the index stream,
//!   which gives the same misses since a hit does not change a FIFO).
//! - **Batch** of `n` indices (Kerbl, Kenzel, Schmalstieg, Steinberger 2018,
//!   "Revisiting the vertex cache: understanding and optimizing vertex
//!   processing on the modern GPU", sections 4–5): the input assembler cuts
//!   the index buffer into batches of `n` consecutive indices (they measured
//!   96 on NVIDIA, 384 on AMD) and shades each distinct vertex once per batch;
//!   there is no reuse across batches.
//! - **LRU** of `n` entries: the textbook cache, as an upper bound on what a
//!   reuse-aware unit can do with `n` slots.
//!
//! Decision, for strips in the batch model: restart values **count** toward
//! the `n` indices of a batch. The assembler reads them from the buffer like
//! any index (Kerbl et al. batch by index-buffer position), so a buffer of
//! short strips fills its batches with fewer real vertices; not counting them
//! would flatter strips. A triangle belongs to the batch holding its last
//! index; a batch shades the distinct vertices of its triangles, so a strip
//! crossing a batch boundary shades its two carried vertices again. Windows
//! with a repeated vertex (swaps, stitching) are assembled and then culled, so
//! their vertices are shaded too.

use super::encode::RESTART_U32;
use crate::lod::Topology;

/// A post-transform cache model; the number is its size (entries, or
/// indices per batch).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CacheModel {
    /// First in, first out, `n` vertices.
    Fifo(u32),
    /// Reuse only inside batches of `n` consecutive indices.
    Batch(u32),
    /// Least recently used, `n` vertices.
    Lru(u32),
    /// Least recently used, `n` vertices, emptied at every primitive
    /// restart: what Mesa's lavapipe measured (docs/experiments/vertex-work.md:
    /// the cache-aware strips' 6,422 runs on the bunny shade 1.186
    /// vertices per triangle there, the sum of the runs' distinct vertices
    /// is 1.185, FIFO 16 models 0.626). For a list or a stitched buffer it
    /// is [`CacheModel::Lru`].
    LruPerRun(u32),
}

/// The models reported beside measured invocations: FIFO 16 (the ACMR of
/// every earlier figure), batches of 96 (NVIDIA) and 384 (AMD) after Kerbl
/// et al. 2018, LRU 32, and LRU 32 emptied at every restart (lavapipe).
pub const REPORTED_MODELS: [(&str, CacheModel); 5] = [
    ("fifo16", CacheModel::Fifo(16)),
    ("batch96", CacheModel::Batch(96)),
    ("batch384", CacheModel::Batch(384)),
    ("lru32", CacheModel::Lru(32)),
    ("lru32_run", CacheModel::LruPerRun(32)),
];

/// The two figures strips are held to against a triangle list (issue 24):
/// the FIFO-16 ACMR of `triangles` in their order, and their invocations
/// per triangle in batches of 96 indices.
///
/// # Panics
/// If an index is not below `vertex_count`.
#[must_use]
pub fn list_fifo16_batch96(triangles: &[[u32; 3]], vertex_count: usize) -> (f64, f64) {
    let flat: Vec<u32> = triangles.iter().flatten().copied().collect();
    (
        super::acmr::fifo_acmr(triangles, vertex_count, super::acmr::CACHE_SIZE),
        vertex_work(&flat, Topology::TriangleList, CacheModel::Batch(96)).per_triangle(),
    )
}

/// Vertex work of one index buffer under one model.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct VertexWork {
    /// Vertex-shader invocations the model predicts.
    pub invocations: u64,
    /// Non-degenerate triangles assembled.
    pub triangles: u64,
    /// Indices read, restart values included.
    pub indices: u64,
}

impl VertexWork {
    /// Invocations per non-degenerate triangle (0 for none): the ACMR of
    /// the model.
    #[must_use]
    pub fn per_triangle(&self) -> f64 {
        if self.triangles == 0 {
            0.0
        } else {
            self.invocations as f64 / self.triangles as f64
        }
    }
}

/// The triangles `indices` assembles to under `topology`, as (position of
/// the triangle's last index, its three vertices), degenerate windows
/// included. Cost: O(indices), no allocation.
fn windows(indices: &[u32], topology: Topology) -> impl Iterator<Item = (usize, [u32; 3])> + '_ {
    let step = if topology == Topology::TriangleList {
        3
    } else {
        1
    };
    (0..indices.len().saturating_sub(2))
        .step_by(step)
        .map(move |i| (i + 2, [indices[i], indices[i + 1], indices[i + 2]]))
        .filter(|(_, t)| !t.contains(&RESTART_U32))
}

/// Modelled vertex-shader invocations of `indices` assembled as
/// `topology` under `model`. Indices may be any `u32` but [`RESTART_U32`],
/// which only [`Topology::StripRestart`] gives a meaning (a list never
/// holds it).
///
/// Invariants (property-tested): distinct vertices ≤ invocations ≤ vertex
/// references; a batch larger than the buffer, or a cache larger than the
/// distinct vertices, gives the distinct vertices.
///
/// # Panics
/// If `model`'s size is 0.
///
/// Cost: O(indices) plus one allocation of the largest index (FIFO, LRU,
/// batch) and O(indices · n) worst case for the LRU's linear scan of its
/// `n` entries.
#[must_use]
pub fn vertex_work(indices: &[u32], topology: Topology, model: CacheModel) -> VertexWork {
    let triangles = windows(indices, topology)
        .filter(|(_, [a, b, c])| a != b && b != c && a != c)
        .count() as u64;
    let used = match topology {
        Topology::TriangleList => &indices[..indices.len() / 3 * 3],
        Topology::StripRestart => indices,
    };
    let vertex_count = used
        .iter()
        .filter(|&&v| v != RESTART_U32)
        .max()
        .map_or(0, |&m| m as usize + 1);
    let invocations = match model {
        CacheModel::Fifo(n) => fifo(used, vertex_count, n),
        CacheModel::Batch(n) => batch(used, topology, vertex_count, n),
        CacheModel::Lru(n) => lru(used, n, false),
        CacheModel::LruPerRun(n) => lru(used, n, true),
    };
    VertexWork {
        invocations,
        triangles,
        indices: indices.len() as u64,
    }
}

/// FIFO misses over the vertex references (restart values skipped), with
/// the timestamp trick of [`super::acmr::fifo_acmr`].
fn fifo(indices: &[u32], vertex_count: usize, n: u32) -> u64 {
    assert!(n > 0, "a FIFO cache needs at least one entry");
    let mut stamp = vec![0u64; vertex_count];
    let n = u64::from(n);
    let mut now = n + 1;
    let mut misses = 0;
    for &v in indices.iter().filter(|&&v| v != RESTART_U32) {
        let s = &mut stamp[v as usize];
        if now - *s > n {
            *s = now;
            now += 1;
            misses += 1;
        }
    }
    misses
}

/// Distinct vertices of the triangles of each batch of `n` indices, summed.
fn batch(indices: &[u32], topology: Topology, vertex_count: usize, n: u32) -> u64 {
    assert!(n > 0, "a batch holds at least one index");
    let n = n as usize;
    // `seen[v]` is 1 + the batch that last shaded v.
    let mut seen = vec![0usize; vertex_count];
    let mut invocations = 0;
    for (last, t) in windows(indices, topology) {
        let mark = last / n + 1;
        for v in t {
            let s = &mut seen[v as usize];
            if *s != mark {
                *s = mark;
                invocations += 1;
            }
        }
    }
    invocations
}

/// LRU misses over the vertex references; restart values are skipped, or
/// empty the cache if `per_run`.
fn lru(indices: &[u32], n: u32, per_run: bool) -> u64 {
    assert!(n > 0, "an LRU cache needs at least one entry");
    // Most recent last; `n` is small (32), so a scan beats a linked map.
    let mut cache: Vec<u32> = Vec::with_capacity(n as usize);
    let mut misses = 0;
    for &v in indices {
        if v == RESTART_U32 {
            if per_run {
                cache.clear();
            }
            continue;
        }
        if let Some(i) = cache.iter().rposition(|&c| c == v) {
            cache.remove(i);
        } else {
            misses += 1;
            if cache.len() == n as usize {
                cache.remove(0);
            }
        }
        cache.push(v);
    }
    misses
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    const R: u32 = RESTART_U32;

    #[test]
    fn a_list_in_batches_of_six_shades_each_batch_apart() {
        // Two quads 0-1-2-3 and 2-3-4-5 as four triangles sharing edges:
        //   0---2---4
        //   | / | / |
        //   1---3---5
        let list = [0, 1, 2, 2, 1, 3, 2, 3, 4, 4, 3, 5];
        // Batch 6: {0,1,2,3} then {2,3,4,5}: 8. One batch of 12: 6.
        let w = vertex_work(&list, Topology::TriangleList, CacheModel::Batch(6));
        assert_eq!(
            w,
            VertexWork {
                invocations: 8,
                triangles: 4,
                indices: 12
            }
        );
        assert_eq!(
            vertex_work(&list, Topology::TriangleList, CacheModel::Batch(12)).invocations,
            6
        );
        // FIFO 16 and LRU 32 hold all six vertices.
        assert_eq!(
            vertex_work(&list, Topology::TriangleList, CacheModel::Fifo(16)).invocations,
            6
        );
        assert_eq!(
            vertex_work(&list, Topology::TriangleList, CacheModel::Lru(32)).invocations,
            6
        );
        assert_eq!(w.per_triangle(), 2.0);
    }

    #[test]
    fn a_list_is_held_to_fifo16_over_its_order_and_batches_of_96() {
        // The two quads of the test above: 6 vertices for 4 triangles in
        // FIFO 16 and in one batch; a batch of 96 holds the whole list.
        let t = [[0, 1, 2], [2, 1, 3], [2, 3, 4], [4, 3, 5]];
        assert_eq!(list_fifo16_batch96(&t, 6), (1.5, 1.5));
        // Reversed order, same vertices: the figures do not depend on it here.
        let r: Vec<[u32; 3]> = t.iter().rev().copied().collect();
        assert_eq!(list_fifo16_batch96(&r, 6), (1.5, 1.5));
    }

    #[test]
    fn a_per_run_cache_forgets_at_each_restart() {
        // Two strips sharing the edge 1-2: an LRU shades 1 and 2 once, an
        // LRU emptied at the restart twice; without restarts the two agree.
        let b = [0, 1, 2, R, 1, 2, 3];
        let per_run = vertex_work(&b, Topology::StripRestart, CacheModel::LruPerRun(32));
        let plain = vertex_work(&b, Topology::StripRestart, CacheModel::Lru(32));
        assert_eq!((per_run.invocations, plain.invocations), (6, 4));
        let one = [0, 1, 2, 3, 4];
        assert_eq!(
            vertex_work(&one, Topology::StripRestart, CacheModel::LruPerRun(2)).invocations,
            vertex_work(&one, Topology::StripRestart, CacheModel::Lru(2)).invocations
        );
    }

    #[test]
    fn restarts_count_toward_a_batch() {
        // Strip 0 1 2 3, restart, strip 4 5 6: 8 indices, 3 triangles.
        // Batch 4 = [0 1 2 3] [R 4 5 6]: 4 + 3.
        let b = [0, 1, 2, 3, R, 4, 5, 6];
        let w = vertex_work(&b, Topology::StripRestart, CacheModel::Batch(4));
        assert_eq!(
            w,
            VertexWork {
                invocations: 7,
                triangles: 3,
                indices: 8
            }
        );
        // Batch 3 = [0 1 2] [3 R 4] [5 6]: triangle (0,1,2) in batch 0,
        // (1,2,3) in batch 1 (1, 2 shaded again), (4,5,6) in batch 2.
        assert_eq!(
            vertex_work(&b, Topology::StripRestart, CacheModel::Batch(3)).invocations,
            9
        );
    }

    #[test]
    fn fifo_and_lru_differ_on_a_recently_used_vertex() {
        // Cache of 2. Stream 0 1 0 2 0: FIFO misses 0, 1, 2 then 0 again
        // (pushed out by 2 although just used): 4. LRU keeps 0 (used after
        // 1), drops 1 for 2: 3.
        let s = [0, 1, 0, R, 2, 0, 2];
        assert_eq!(fifo(&s, 3, 2), 4);
        assert_eq!(lru(&s, 2, false), 3);
    }

    #[test]
    fn degenerate_windows_are_shaded_but_not_counted() {
        // A swap: 0 1 0 2 has windows (0,1,0) degenerate, (1,0,2).
        let w = vertex_work(&[0, 1, 0, 2], Topology::StripRestart, CacheModel::Batch(96));
        assert_eq!(
            w,
            VertexWork {
                invocations: 3,
                triangles: 1,
                indices: 4
            }
        );
    }

    fn stream() -> impl Strategy<Value = (Vec<u32>, bool)> {
        (
            prop::collection::vec(prop_oneof![9 => 0u32..40, 1 => Just(R)], 0..300),
            any::<bool>(),
        )
            .prop_map(|(mut v, list)| {
                if list {
                    v.retain(|&i| i != R);
                }
                (v, list)
            })
    }

    proptest! {
        #[test]
        fn invocations_lie_between_distinct_vertices_and_references(
            (s, list) in stream(), n in 1u32..64,
        ) {
            let topology = if list { Topology::TriangleList } else { Topology::StripRestart };
            // The vertices of the assembled windows, and how often they are
            // referenced by the buffer.
            let mut distinct: Vec<u32> =
                windows(&s, topology).flat_map(|(_, t)| t).collect();
            distinct.sort_unstable();
            distinct.dedup();
            let used = if list { &s[..s.len() / 3 * 3] } else { &s[..] };
            let references = used.iter().filter(|&&v| v != R).count() as u64;
            let window_refs = 3 * windows(&s, topology).count() as u64;
            for model in [CacheModel::Fifo(n), CacheModel::Lru(n), CacheModel::LruPerRun(n)] {
                let w = vertex_work(&s, topology, model);
                // FIFO and LRU see every reference, including strips too
                // short for a triangle.
                let mut all: Vec<u32> = used.iter().copied().filter(|&v| v != R).collect();
                all.sort_unstable();
                all.dedup();
                prop_assert!(w.invocations >= all.len() as u64);
                prop_assert!(w.invocations <= references);
            }
            // Emptying the cache at restarts only adds misses.
            prop_assert!(
                vertex_work(&s, topology, CacheModel::LruPerRun(n)).invocations
                    >= vertex_work(&s, topology, CacheModel::Lru(n)).invocations
            );
            let w = vertex_work(&s, topology, CacheModel::Batch(n));
            prop_assert!(w.invocations >= distinct.len() as u64);
            prop_assert!(w.invocations <= window_refs);
            let whole = vertex_work(&s, topology, CacheModel::Batch(s.len() as u32 + 1));
            prop_assert_eq!(whole.invocations, distinct.len() as u64);
        }

        #[test]
        fn a_big_cache_shades_each_vertex_once((s, _) in stream()) {
            let mut all: Vec<u32> = s.iter().copied().filter(|&v| v != R).collect();
            all.sort_unstable();
            all.dedup();
            for model in [CacheModel::Fifo(64), CacheModel::Lru(64)] {
                let w = vertex_work(&s, Topology::StripRestart, model);
                prop_assert_eq!(w.invocations, all.len() as u64);
            }
        }

        #[test]
        fn fifo_over_the_stream_is_fifo_acmr_over_its_triangles(
            t in prop::collection::vec([0u32..30, 0u32..30, 0u32..30], 1..100),
        ) {
            let flat: Vec<u32> = t.iter().flatten().copied().collect();
            let w = vertex_work(&flat, Topology::TriangleList, CacheModel::Fifo(16));
            let acmr = super::super::acmr::fifo_acmr(&t, 30, 16);
            let misses = (acmr * t.len() as f64).round() as u64;
            prop_assert_eq!(w.invocations, misses);
        }
    }
}
