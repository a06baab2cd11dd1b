//! A bounding volume hierarchy over triangles for closest-point queries.
//!
//! Built top-down by splitting the triangles at the median centroid along
//! the longest axis of the centroids' bounds (O(T log T)); queried
//! depth-first, nearer child first, pruning boxes farther than the best
//! distance found so far. Each triangle keeps its index in the input, so a
//! query can say which triangle it landed on ([`TriangleBvh::closest_triangle`]).

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
    /// `ids[i]` is the index in the input of `triangles[i]`; apart from
    /// `triangles` so that the queries' inner loop reads corners only.
    ids: Vec<u32>,
}

impl TriangleBvh {
    /// Builds the hierarchy over `triangles` (corner positions; degenerate
    /// triangles are fine). O(T log T).
    ///
    /// # Panics
    /// If there are more than `u32::MAX` triangles.
    #[must_use]
    pub fn new(triangles: Vec<[Vec3; 3]>) -> TriangleBvh {
        assert!(
            u32::try_from(triangles.len()).is_ok(),
            "TriangleBvh holds at most u32::MAX triangles"
        );
        let mut items: Vec<([Vec3; 3], u32)> = triangles.into_iter().zip(0..).collect();
        let mut nodes = Vec::with_capacity(2 * items.len() / LEAF_SIZE + 1);
        if !items.is_empty() {
            nodes.push(Node {
                min: Vec3::ZERO,
                max: Vec3::ZERO,
                start: 0,
                count: 0,
            });
            build(&mut nodes, &mut items, 0, 0);
        }
        let (triangles, ids) = items.into_iter().unzip();
        TriangleBvh {
            nodes,
            triangles,
            ids,
        }
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
        self.nearest(p).map(|(_, q, d)| (q, d))
    }

    /// [`TriangleBvh::closest`] and the triangle the point lies on, as its
    /// index in the triangles given to [`TriangleBvh::new`]: `(triangle,
    /// point, squared distance)`. Among triangles equally close, the one
    /// whose point `closest` returns. Allocation-free.
    #[must_use]
    pub fn closest_triangle(&self, p: Vec3) -> Option<(u32, Vec3, f32)> {
        self.nearest(p).map(|(i, q, d)| (self.ids[i], q, d))
    }

