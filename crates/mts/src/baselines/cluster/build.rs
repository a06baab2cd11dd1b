//! Hierarchical clustering by closest representatives, section 4 of the
//! cluster-tree paper (Schmalstieg and Schaufler, "Incremental encoding of
//! polygonal models", 1997: "Construction of the cluster tree").
//!
//! Every vertex starts as its own cluster; the two clusters with the
//! closest representatives are joined, and the joint cluster keeps one of
//! the two representatives (the one of the cluster with more vertices, so
//! the per-vertex triangle lists later replays move stay short; ties keep
//! the lower index). The distance of the two representatives is the new
//! node's cluster size. Representatives never move, so a cluster's nearest
//! neighbour only changes when that neighbour disappears: a heap holds
//! each cluster's last known nearest-neighbour distance (a lower bound of
//! the current one) and an entry whose neighbour is gone is recomputed when
//! it surfaces. Nearest neighbours come from a kd-tree over the live
//! representatives, rebuilt when half of them are gone. Cluster sizes come
//! out non-decreasing: the popped pair is the closest of all live pairs, and
//! removing points never brings two others closer.
//!
//! Cost: O(n log n) expected for surface meshes (each merge costs one or
//! two nearest-neighbour queries plus the lazy recomputations).

use crate::simplify::Collapse;
use glam::Vec3;
use std::cmp::Reverse;
use std::collections::BinaryHeap;

/// A kd-tree over points, with deletion by per-subtree live counts.
///
/// Implicit layout: the subtree over `idx[lo..hi]` has its splitting point
/// at `mid = (lo + hi) / 2`, its axis in `axis[mid]` and its live count in
/// `live[mid]`.
struct KdTree<'a> {
    points: &'a [Vec3],
    idx: Vec<u32>,
    axis: Vec<u8>,
    live: Vec<u32>,
    /// Position of each point in `idx` (`u32::MAX` when not in the tree).
    slot: Vec<u32>,
    alive: usize,
}

impl<'a> KdTree<'a> {
    fn new(points: &'a [Vec3], members: Vec<u32>) -> KdTree<'a> {
        let m = members.len();
        let mut t = KdTree {
            points,
            idx: members,
            axis: vec![0; m],
            live: vec![0; m],
            slot: vec![u32::MAX; points.len()],
            alive: m,
        };
        t.build(0, m);
        for (s, &p) in t.idx.iter().enumerate() {
            t.slot[p as usize] = s as u32;
        }
        t
    }

    fn build(&mut self, lo: usize, hi: usize) {
        if lo >= hi {
            return;
        }
        let (mut min, mut max) = (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY));
        for &p in &self.idx[lo..hi] {
            min = min.min(self.points[p as usize]);
            max = max.max(self.points[p as usize]);
        }
        let e = max - min;
        let axis = if e.x >= e.y && e.x >= e.z {
            0
        } else if e.y >= e.z {
            1
        } else {
            2
        };
        let mid = (lo + hi) / 2;
        let pts = self.points;
        self.idx[lo..hi].select_nth_unstable_by(mid - lo, |&a, &b| {
            pts[a as usize][axis]
                .total_cmp(&pts[b as usize][axis])
                .then(a.cmp(&b))
        });
        self.axis[mid] = axis as u8;
        self.live[mid] = (hi - lo) as u32;
        self.build(lo, mid);
        self.build(mid + 1, hi);
    }

    /// Removes point `p` (which must be in the tree and live).
    fn remove(&mut self, p: u32) {
        let s = self.slot[p as usize] as usize;
        let (mut lo, mut hi) = (0, self.idx.len());
        loop {
            let mid = (lo + hi) / 2;
            self.live[mid] -= 1;
            if s == mid {
                break;
            }
            if s < mid {
                hi = mid;
            } else {
                lo = mid + 1;
            }
        }
        self.slot[p as usize] = u32::MAX;
        self.alive -= 1;
    }

    fn contains(&self, p: u32) -> bool {
        self.slot[p as usize] != u32::MAX
    }

    /// The live point nearest to `q`'s position other than `q`, as
    /// (squared distance, point); ties go to the lower index.
    fn nearest(&self, q: u32) -> Option<(f32, u32)> {
        let mut best: Option<(f32, u32)> = None;
        self.search(0, self.idx.len(), q, self.points[q as usize], &mut best);
        best
    }

