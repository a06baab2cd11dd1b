//! Triangle order for the post-transform vertex cache: what an indexed
//! triangle list (a glTF level, which has no strips) is drawn in.
//!
//! Follows Tom Forsyth, "Linear-speed vertex cache optimisation" (2006):
//! every vertex has a score from its place in a modelled LRU cache (the
//! three vertices of the last triangle a fixed score, older entries a score
//! decaying with their place) plus a boost that falls with the number of
//! triangles still to draw around it (finishing a vertex off frees its
//! slot for good); every triangle scores the sum of its vertices'; the best
//! triangle next to the cache is drawn, the cache updated, and only the
//! scores of vertices that moved in the cache (and of their triangles)
//! recomputed. Where no triangle touches the cache (a finished region),
//! the next undrawn triangle in input order starts a new one, which keeps
//! the whole pass O(triangles × cache size × valence) rather than
//! rescanning every triangle.
//!
//! Constants, tuned on eight meshes (three generated, five shared scans and
//! CAD models) for the 16-entry FIFO ACMR that every figure here uses
//! (`strip::acmr`): Forsyth's 32-entry cache, last-triangle score 0.75 and
//! valence boost `2 / sqrt(valence)`, but a cache score falling linearly
//! with age instead of his power 1.5 (mean ACMR 0.690 against 0.699; a
//! cache of 16, 24 or 40 entries, a boost of 1 or 3, a last-triangle score
//! of 0.5 or 0.9 all measured worse or no better). meshoptimizer's tuned
//! `optimizeVertexCache` reaches 0.672 on the same meshes; the comparison
//! is a test in `tests/export.rs`.

/// Entries of the modelled LRU cache.
const CACHE: usize = 32;
/// Score of a vertex of the last triangle drawn (Forsyth: below that of the
/// entry just after them, so the next triangle does not reuse all three).
const LAST_TRIANGLE_SCORE: f32 = 0.75;
/// Boost of a vertex with one triangle left to draw; `valence^-0.5` times
/// this for more.
const VALENCE_BOOST: f32 = 2.0;
/// Valences scored from the table; larger ones score as this one (the
/// boost is nearly flat there).
const MAX_VALENCE: usize = 64;

/// Not in the cache.
const OUTSIDE: u32 = u32::MAX;

/// The triangles in an order that reuses the post-transform vertex cache
/// (see the module docs); each triangle keeps its corners and their order,
/// so winding is unchanged. Indices must be below `vertex_count`.
/// Deterministic: ties go to the earlier triangle.
///
/// # Panics
/// If an index is not below `vertex_count`.
///
/// Cost: O(triangles × 35 × mean valence) time, O(vertices + triangles)
/// memory.
#[must_use]
pub fn reorder_for_vertex_cache(triangles: &[[u32; 3]], vertex_count: usize) -> Vec<[u32; 3]> {
    let n = vertex_count;
    // Triangles around each vertex, as offsets into one list.
    let mut start = vec![0u32; n + 1];
    for &v in triangles.iter().flatten() {
        assert!((v as usize) < n, "index {v} of {n} vertices");
        start[v as usize + 1] += 1;
    }
    for v in 0..n {
        start[v + 1] += start[v];
    }
    let mut around = vec![0u32; start[n] as usize];
    let mut fill = start.clone();
    for (t, tri) in triangles.iter().enumerate() {
        for &v in tri {
            around[fill[v as usize] as usize] = t as u32;
            fill[v as usize] += 1;
        }
    }
    let mut live: Vec<u32> = (0..n).map(|v| start[v + 1] - start[v]).collect();
    let position_score = position_scores();
    let valence_score = valence_scores();
    let score = |place: u32, live: u32| -> f32 {
        if live == 0 {
            return -1.0;
        }
        let cached = if place == OUTSIDE {
            0.0
        } else {
            position_score[place as usize]
        };
        cached + valence_score[(live as usize).min(MAX_VALENCE)]
    };
    let mut place = vec![OUTSIDE; n];
    let mut vertex_score: Vec<f32> = (0..n).map(|v| score(OUTSIDE, live[v])).collect();
    let mut triangle_score: Vec<f32> = triangles
        .iter()
        .map(|t| t.iter().map(|&v| vertex_score[v as usize]).sum())
        .collect();
    let mut drawn = vec![false; triangles.len()];
    let mut out = Vec::with_capacity(triangles.len());
    // The cache, most recent first, with room for the three a triangle
    // pushes past its end (their scores fall when they leave).
    let mut cache: Vec<u32> = Vec::with_capacity(CACHE + 3);
    let mut next_cache: Vec<u32> = Vec::with_capacity(CACHE + 3);
    let mut cursor = 0;
    let mut best = best_start(&triangle_score);
    while let Some(t) = best {
        let tri = triangles[t];
        drawn[t] = true;
        out.push(tri);
        next_cache.clear();
        next_cache.extend_from_slice(&tri);
        next_cache.extend(cache.iter().filter(|v| !tri.contains(v)));
        for &v in &tri {
            live[v as usize] -= 1;
        }
        for (i, &v) in next_cache.iter().enumerate() {
            let p = if i < CACHE { i as u32 } else { OUTSIDE };
            place[v as usize] = p;
            vertex_score[v as usize] = score(p, live[v as usize]);
        }
        best = None;
        let mut best_score = f32::NEG_INFINITY;
        for &v in &next_cache {
            let v = v as usize;
            for &u in &around[start[v] as usize..start[v + 1] as usize] {
                let u = u as usize;
                if drawn[u] {
                    continue;
                }
                let s: f32 = triangles[u].iter().map(|&w| vertex_score[w as usize]).sum();
                triangle_score[u] = s;
                if s > best_score || (s == best_score && best.is_some_and(|b| u < b)) {
                    best_score = s;
                    best = Some(u);
                }
            }
        }
        next_cache.truncate(CACHE);
        std::mem::swap(&mut cache, &mut next_cache);
        if best.is_none() {
            while cursor < triangles.len() && drawn[cursor] {
                cursor += 1;
            }
            best = (cursor < triangles.len()).then_some(cursor);
        }
    }
    debug_assert_eq!(out.len(), triangles.len(), "every triangle drawn once");
    out
}

