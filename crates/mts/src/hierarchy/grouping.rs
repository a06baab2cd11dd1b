//! Groups the clusters of one level into sets of a few adjacent ones
//! (meshoptimizer's `partitionClusters` does this with a priority on shared
//! border length; here a greedy pass in Morton order of the clusters'
//! centres, each group taking the free neighbour that shares the most
//! points with it). Sharing points, not edges, makes clusters that touch at
//! a corner neighbours too, so no cluster is left alone while a neighbour
//! is free.

use glam::Vec3;
use std::collections::HashMap;

/// Groups `clusters` (each a list of triangles over `positions`, points
/// told apart by `point_of`) into groups of at most `max_clusters`
/// clusters; returns each group's cluster indices, every cluster in exactly
/// one group. A group grows from the first free cluster in Morton order of
/// the clusters' centres, taking the free cluster that shares the most
/// points with it until it is full or has no free neighbour.
///
/// Cost: O(corners) with hashing, plus O(neighbours²) per group.
#[must_use]
pub(crate) fn group(
    positions: &[Vec3],
    point_of: impl Fn(u32) -> u32,
    clusters: &[&[[u32; 3]]],
    max_clusters: usize,
) -> Vec<Vec<u32>> {
    let n = clusters.len();
    // Point -> the clusters that use it (each once).
    let mut users: HashMap<u32, Vec<u32>> = HashMap::new();
    for (c, tris) in clusters.iter().enumerate() {
        for t in tris.iter() {
            for &v in t {
                let list = users.entry(point_of(v)).or_default();
                if list.last() != Some(&(c as u32)) {
                    list.push(c as u32);
                }
            }
        }
    }
    // Cluster adjacency weighted by shared points.
    let mut weight: HashMap<(u32, u32), u32> = HashMap::new();
    for list in users.values() {
        for (i, &a) in list.iter().enumerate() {
            for &b in &list[i + 1..] {
                if a != b {
                    *weight.entry((a.min(b), a.max(b))).or_default() += 1;
                }
            }
        }
    }
    let mut neighbours: Vec<Vec<(u32, u32)>> = vec![Vec::new(); n];
    for (&(a, b), &w) in &weight {
        neighbours[a as usize].push((b, w));
        neighbours[b as usize].push((a, w));
    }
    for list in &mut neighbours {
        list.sort_unstable();
    }
    let centres: Vec<Vec3> = clusters
        .iter()
        .map(|tris| {
            let sum: Vec3 = tris
                .iter()
                .flat_map(|t| t.iter().map(|&v| positions[v as usize]))
                .sum();
            sum / (3 * tris.len()).max(1) as f32
        })
        .collect();
    let codes = super::partition::morton_codes(&centres);
    let mut order: Vec<u32> = (0..n as u32).collect();
    order.sort_unstable_by_key(|&c| (codes[c as usize], c));
    let mut taken = vec![false; n];
    let mut groups = Vec::new();
    for &seed in &order {
        if taken[seed as usize] {
            continue;
        }
        taken[seed as usize] = true;
        let mut members = vec![seed];
        while members.len() < max_clusters {
            let mut best: Option<(u32, u32)> = None;
            for &m in &members {
                for &(c, _) in &neighbours[m as usize] {
                    if taken[c as usize] {
                        continue;
                    }
                    let shared: u32 = members
                        .iter()
                        .filter_map(|&x| {
                            let list = &neighbours[x as usize];
                            list.binary_search_by_key(&c, |&(y, _)| y)
                                .ok()
                                .map(|i| list[i].1)
                        })
                        .sum();
                    if best.is_none_or(|(bw, bc)| shared > bw || (shared == bw && c < bc)) {
                        best = Some((shared, c));
                    }
                }
            }
            let Some((_, c)) = best else { break };
            taken[c as usize] = true;
            members.push(c);
        }
        groups.push(members);
    }
    groups
}