    fn search(&self, lo: usize, hi: usize, q: u32, at: Vec3, best: &mut Option<(f32, u32)>) {
        if lo >= hi {
            return;
        }
        let mid = (lo + hi) / 2;
        if self.live[mid] == 0 {
            return;
        }
        let p = self.idx[mid];
        if p != q && self.slot[p as usize] != u32::MAX {
            let d = self.points[p as usize].distance_squared(at);
            if best.is_none_or(|(bd, bp)| d < bd || (d == bd && p < bp)) {
                *best = Some((d, p));
            }
        }
        let axis = self.axis[mid] as usize;
        let diff = at[axis] - self.points[p as usize][axis];
        let (near, far) = if diff < 0.0 {
            ((lo, mid), (mid + 1, hi))
        } else {
            ((mid + 1, hi), (lo, mid))
        };
        self.search(near.0, near.1, q, at, best);
        if best.is_none_or(|(bd, _)| diff * diff <= bd) {
            self.search(far.0, far.1, q, at, best);
        }
    }
}

/// The joins of the clustering in order, as contractions (`removed`'s
/// cluster joins `kept`'s, which keeps its representative), with each
/// join's cluster size (Euclidean distance of the two representatives, in
/// the mesh's units). `n - 1` joins for `n > 0` points: the last leaves
/// one cluster, the tree's root.
#[must_use]
pub(crate) fn cluster(points: &[Vec3]) -> Vec<(Collapse, f32)> {
    let n = points.len();
    let mut out = Vec::with_capacity(n.saturating_sub(1));
    if n < 2 {
        return out;
    }
    let mut tree = KdTree::new(points, (0..n as u32).collect());
    let mut members = vec![1u32; n];
    let mut heap = BinaryHeap::with_capacity(n);
    for v in 0..n as u32 {
        if let Some((d, p)) = tree.nearest(v) {
            heap.push(Reverse((d.to_bits(), v, p)));
        }
    }
    while let Some(Reverse((d, a, b))) = heap.pop() {
        if !tree.contains(a) {
            continue;
        }
        if !tree.contains(b) {
            if let Some((d, p)) = tree.nearest(a) {
                heap.push(Reverse((d.to_bits(), a, p)));
            }
            continue;
        }
        let (kept, removed) = if members[b as usize] > members[a as usize]
            || (members[b as usize] == members[a as usize] && b < a)
        {
            (b, a)
        } else {
            (a, b)
        };
        members[kept as usize] += members[removed as usize];
        tree.remove(removed);
        out.push((
            Collapse {
                removed,
                kept,
                error: 0.0,
            },
            f32::from_bits(d).sqrt(),
        ));
        if tree.alive == 1 {
            break;
        }
        if 2 * tree.alive < tree.idx.len() {
            let live: Vec<u32> = tree
                .idx
                .iter()
                .copied()
                .filter(|&p| tree.contains(p))
                .collect();
            tree = KdTree::new(points, live);
        }
        if let Some((d, p)) = tree.nearest(kept) {
            heap.push(Reverse((d.to_bits(), kept, p)));
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Points on a line at 0, 1, 3, 7: joins at distances 1, 2, 4.
    #[test]
    fn joins_the_closest_pair_first() {
        let p: Vec<Vec3> = [0.0, 1.0, 3.0, 7.0]
            .iter()
            .map(|&x| Vec3::new(x, 0.0, 0.0))
            .collect();
        let joins = cluster(&p);
        let got: Vec<(u32, u32, f32)> =
            joins.iter().map(|(c, s)| (c.removed, c.kept, *s)).collect();
        // 0 and 1 first (0 keeps: lower index); with 1 gone, 2 is closest
        // to 0 (3, against 4 to point 3) and 0 keeps (more members); last 3.
        assert_eq!(got, vec![(1, 0, 1.0), (2, 0, 3.0), (3, 0, 7.0)]);
    }

    #[test]
    fn sizes_do_not_decrease_and_everything_joins() {
        let p: Vec<Vec3> = (0..500u32)
            .map(|i| {
                let f = i as f32;
                Vec3::new(
                    (f * 0.618).fract(),
                    (f * 0.414).fract(),
                    (f * 0.732).fract(),
                )
            })
            .collect();
        let joins = cluster(&p);
        assert_eq!(joins.len(), 499);
        assert!(joins.windows(2).all(|w| w[0].1 <= w[1].1));
        let mut removed = vec![false; 500];
        for (c, _) in &joins {
            assert!(!removed[c.removed as usize] && !removed[c.kept as usize]);
            removed[c.removed as usize] = true;
        }
    }
}
