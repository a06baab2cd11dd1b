//! A bounding volume hierarchy over triangles for closest-point queries.
//!
//! Built top-down by splitting the triangles at the median centroid along
//! the longest axis of the centroids' bounds (O(T log T)); queried
//! depth-first, nearer child first, pruning boxes farther than the best
//! distance found so far.

use glam::{DVec3, Vec3};

/// Triangles per leaf at most: 4 measured fastest for bunny-sized queries
/// against 2 and 8 (fewer boxes against fewer triangle tests).
const LEAF_SIZE: usize = 4;

#[derive(Debug, Clone, Copy)]
struct Node {
    min: Vec3,
    max: Vec3,
    /// Leaf: first triangle in `triangles`; inner: index of the left child
    /// (the right one follows it).
    start: u32,
    /// Leaf: triangle count (> 0); inner: 0.
    count: u32,
}

/// Closest-point queries against a fixed set of triangles.
#[derive(Debug, Clone)]
pub struct TriangleBvh {
    nodes: Vec<Node>,
    /// Triangle corners in leaf order.
    triangles: Vec<[Vec3; 3]>,
}

impl TriangleBvh {
    /// Builds the hierarchy over `triangles` (corner positions; degenerate
    /// triangles are fine). O(T log T).
    #[must_use]
    pub fn new(mut triangles: Vec<[Vec3; 3]>) -> TriangleBvh {
        let mut nodes = Vec::with_capacity(2 * triangles.len() / LEAF_SIZE + 1);
        if !triangles.is_empty() {
            nodes.push(Node {
                min: Vec3::ZERO,
                max: Vec3::ZERO,
                start: 0,
                count: 0,
            });
            build(&mut nodes, &mut triangles, 0, 0);
        }
        TriangleBvh { nodes, triangles }
    }

    /// Number of triangles.
    #[must_use]
    pub fn triangle_count(&self) -> usize {
        self.triangles.len()
    }

    /// The point of the triangles closest to `p` and its squared distance;
    /// `None` when there are no triangles. Allocation-free.
    #[must_use]
    pub fn closest(&self, p: Vec3) -> Option<(Vec3, f32)> {
        if self.nodes.is_empty() {
            return None;
        }
        let mut best = (Vec3::ZERO, f32::INFINITY);
        let mut stack = [0u32; 64];
        let mut top = 1;
        while top > 0 {
            top -= 1;
            let node = self.nodes[stack[top] as usize];
            if box_distance2(&node, p) >= best.1 {
                continue;
            }
            if node.count > 0 {
                let range = node.start as usize..(node.start + node.count) as usize;
                for t in &self.triangles[range] {
                    let q = closest_on_triangle(p, t[0], t[1], t[2]);
                    let d = q.distance_squared(p);
                    if d < best.1 {
                        best = (q, d);
                    }
                }
            } else {
                let (l, r) = (node.start, node.start + 1);
                let dl = box_distance2(&self.nodes[l as usize], p);
                let dr = box_distance2(&self.nodes[r as usize], p);
                // Push the farther first so the nearer is searched first.
                let (near, far) = if dl <= dr { (l, r) } else { (r, l) };
                stack[top] = far;
                stack[top + 1] = near;
                top += 2;
            }
        }
        Some(best)
    }
}

fn build(nodes: &mut Vec<Node>, triangles: &mut [[Vec3; 3]], node: usize, offset: usize) {
    let (mut min, mut max) = (Vec3::INFINITY, Vec3::NEG_INFINITY);
    let (mut cmin, mut cmax) = (Vec3::INFINITY, Vec3::NEG_INFINITY);
    for t in triangles.iter() {
        for &p in t {
            min = min.min(p);
            max = max.max(p);
        }
        let c = centroid(t);
        cmin = cmin.min(c);
        cmax = cmax.max(c);
    }
    nodes[node].min = min;
    nodes[node].max = max;
    if triangles.len() <= LEAF_SIZE {
        nodes[node].start = offset as u32;
        nodes[node].count = triangles.len() as u32;
        return;
    }
    let extent = cmax - cmin;
    let axis = if extent.x >= extent.y && extent.x >= extent.z {
        0
    } else if extent.y >= extent.z {
        1
    } else {
        2
    };
    let mid = triangles.len() / 2;
    triangles.select_nth_unstable_by(mid, |a, b| centroid(a)[axis].total_cmp(&centroid(b)[axis]));
    let left = nodes.len();
    let empty = Node {
        min: Vec3::ZERO,
        max: Vec3::ZERO,
        start: 0,
        count: 0,
    };
    nodes.push(empty);
    nodes.push(empty);
    nodes[node].start = left as u32;
    nodes[node].count = 0;
    let (lo, hi) = triangles.split_at_mut(mid);
    build(nodes, lo, left, offset);
    build(nodes, hi, left + 1, offset + mid);
}

fn centroid(t: &[Vec3; 3]) -> Vec3 {
    (t[0] + t[1] + t[2]) / 3.0
}

