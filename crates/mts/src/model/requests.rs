//! Request sequences: the LoD requests of the MTS paper's Table 2 (section 5.2):
//! linear, exponential and random. The paper does not define them beyond
//! their names; these definitions are ours, shared by the benches, `mts
//! bench` and the baselines so every method sees the same requests.

/// The three sequences of Table 2 by name, `n` requests each, over the LoD
/// → triangle count table `counts` (`counts.len() - 1` is the coarsest
/// LoD): linear, exponential and random (seed 1). What every measurement of
/// LoD-change cost runs, so all methods see the same requests.
#[must_use]
pub fn table2(counts: &[u32], n: usize) -> [(&'static str, Vec<usize>); 3] {
    let max_lod = counts.len().saturating_sub(1);
    [
        ("linear", linear(max_lod, n)),
        ("exponential", exponential(counts, n)),
        ("random", random(max_lod, n, 1)),
    ]
}

/// `n` LoDs from the coarsest (`max_lod`) to the finest (0) in equal steps
/// (`n = max_lod + 1` visits every LoD once).
#[must_use]
pub fn linear(max_lod: usize, n: usize) -> Vec<usize> {
    match n {
        0 => Vec::new(),
        1 => vec![max_lod],
        _ => (0..n)
            .map(|i| max_lod - (i as f64 * max_lod as f64 / (n - 1) as f64).round() as usize)
            .collect(),
    }
}

/// `n` LoDs from the coarsest to the finest whose triangle counts grow
/// geometrically (each request about the same factor finer than the last),
/// read through the LoD → triangle count table `counts` (non-increasing,
/// `counts[0]` the full mesh).
#[must_use]
pub fn exponential(counts: &[u32], n: usize) -> Vec<usize> {
    let Some(max_lod) = counts.len().checked_sub(1) else {
        return Vec::new();
    };
    let (lo, hi) = (
        f64::from(counts[max_lod].max(1)),
        f64::from(counts[0].max(1)),
    );
    (0..n)
        .map(|i| {
            let t = if n == 1 {
                0.0
            } else {
                i as f64 / (n - 1) as f64
            };
            let budget = (lo * (hi / lo).powf(t)).round() as u32;
            // The finest LoD with at most `budget` triangles.
            counts.partition_point(|&c| c > budget).min(max_lod)
        })
        .collect()
}

/// `n` LoDs drawn uniformly from `0..=max_lod` (SplitMix64 from `seed`,
/// so a run is repeatable).
#[must_use]
pub fn random(max_lod: usize, n: usize, seed: u64) -> Vec<usize> {
    let mut state = seed;
    (0..n)
        .map(|_| {
            state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
            let mut z = state;
            z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
            z ^= z >> 31;
            (z % (max_lod as u64 + 1)) as usize
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn linear_runs_from_coarsest_to_finest() {
        assert_eq!(linear(10, 3), vec![10, 5, 0]);
        assert_eq!(linear(4, 5), vec![4, 3, 2, 1, 0]);
        assert_eq!(linear(7, 1), vec![7]);
    }

    #[test]
    fn exponential_multiplies_the_triangle_count() {
        // 2 triangles per LoD: 64 triangles at LoD 0, 1 at LoD 32 (clamped).
        let counts: Vec<u32> = (0..=32u32).map(|l| (64 - 2 * l).max(1)).collect();
        let lods = exponential(&counts, 7);
        let tris: Vec<u32> = lods.iter().map(|&l| counts[l]).collect();
        assert_eq!(tris, vec![1, 2, 4, 8, 16, 32, 64]);
        assert_eq!(lods.first(), Some(&32));
        assert_eq!(lods.last(), Some(&0));
    }

    #[test]
    fn random_is_repeatable_and_in_range() {
        let a = random(100, 1000, 7);
        assert_eq!(a, random(100, 1000, 7));
        assert_ne!(a, random(100, 1000, 8));
        assert!(a.iter().all(|&l| l <= 100));
        // Every decile is hit.
        for d in 0..10 {
            assert!(a.iter().any(|&l| l / 10 == d));
        }
    }
}
