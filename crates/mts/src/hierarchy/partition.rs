//! Cuts triangles into connected clusters of bounded size: triangles in
//! Morton order of their centroids seed breadth-first growth over shared
//! vertices (our own scheme; meshoptimizer's `buildMeshlets` also grows
//! clusters from a seed, scoring candidates by the vertices they add).
//! Growth from the first unassigned triangle in Morton order keeps clusters
//! compact and the leftovers next to each other.

use glam::Vec3;
use std::collections::VecDeque;

/// Splits `triangles` (indices into `positions`) into clusters of at most
/// `max_triangles` triangles, each connected through shared vertices;
/// returns each cluster's triangles as indices into `triangles`, every
/// triangle in exactly one cluster. Clusters smaller than a quarter of the
/// limit are merged into the neighbour they share the most vertices with
/// when it has room for them (up to 1.5 times the limit).
///
/// Cost: O(T log T) for the Morton sort, O(T) for the growth.
#[must_use]
pub(crate) fn partition(
    positions: &[Vec3],
    triangles: &[[u32; 3]],
    max_triangles: usize,
) -> Vec<Vec<u32>> {
    let max_triangles = max_triangles.max(1);
    let n = triangles.len();
    if n == 0 {
        return Vec::new();
    }
    // Vertex -> triangles, over the vertices these triangles use.
    let mut local = std::collections::HashMap::new();
    let corners: Vec<[u32; 3]> = triangles
        .iter()
        .map(|t| {
            t.map(|v| {
                let next = local.len() as u32;
                *local.entry(v).or_insert(next)
            })
        })
        .collect();
    let vertices = local.len();
    let mut start = vec![0u32; vertices + 1];
    for t in &corners {
        for &v in t {
            start[v as usize + 1] += 1;
        }
    }
    for i in 0..vertices {
        start[i + 1] += start[i];
    }
    let mut fill = start.clone();
    let mut around = vec![0u32; 3 * n];
    for (t, tri) in corners.iter().enumerate() {
        for &v in tri {
            around[fill[v as usize] as usize] = t as u32;
            fill[v as usize] += 1;
        }
    }
    let order = morton_order(positions, triangles);
    const NONE: u32 = u32::MAX;
    let mut cluster_of = vec![NONE; n];
    let mut clusters: Vec<Vec<u32>> = Vec::new();
    let mut queue = VecDeque::new();
    for &seed in &order {
        if cluster_of[seed as usize] != NONE {
            continue;
        }
        let id = clusters.len() as u32;
        let mut members = Vec::with_capacity(max_triangles);
        queue.clear();
        queue.push_back(seed);
        cluster_of[seed as usize] = id;
        while let Some(t) = queue.pop_front() {
            members.push(t);
            if members.len() + queue.len() >= max_triangles {
                continue;
            }
            for &v in &corners[t as usize] {
                let r = start[v as usize] as usize..start[v as usize + 1] as usize;
                for &u in &around[r] {
                    if cluster_of[u as usize] == NONE && members.len() + queue.len() < max_triangles
                    {
                        cluster_of[u as usize] = id;
                        queue.push_back(u);
                    }
                }
            }
        }
        clusters.push(members);
    }
    merge_small(
        &mut clusters,
        &mut cluster_of,
        &corners,
        &start,
        &around,
        max_triangles,
    );
    clusters.retain(|c| !c.is_empty());
    clusters
}

/// Merges each cluster under a quarter of `max_triangles` into the
/// neighbour sharing the most corners with it, when the sum stays within
/// 1.5 times the limit (leftovers of the growth, which would otherwise make
/// groups of slivers).
fn merge_small(
    clusters: &mut [Vec<u32>],
    cluster_of: &mut [u32],
    corners: &[[u32; 3]],
    start: &[u32],
    around: &[u32],
    max_triangles: usize,
) {
    let small = max_triangles / 4;
    let room = max_triangles + max_triangles / 2;
    for c in 0..clusters.len() {
        let size = clusters[c].len();
        if size == 0 || size >= small {
            continue;
        }
        let mut shared: Vec<(u32, u32)> = Vec::new();
        for &t in &clusters[c] {
            for &v in &corners[t as usize] {
                let r = start[v as usize] as usize..start[v as usize + 1] as usize;
                for &u in &around[r] {
                    let d = cluster_of[u as usize];
                    if d as usize != c {
                        match shared.iter_mut().find(|(x, _)| *x == d) {
                            Some(e) => e.1 += 1,
                            None => shared.push((d, 1)),
                        }
                    }
                }
            }
        }
        let best = shared
            .iter()
            .filter(|&&(d, _)| clusters[d as usize].len() + size <= room)
            .max_by_key(|&&(d, count)| (count, std::cmp::Reverse(d)));
        if let Some(&(d, _)) = best {
            let moved = std::mem::take(&mut clusters[c]);
            for &t in &moved {
                cluster_of[t as usize] = d;
            }
            clusters[d as usize].extend(moved);
        }
    }
}

/// Triangle indices sorted by the Morton code of their centroids (10 bits
/// per axis over the triangles' bounding box), ties by index.
pub(crate) fn morton_order(positions: &[Vec3], triangles: &[[u32; 3]]) -> Vec<u32> {
    let centroids: Vec<Vec3> = triangles
        .iter()
        .map(|t| t.iter().map(|&v| positions[v as usize]).sum::<Vec3>() / 3.0)
        .collect();
    let mut keys: Vec<(u32, u32)> = morton_codes(&centroids)
        .into_iter()
        .enumerate()
        .map(|(i, k)| (k, i as u32))
        .collect();
    keys.sort_unstable();
    keys.into_iter().map(|(_, i)| i).collect()
}

/// The Morton code of each point (10 bits per axis over their bounding
/// box).
pub(crate) fn morton_codes(points: &[Vec3]) -> Vec<u32> {
    let (lo, hi) = crate::mesh::bounds_of(points).unwrap_or_default();
    let size = (hi - lo).max(Vec3::splat(f32::MIN_POSITIVE));
    let spread = |x: u32| {
        let mut x = x & 0x3ff;
        x = (x | (x << 16)) & 0x0300_00ff;
        x = (x | (x << 8)) & 0x0300_f00f;
        x = (x | (x << 4)) & 0x030c_30c3;
        (x | (x << 2)) & 0x0924_9249
    };
    points
        .iter()
        .map(|&p| {
            let q = ((p - lo) / size * 1023.0).clamp(Vec3::ZERO, Vec3::splat(1023.0));
            spread(q.x as u32) | (spread(q.y as u32) << 1) | (spread(q.z as u32) << 2)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_grid_is_cut_into_connected_clusters_of_bounded_size() {
        let mesh = crate::mesh::generate::grid(20, 20);
        let clusters = partition(&mesh.positions, &mesh.triangles, 128);
        let mut seen = vec![0u32; mesh.triangle_count()];
        for c in &clusters {
            assert!(!c.is_empty() && c.len() <= 192, "cluster of {}", c.len());
            for &t in c {
                seen[t as usize] += 1;
            }
        }
        assert!(seen.iter().all(|&s| s == 1));
        // 800 triangles: at least 800 / 192 clusters.
        assert!(
            (5..=12).contains(&clusters.len()),
            "{} clusters",
            clusters.len()
        );
    }
}