    /// The closest point's triangle in leaf order, the point and its
    /// squared distance. Inlined into both queries, so `closest` drops the
    /// index at no cost.
    #[inline(always)]
    fn nearest(&self, p: Vec3) -> Option<(usize, Vec3, f32)> {
        if self.nodes.is_empty() {
            return None;
        }
        let mut best = (0, Vec3::ZERO, f32::INFINITY);
        let mut stack = [0u32; 64];
        let mut top = 1;
        while top > 0 {
            top -= 1;
            let node = self.nodes[stack[top] as usize];
            if box_distance2(&node, p) >= best.2 {
                continue;
            }
            if node.count > 0 {
                let range = node.start as usize..(node.start + node.count) as usize;
                for (i, t) in self.triangles[range.clone()].iter().enumerate() {
                    let q = closest_on_triangle(p, t[0], t[1], t[2]);
                    let d = q.distance_squared(p);
                    if d < best.2 {
                        best = (range.start + i, q, d);
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

fn build(nodes: &mut Vec<Node>, triangles: &mut [([Vec3; 3], u32)], node: usize, offset: usize) {
    let (mut min, mut max) = (Vec3::INFINITY, Vec3::NEG_INFINITY);
    let (mut cmin, mut cmax) = (Vec3::INFINITY, Vec3::NEG_INFINITY);
    for (t, _) in triangles.iter() {
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
    triangles.select_nth_unstable_by(mid, |a, b| {
        centroid(&a.0)[axis].total_cmp(&centroid(&b.0)[axis])
    });
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
    closest_on_triangle_weights_f64(p, a, b, c).0
}

/// [`closest_on_triangle`] in `f64` with the point's barycentric weights
/// `[wa, wb, wc]` (summing to 1 up to rounding): a weight is exactly 0 when
/// the point lies on the opposite edge's or a corner's region, so a caller
/// can tell a point on an edge or corner from one inside. The point is the
/// one [`closest_on_triangle`] returns, bit for bit. Allocation-free.
#[must_use]
#[inline]
pub(crate) fn closest_on_triangle_weights_f64(
    p: DVec3,
    a: DVec3,
    b: DVec3,
    c: DVec3,
) -> (DVec3, [f64; 3]) {
    let ab = b - a;
    let ac = c - a;
    let ap = p - a;
    let d1 = ab.dot(ap);
    let d2 = ac.dot(ap);
    if d1 <= 0.0 && d2 <= 0.0 {
        return (a, [1.0, 0.0, 0.0]);
    }
    let bp = p - b;
    let d3 = ab.dot(bp);
    let d4 = ac.dot(bp);
    if d3 >= 0.0 && d4 <= d3 {
        return (b, [0.0, 1.0, 0.0]);
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        let t = d1 / (d1 - d3);
        return (a + ab * t, [1.0 - t, t, 0.0]);
    }
    let cp = p - c;
    let d5 = ab.dot(cp);
    let d6 = ac.dot(cp);
    if d6 >= 0.0 && d5 <= d6 {
        return (c, [0.0, 0.0, 1.0]);
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        let t = d2 / (d2 - d6);
        return (a + ac * t, [1.0 - t, 0.0, t]);
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        let t = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return (b + (c - b) * t, [0.0, 1.0 - t, t]);
    }
    let sum = va + vb + vc;
    if sum <= 0.0 || !sum.is_finite() {
        // Degenerate triangle: the closest of its three edges.
        let corners = [a, b, c];
        return (0..3)
            .map(|k| {
                let (q, t) = closest_on_segment(p, corners[k], corners[(k + 1) % 3]);
                let mut w = [0.0; 3];
                w[k] = 1.0 - t;
                w[(k + 1) % 3] = t;
                (q, w)
            })
            .min_by(|x, y| x.0.distance_squared(p).total_cmp(&y.0.distance_squared(p)))
            .unwrap_or((a, [1.0, 0.0, 0.0]));
    }
    let v = vb / sum;
    let w = vc / sum;
    (a + ab * v + ac * w, [va / sum, v, w])
}

/// The point of segment `se` closest to `p` and its parameter along it
/// (0 at `s`, 1 at `e`).
fn closest_on_segment(p: DVec3, s: DVec3, e: DVec3) -> (DVec3, f64) {
    let d = e - s;
    let len2 = d.length_squared();
    if len2 <= 0.0 {
        return (s, 0.0);
    }
    let t = ((p - s).dot(d) / len2).clamp(0.0, 1.0);
    (s + d * t, t)
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
    fn weights_rebuild_the_point_and_zero_on_edges_and_corners() {
        let (a, b, c) = (DVec3::ZERO, DVec3::X, DVec3::Y);
        let cases = [
            (DVec3::new(0.2, 0.3, 3.0), [0.5, 0.2, 0.3]),
            (DVec3::new(-1.0, -1.0, 0.0), [1.0, 0.0, 0.0]),
            (DVec3::new(2.0, -0.5, 1.0), [0.0, 1.0, 0.0]),
            (DVec3::new(-0.1, 5.0, 0.0), [0.0, 0.0, 1.0]),
            (DVec3::new(0.25, -2.0, 0.0), [0.75, 0.25, 0.0]),
            (DVec3::new(-2.0, 0.5, 0.0), [0.5, 0.0, 0.5]),
            (DVec3::new(1.0, 0.5, 0.0), [0.0, 0.75, 0.25]),
        ];
        for (p, want) in cases {
            let (q, w) = closest_on_triangle_weights_f64(p, a, b, c);
            assert_eq!(q, closest_on_triangle_f64(p, a, b, c));
            assert!((a * w[0] + b * w[1] + c * w[2] - q).length() < 1e-12, "{p}");
            for k in 0..3 {
                // Zeros exact, the rest to rounding.
                assert!(
                    (w[k] - want[k]).abs() < 1e-12 && (want[k] != 0.0 || w[k] == 0.0),
                    "{p}: {w:?}, want {want:?}"
                );
            }
        }
        // Degenerate: the closest point of the collinear triangle's edges.
        let (q, w) = closest_on_triangle_weights_f64(DVec3::new(0.5, 1.0, 0.0), a, b, b * 2.0);
        assert_eq!((q, w), (DVec3::new(0.5, 0.0, 0.0), [0.5, 0.5, 0.0]));
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
            let (q, d) = bvh.closest(p).unwrap();
            assert_eq!(d, brute);
            // The triangle named is the input triangle the point is on.
            let (i, qi, di) = bvh.closest_triangle(p).unwrap();
            assert_eq!((qi, di), (q, d));
            let t = triangles[i as usize];
            assert_eq!(closest_on_triangle(p, t[0], t[1], t[2]), q);
        }
        assert!(TriangleBvh::new(Vec::new()).closest(Vec3::ZERO).is_none());
        assert!(TriangleBvh::new(Vec::new())
            .closest_triangle(Vec3::ZERO)
            .is_none());
    }
}
