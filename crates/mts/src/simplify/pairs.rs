//! Candidate pairs for contraction (Garland and Heckbert 1997, section 3):
//! the mesh edges, and optionally "virtual" pairs of vertices closer than a
//! threshold that share no edge.

use super::fans::Fans;
use glam::Vec3;
use std::collections::HashMap;

/// Most virtual partners kept per vertex (the closest ones): bounds the
/// candidate count when the threshold is large against the sampling.
pub(crate) const MAX_VIRTUAL_PER_VERTEX: usize = 8;

/// Pairs `(a, b)`, `a < b`, of vertices closer than `distance` that share
/// no triangle, at most [`MAX_VIRTUAL_PER_VERTEX`] (the closest) per vertex
/// `a`. A uniform grid with cells of side `distance` finds them in
/// O(V + pairs) for well-spread points.
pub(crate) fn virtual_pairs(
    positions: &[Vec3],
    fans: &Fans,
    triangles: &[[u32; 3]],
    distance: f32,
) -> Vec<(u32, u32)> {
    if distance <= 0.0 || !distance.is_finite() || positions.is_empty() {
        return Vec::new();
    }
    let cell = |p: Vec3| (p / distance).floor().as_ivec3();
    let mut grid: HashMap<glam::IVec3, Vec<u32>> = HashMap::new();
    for (i, &p) in positions.iter().enumerate() {
        grid.entry(cell(p)).or_default().push(i as u32);
    }
    let shares_triangle = |a: u32, b: u32| {
        fans.get(a)
            .iter()
            .any(|&t| triangles[t as usize].contains(&b))
    };
    let mut out = Vec::new();
    let mut found: Vec<(f32, u32)> = Vec::new();
    for (a, &p) in positions.iter().enumerate() {
        let a = a as u32;
        found.clear();
        let c = cell(p);
        for dz in -1..=1 {
            for dy in -1..=1 {
                for dx in -1..=1 {
                    let Some(list) = grid.get(&(c + glam::IVec3::new(dx, dy, dz))) else {
                        continue;
                    };
                    for &b in list {
                        let d = positions[b as usize].distance(p);
                        if b > a && d < distance {
                            found.push((d, b));
                        }
                    }
                }
            }
        }
        found.sort_unstable_by(|x, y| x.0.total_cmp(&y.0).then(x.1.cmp(&y.1)));
        out.extend(
            found
                .iter()
                .filter(|&&(_, b)| !shares_triangle(a, b))
                .take(MAX_VIRTUAL_PER_VERTEX)
                .map(|&(_, b)| (a, b)),
        );
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn virtual_pairs_skip_edges_and_far_vertices() {
        // Two triangles 0.1 apart; vertex 0 also shares a triangle with 1, 2.
        let positions = vec![
            Vec3::ZERO,
            Vec3::X,
            Vec3::Y,
            Vec3::new(0.0, 0.0, 0.1),
            Vec3::new(1.0, 0.0, 0.1),
            Vec3::new(0.0, 1.0, 0.1),
        ];
        let triangles = vec![[0, 1, 2], [3, 4, 5]];
        let vt = Fans::new(6, &triangles);
        let mut pairs = virtual_pairs(&positions, &vt, &triangles, 0.2);
        pairs.sort_unstable();
        assert_eq!(pairs, vec![(0, 3), (1, 4), (2, 5)]);
        assert!(virtual_pairs(&positions, &vt, &triangles, 0.05).is_empty());
    }
}
