//! From what a source said to a valid [`Mesh`]: weld, drop degenerate
//! triangles, drop unreferenced vertices.

use super::Mesh;
use crate::error::{Error, Result};
use glam::Vec3;
use std::collections::HashMap;

/// A mesh as a loader or generator produced it: finite positions and
/// in-range indices (loaders check both), but possibly degenerate triangles,
/// duplicate positions and unreferenced vertices.
#[derive(Debug, Clone, Default)]
pub struct RawMesh {
    /// Vertex positions, all finite.
    pub positions: Vec<Vec3>,
    /// Triangles, every index below `positions.len()`.
    pub triangles: Vec<[u32; 3]>,
    /// Triangles the source itself dropped as degenerate (e.g. repeated
    /// indices inside a PLY triangle strip or a polygon of fewer than 3
    /// vertices), added to [`CleanReport::degenerate_dropped`].
    pub degenerate_in_source: usize,
}

/// How [`clean`] treats a raw mesh.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct CleanOptions {
    /// Merge vertices whose positions are bit-identical (after mapping -0.0
    /// to 0.0). Off by default: a seam in the source is kept as a seam.
    pub weld: bool,
}

/// What [`clean`] changed.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct CleanReport {
    /// Vertices in the source.
    pub source_vertices: usize,
    /// Triangles in the source (after polygon triangulation), including
    /// degenerate ones.
    pub source_triangles: usize,
    /// Vertices merged into another by the weld.
    pub welded: usize,
    /// Triangles dropped because two of their indices are equal (after the
    /// weld).
    pub degenerate_dropped: usize,
    /// Vertices dropped because no triangle uses them.
    pub unreferenced_dropped: usize,
}

/// Turns a [`RawMesh`] into a valid [`Mesh`], keeping the order of the
/// surviving vertices and triangles.
///
/// Zero-area triangles with three distinct indices are kept: they are valid
/// topology, and dropping them would open holes in the connectivity.
/// `source_name` names the input in errors.
///
/// # Errors
/// [`Error::InvalidMesh`] when no triangle is left, or when the raw mesh
/// breaks its own preconditions (non-finite position, index out of range).
///
/// Cost: O(V + T) expected time (hashing for the weld), O(V + T) memory.
pub fn clean(
    raw: RawMesh,
    options: CleanOptions,
    source_name: &str,
) -> Result<(Mesh, CleanReport)> {
    let invalid = |message: String| Error::InvalidMesh {
        source_name: source_name.to_owned(),
        message,
    };
    let n = raw.positions.len();
    if let Some(i) = raw.positions.iter().position(|p| !p.is_finite()) {
        return Err(invalid(format!("vertex {i} has a non-finite coordinate")));
    }
    if let Some((t, tri)) = raw
        .triangles
        .iter()
        .enumerate()
        .find(|(_, tri)| tri.iter().any(|&v| v as usize >= n))
    {
        return Err(invalid(format!(
            "triangle {t} has index out of range {tri:?} ({n} vertices)"
        )));
    }
    let mut report = CleanReport {
        source_vertices: n,
        source_triangles: raw.triangles.len() + raw.degenerate_in_source,
        degenerate_dropped: raw.degenerate_in_source,
        ..CleanReport::default()
    };

    // Weld: map every vertex to the first vertex with the same position.
    let weld_map: Vec<u32> = if options.weld {
        let key = |p: Vec3| {
            let k = |x: f32| if x == 0.0 { 0u32 } else { x.to_bits() };
            (k(p.x), k(p.y), k(p.z))
        };
        let mut first: HashMap<(u32, u32, u32), u32> = HashMap::with_capacity(n);
        raw.positions
            .iter()
            .enumerate()
            .map(|(i, &p)| *first.entry(key(p)).or_insert(i as u32))
            .collect()
    } else {
        (0..n as u32).collect()
    };
    report.welded = weld_map
        .iter()
        .enumerate()
        .filter(|&(i, &m)| m as usize != i)
        .count();

    let mut triangles = Vec::with_capacity(raw.triangles.len());
    for tri in &raw.triangles {
        let t = tri.map(|v| weld_map[v as usize]);
        if super::is_degenerate(t) {
            report.degenerate_dropped += 1;
        } else {
            triangles.push(t);
        }
    }
    if triangles.is_empty() {
        return Err(invalid(format!(
            "empty mesh: no non-degenerate triangle among {} ({} vertices)",
            report.source_triangles, n
        )));
    }

    // Compact: keep referenced vertices in their original order.
    const UNUSED: u32 = u32::MAX;
    let mut remap = vec![UNUSED; n];
    for t in &triangles {
        for &v in t {
            remap[v as usize] = 0;
        }
    }
    let mut positions = Vec::with_capacity(n);
    for (i, r) in remap.iter_mut().enumerate() {
        if *r != UNUSED {
            *r = positions.len() as u32;
            positions.push(raw.positions[i]);
        }
    }
    report.unreferenced_dropped = n - positions.len();
    for t in &mut triangles {
        *t = t.map(|v| remap[v as usize]);
    }
    let mesh = Mesh {
        positions,
        triangles,
        properties: Default::default(),
    };
    #[cfg(debug_assertions)]
    mesh.validate()
        .expect("clean produced an invalid mesh (internal error)");
    Ok((mesh, report))
}

#[cfg(test)]
mod tests {
    use super::*;

    //  3 --- 2      vertex 4 duplicates vertex 2's position,
    //  |   / |      vertex 5 is unreferenced,
    //  | /   |      triangle (0, 0, 1) is degenerate.
    //  0 --- 1
    fn raw() -> RawMesh {
        RawMesh {
            positions: vec![
                Vec3::new(0.0, 0.0, 0.0),
                Vec3::new(1.0, 0.0, 0.0),
                Vec3::new(1.0, 1.0, 0.0),
                Vec3::new(0.0, 1.0, 0.0),
                Vec3::new(1.0, 1.0, 0.0),
                Vec3::new(5.0, 5.0, 5.0),
            ],
            triangles: vec![[0, 1, 2], [0, 4, 3], [0, 0, 1]],
            degenerate_in_source: 0,
        }
    }

    #[test]
    fn drops_degenerate_and_unreferenced_without_weld() {
        let (mesh, report) = clean(raw(), CleanOptions::default(), "t").unwrap();
        assert_eq!(mesh.triangles, vec![[0, 1, 2], [0, 4, 3]]);
        assert_eq!(mesh.vertex_count(), 5);
        assert_eq!(report.degenerate_dropped, 1);
        assert_eq!(report.unreferenced_dropped, 1);
        assert_eq!(report.welded, 0);
        assert_eq!(report.source_triangles, 3);
    }

    #[test]
    fn weld_merges_identical_positions() {
        let (mesh, report) = clean(raw(), CleanOptions { weld: true }, "t").unwrap();
        assert_eq!(mesh.triangles, vec![[0, 1, 2], [0, 2, 3]]);
        assert_eq!(mesh.vertex_count(), 4);
        assert_eq!(report.welded, 1);
        assert_eq!(report.unreferenced_dropped, 2);
    }

    #[test]
    fn empty_mesh_is_an_error() {
        let raw = RawMesh {
            positions: vec![Vec3::ZERO; 3],
            triangles: vec![[0, 0, 1]],
            degenerate_in_source: 0,
        };
        match clean(raw, CleanOptions::default(), "empty.ply").unwrap_err() {
            Error::InvalidMesh { source_name, .. } => assert_eq!(source_name, "empty.ply"),
            other => panic!("expected an invalid-mesh error, got {other:?}"),
        }
    }
}