/// The first triangle: the best scored (all vertices outside the cache, so
/// the one whose vertices have the fewest triangles: a border or corner).
fn best_start(scores: &[f32]) -> Option<usize> {
    let mut best: Option<(usize, f32)> = None;
    for (t, &s) in scores.iter().enumerate() {
        if best.is_none_or(|(_, b)| s > b) {
            best = Some((t, s));
        }
    }
    best.map(|(t, _)| t)
}

/// Score of each cache place.
fn position_scores() -> [f32; CACHE] {
    let mut table = [0.0; CACHE];
    for (i, s) in table.iter_mut().enumerate() {
        *s = if i < 3 {
            LAST_TRIANGLE_SCORE
        } else {
            1.0 - (i - 3) as f32 / (CACHE - 3) as f32
        };
    }
    table
}

/// Boost of each valence (triangles left), 0 unused.
fn valence_scores() -> [f32; MAX_VALENCE + 1] {
    let mut table = [0.0; MAX_VALENCE + 1];
    for (k, s) in table.iter_mut().enumerate().skip(1) {
        *s = VALENCE_BOOST / (k as f32).sqrt();
    }
    table
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::strip::acmr::{fifo_acmr, CACHE_SIZE};
    use crate::strip::sorted_canonical;

    /// A grid of `w × h` quads, two triangles each, listed column by column
    /// so that the input order reuses the cache badly.
    fn grid_by_columns(w: u32, h: u32) -> (Vec<[u32; 3]>, usize) {
        let id = |x: u32, y: u32| y * (w + 1) + x;
        let mut t = Vec::new();
        for x in 0..w {
            for y in 0..h {
                let (a, b, c, d) = (id(x, y), id(x + 1, y), id(x + 1, y + 1), id(x, y + 1));
                t.push([a, b, c]);
                t.push([a, c, d]);
            }
        }
        (t, ((w + 1) * (h + 1)) as usize)
    }

    #[test]
    fn every_triangle_comes_out_once_with_its_winding() {
        let (t, n) = grid_by_columns(20, 30);
        let out = reorder_for_vertex_cache(&t, n);
        assert_eq!(out.len(), t.len());
        // The same oriented triangles, each with its corners in their order.
        assert_eq!(sorted_canonical(&out), sorted_canonical(&t));
        let mut a = out.clone();
        let mut b = t.clone();
        a.sort_unstable();
        b.sort_unstable();
        assert_eq!(a, b);
    }

    /// ```text
    ///  3---2
    ///  | / |      two triangles sharing the edge 0-2, and a lone one
    ///  0---1      4-5-6: the pair is drawn together, the lone one after
    /// ```
    #[test]
    fn a_tiny_mesh_is_drawn_neighbour_after_neighbour() {
        let t = [[4, 5, 6], [0, 1, 2], [0, 2, 3]];
        let out = reorder_for_vertex_cache(&t, 7);
        // 4-5-6 starts (three vertices of one triangle each: the largest
        // valence boost); then nothing touches the cache and input order
        // resumes with the pair.
        assert_eq!(out, vec![[4, 5, 6], [0, 1, 2], [0, 2, 3]]);
    }

    #[test]
    fn a_badly_ordered_grid_reuses_the_cache_after_reordering() {
        let (t, n) = grid_by_columns(60, 200);
        let before = fifo_acmr(&t, n, CACHE_SIZE);
        let after = fifo_acmr(&reorder_for_vertex_cache(&t, n), n, CACHE_SIZE);
        // Columns 200 quads long reuse nothing across columns: about one
        // vertex per triangle. A good order approaches 0.5 (each vertex
        // once for its six triangles would be 0.5 on an infinite grid).
        assert!(before > 0.99, "{before}");
        assert!(after < 0.7, "{after}");
    }

    #[test]
    fn empty_and_isolated_triangles() {
        assert!(reorder_for_vertex_cache(&[], 0).is_empty());
        let t: Vec<[u32; 3]> = (0..50).map(|i| [3 * i, 3 * i + 1, 3 * i + 2]).collect();
        assert_eq!(reorder_for_vertex_cache(&t, 150), t);
    }
}