fn box_distance2(node: &Node, p: Vec3) -> f32 {
    let d = (node.min - p).max(p - node.max).max(Vec3::ZERO);
    d.length_squared()
}

/// The point of triangle `abc` closest to `p`, by the Voronoi regions of
/// its corners, edges and face (Ericson, "Real-Time Collision Detection",
/// section 5.1.5). Handles degenerate triangles (returns a point on them).
///
/// Computed in `f64`: the region tests multiply dot products (fourth
/// powers of the coordinates), which in `f32` put a point lying on a long
/// sliver up to 4e-5 of the diagonal off it on `alligator.obj` (coordinates
/// near 1000), an error larger than the flat model's simplification error.
#[must_use]
pub fn closest_on_triangle(p: Vec3, a: Vec3, b: Vec3, c: Vec3) -> Vec3 {
    closest_on_triangle_f64(p.as_dvec3(), a.as_dvec3(), b.as_dvec3(), c.as_dvec3()).as_vec3()
}

pub(crate) fn closest_on_triangle_f64(p: DVec3, a: DVec3, b: DVec3, c: DVec3) -> DVec3 {
    let ab = b - a;
    let ac = c - a;
    let ap = p - a;
    let d1 = ab.dot(ap);
    let d2 = ac.dot(ap);
    if d1 <= 0.0 && d2 <= 0.0 {
        return a;
    }
    let bp = p - b;
    let d3 = ab.dot(bp);
    let d4 = ac.dot(bp);
    if d3 >= 0.0 && d4 <= d3 {
        return b;
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        return a + ab * (d1 / (d1 - d3));
    }
    let cp = p - c;
    let d5 = ab.dot(cp);
    let d6 = ac.dot(cp);
    if d6 >= 0.0 && d5 <= d6 {
        return c;
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        return a + ac * (d2 / (d2 - d6));
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
    }
    let sum = va + vb + vc;
    if sum <= 0.0 || !sum.is_finite() {
        // Degenerate triangle: the closest of its three edges.
        return [(a, b), (b, c), (c, a)]
            .into_iter()
            .map(|(s, e)| closest_on_segment(p, s, e))
            .min_by(|x, y| x.distance_squared(p).total_cmp(&y.distance_squared(p)))
            .unwrap_or(a);
    }
    let v = vb / sum;
    let w = vc / sum;
    a + ab * v + ac * w
}

fn closest_on_segment(p: DVec3, s: DVec3, e: DVec3) -> DVec3 {
    let d = e - s;
    let len2 = d.length_squared();
    if len2 <= 0.0 {
        return s;
    }
    s + d * ((p - s).dot(d) / len2).clamp(0.0, 1.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn closest_point_in_each_region() {
        let (a, b, c) = (Vec3::ZERO, Vec3::X, Vec3::Y);
        let near = |p: Vec3, want: Vec3| {
            let q = closest_on_triangle(p, a, b, c);
            assert!((q - want).length() < 1e-6, "{p} -> {q}, want {want}");
        };
        near(Vec3::new(0.2, 0.2, 3.0), Vec3::new(0.2, 0.2, 0.0));
        near(Vec3::new(-1.0, -1.0, 0.0), a);
        near(Vec3::new(2.0, -0.5, 1.0), b);
        near(Vec3::new(-0.1, 5.0, 0.0), c);
        near(Vec3::new(0.5, -2.0, 0.0), Vec3::new(0.5, 0.0, 0.0));
        near(Vec3::new(-2.0, 0.5, 0.0), Vec3::new(0.0, 0.5, 0.0));
        near(Vec3::new(1.0, 1.0, 0.0), Vec3::new(0.5, 0.5, 0.0));
        // Degenerate (collinear) triangle.
        let q = closest_on_triangle(Vec3::new(0.5, 1.0, 0.0), a, b, Vec3::X * 2.0);
        assert!((q - Vec3::new(0.5, 0.0, 0.0)).length() < 1e-6);
    }

    #[test]
    fn bvh_agrees_with_brute_force() {
        let mut state = 12345u64;
        let mut next = || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((state >> 40) as f32) / (1u64 << 24) as f32
        };
        let triangles: Vec<[Vec3; 3]> = (0..500)
            .map(|_| {
                let o = Vec3::new(next(), next(), next()) * 10.0;
                [
                    o,
                    o + Vec3::new(next(), next(), 0.0),
                    o + Vec3::new(0.0, next(), next()),
                ]
            })
            .collect();
        let bvh = TriangleBvh::new(triangles.clone());
        for _ in 0..200 {
            let p = Vec3::new(next(), next(), next()) * 12.0 - 1.0;
            let brute = triangles
                .iter()
                .map(|t| closest_on_triangle(p, t[0], t[1], t[2]).distance_squared(p))
                .fold(f32::INFINITY, f32::min);
            let (_, d) = bvh.closest(p).unwrap();
            assert_eq!(d, brute);
        }
        assert!(TriangleBvh::new(Vec::new()).closest(Vec3::ZERO).is_none());
    }
}
