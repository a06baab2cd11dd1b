//! Counts the cracks of what a cut draws: the check of `select.rs`'s
//! statement that `mts verify` runs on a hierarchy's file, and the rule of
//! `tests/hierarchy.rs`'s `check_watertight`.

use super::{Hierarchy, NO_GROUP};
use std::collections::HashMap;

/// The cracks in `drawn` (triangles in input vertex numbers, what
/// [`super::Cut::triangles`] gives): edges are taken by point (a seam's
/// vertices are one point, [`crate::mesh::Properties::position_id`]), and a
/// directed edge drawn more often than its reverse is a crack, once per
/// unmatched drawing, unless both its points lie on the input's own
/// boundary (which groups may simplify). The input is the level-0
/// clusters' triangles (those with no producer); its boundary points are
/// those of its edges without a reverse.
///
/// On a closed input every drawn edge must then be drawn as often in each
/// direction; a crack, a T-junction or a torn seam is counted. Folds (an
/// edge drawn twice in one direction, matched by its reverse twice) are not
/// cracks. A drawn vertex that is not an input vertex is its own point.
///
/// Cost: O(input + drawn) hash map updates; allocates.
#[must_use]
pub fn cracks(h: &Hierarchy, drawn: &[[u32; 3]]) -> usize {
    let n = h.positions.len();
    let point = |v: u32| {
        if (v as usize) < n {
            h.properties.position_id(v)
        } else {
            v
        }
    };
    let input = h
        .clusters
        .iter()
        .enumerate()
        .filter(|(_, c)| c.producer == NO_GROUP)
        .flat_map(|(i, _)| h.cluster_triangles(i));
    let mut on_boundary = std::collections::HashSet::new();
    for ((a, b), _) in open_edges(input.map(|t| t.map(point))) {
        on_boundary.insert(a);
        on_boundary.insert(b);
    }
    open_edges(drawn.iter().map(|t| t.map(point)))
        .filter(|((a, b), _)| !(on_boundary.contains(a) && on_boundary.contains(b)))
        .map(|(_, net)| net as usize)
        .sum()
}

/// The directed edges of `triangles` drawn more often than their reverse,
/// each with how many times more.
fn open_edges(
    triangles: impl Iterator<Item = [u32; 3]>,
) -> impl Iterator<Item = ((u32, u32), i64)> {
    let mut net: HashMap<(u32, u32), i64> = HashMap::new();
    for t in triangles {
        for i in 0..3 {
            let (a, b) = (t[i], t[(i + 1) % 3]);
            if a != b {
                *net.entry((a, b)).or_default() += 1;
                *net.entry((b, a)).or_default() -= 1;
            }
        }
    }
    net.into_iter().filter(|&(_, k)| k > 0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::hierarchy::{build, HierarchyOptions};
    use crate::mesh::generate::Generated;

    #[test]
    fn a_hole_is_counted_the_boundary_is_not() {
        for (name, properties) in [
            ("icosphere:1k", false),
            ("torus:1k", true),
            ("grid:1k", false),
        ] {
            let g: Generated = name.parse().unwrap();
            let mesh = if properties {
                g.build_with_properties()
            } else {
                g.build()
            };
            let h = build(&mesh, &HierarchyOptions::default()).unwrap();
            assert_eq!(cracks(&h, &mesh.triangles), 0, "{name}");
            // A triangle away from any boundary left out: its three edges'
            // reverses are drawn alone.
            let boundary = cracks(&h, &[]);
            assert_eq!(boundary, 0, "{name}: nothing drawn, nothing open");
            let inner = (0..mesh.triangle_count())
                .find(|&t| {
                    let mut rest = mesh.triangles.clone();
                    rest.remove(t);
                    cracks(&h, &rest) == 3
                })
                .is_some();
            assert!(inner, "{name}");
            let mut flipped = mesh.triangles.clone();
            flipped[mesh.triangle_count() / 2].swap(0, 1);
            assert!(cracks(&h, &flipped) > 0, "{name}: a flipped triangle");
        }
    }
}
