//! The post-transform vertex cache as a FIFO of `size` entries: the model
//! behind every ACMR (average cache miss ratio) figure, after Hoppe 1999,
//! "Optimization of mesh locality for transparent vertex caching", and as
//! meshoptimizer's `analyzeVertexCache` computes it without warps or
//! primitive groups (a test checks the two agree bit for bit).

/// FIFO cache size used for every ACMR figure.
pub const CACHE_SIZE: u32 = 16;

/// Vertex transforms per triangle when `triangles` are drawn in order
/// through a FIFO cache of `cache_size` entries (0 for no triangle).
/// Indices must be below `vertex_count`.
///
/// The ratio is computed in `f32`, as meshoptimizer does, so figures read
/// before this model moved into the core are unchanged.
///
/// # Panics
/// If an index is not below `vertex_count`.
///
/// Cost: O(triangles + vertices), one allocation.
#[must_use]
pub fn fifo_acmr(triangles: &[[u32; 3]], vertex_count: usize, cache_size: u32) -> f64 {
    if triangles.is_empty() {
        return 0.0;
    }
    // A vertex is in the cache while fewer than `cache_size` misses came
    // after its own: its miss's timestamp tells, without a queue.
    let mut stamp = vec![0u32; vertex_count];
    let mut now = cache_size + 1;
    let mut misses = 0u32;
    for &v in triangles.iter().flatten() {
        let s = &mut stamp[v as usize];
        if now - *s > cache_size {
            *s = now;
            now += 1;
            misses += 1;
        }
    }
    f64::from(misses as f32 / triangles.len() as f32)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_strip_of_a_grid_reuses_two_of_three() {
        // Triangles (i, i+1, i+2) of one long strip: each new triangle
        // brings one new vertex.
        let triangles: Vec<[u32; 3]> = (0..100u32).map(|i| [i, i + 1, i + 2]).collect();
        assert_eq!(fifo_acmr(&triangles, 102, 16), f64::from(102f32 / 100f32));
    }

    #[test]
    fn a_vertex_stays_for_size_minus_one_later_misses() {
        // Vertex 0, then 1, 2, 3 miss before 0 comes back: three later
        // misses. A cache of 4 still holds 0 (5 misses in all), a cache of
        // 3 has pushed it out (6).
        let t = [[0, 1, 2], [3, 0, 4]];
        assert_eq!(fifo_acmr(&t, 5, 4), f64::from(5f32 / 2f32));
        assert_eq!(fifo_acmr(&t, 5, 3), f64::from(6f32 / 2f32));
    }
}
