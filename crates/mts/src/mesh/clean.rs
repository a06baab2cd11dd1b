//! From what a source said to a valid [`Mesh`]: weld, drop degenerate
//! triangles, drop unreferenced vertices.

use super::{Mesh, Properties};
use crate::error::{Error, Result};
use glam::{Vec3, Vec4};
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
    /// Property streams, one value per vertex (counts checked by
    /// [`clean`]). `position_ids` here may be any numbers (e.g. the
    /// source's position index of each vertex): equal numbers say that
    /// vertices are one point split at a seam, and such vertices must have
    /// identical positions. Empty with property streams (a source that
    /// cannot say, such as PLY or glTF): vertices with bit-identical
    /// positions are one point.
    pub properties: Properties,
}

/// How [`clean`] treats a raw mesh.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct CleanOptions {
    /// Merge vertices whose positions are bit-identical (after mapping -0.0
    /// to 0.0) and whose properties are too; vertices at one position with
    /// different properties become one point split at a seam. Off by
    /// default: vertices the source keeps apart stay apart.
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
/// Properties follow their vertices. Normals are normalised (a zero normal
/// stays zero: none given) and colours clamped to 0..=1, since sources
/// write both loosely. A triangle whose corners are fewer than three
/// points is degenerate like one that repeats an index.
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
    let mut properties = raw.properties;
    check_properties(&mut properties, n).map_err(invalid)?;
    let mut positions_in = raw.positions;
    let mut report = CleanReport {
        source_vertices: n,
        source_triangles: raw.triangles.len() + raw.degenerate_in_source,
        degenerate_dropped: raw.degenerate_in_source,
        ..CleanReport::default()
    };

    // Weld: map every vertex to the first vertex with the same position and
    // properties. Points: every vertex to the first vertex of its point
    // (same position when welding, same source id otherwise).
    let key = |p: Vec3| {
        let k = |x: f32| if x == 0.0 { 0u32 } else { x.to_bits() };
        (k(p.x), k(p.y), k(p.z))
    };
    let mut point: Vec<u32> = Vec::with_capacity(n);
    let weld_map: Vec<u32> = if options.weld {
        let mut first_at: HashMap<PositionKey, u32> = HashMap::with_capacity(n);
        let mut first: HashMap<(PositionKey, Vec<u32>), u32> = HashMap::with_capacity(n);
        (0..n)
            .map(|i| {
                let k = key(positions_in[i]);
                let p = *first_at.entry(k).or_insert(i as u32);
                point.push(p);
                // One point, one position (-0.0 and 0.0 alike).
                positions_in[i] = positions_in[p as usize];
                *first
                    .entry((k, property_bits(&properties, i)))
                    .or_insert(i as u32)
            })
            .collect()
    } else if properties.position_ids.is_empty() && !properties.is_empty() {
        // Property streams but no word on seams (PLY, glTF): vertices with
        // bit-identical positions are one point, as meshoptimizer also
        // assumes. Otherwise a seam would be two borders that
        // simplification could pull apart; the cost is that two parts
        // touching at exactly one position are joined there too.
        let mut first: HashMap<[u32; 3], u32> = HashMap::with_capacity(n);
        for (i, p) in positions_in.iter().enumerate() {
            point.push(
                *first
                    .entry(p.to_array().map(f32::to_bits))
                    .or_insert(i as u32),
            );
        }
        (0..n as u32).collect()
    } else {
        let mut first: HashMap<u32, u32> = HashMap::new();
        for i in 0..n as u32 {
            point.push(*first.entry(properties.position_id(i)).or_insert(i));
        }
        if let Some(v) = (0..n).find(|&v| {
            positions_in[v].to_array().map(f32::to_bits)
                != positions_in[point[v] as usize].to_array().map(f32::to_bits)
        }) {
            return Err(invalid(format!(
                "vertex {v} shares a position index with vertex {} but not its position",
                point[v]
            )));
        }
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
        if super::is_degenerate(t) || super::is_degenerate(t.map(|v| point[v as usize])) {
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
    let mut order = Vec::with_capacity(n);
    for (i, r) in remap.iter_mut().enumerate() {
        if *r != UNUSED {
            *r = positions.len() as u32;
            positions.push(positions_in[i]);
            order.push(i as u32);
        }
    }
    properties.position_ids = point;
    let mut properties = properties.gather(&order);
    if properties
        .position_ids
        .iter()
        .enumerate()
        .all(|(v, &id)| id as usize == v)
    {
        properties.position_ids = Vec::new();
    }
    report.unreferenced_dropped = n - positions.len();
    for t in &mut triangles {
        *t = t.map(|v| remap[v as usize]);
    }
    let mesh = Mesh {
        positions,
        triangles,
        properties,
    };
    #[cfg(debug_assertions)]
    mesh.validate()
        .expect("clean produced an invalid mesh (internal error)");
    Ok((mesh, report))
}

/// A position's bits, -0.0 and 0.0 alike (the weld's key).
type PositionKey = (u32, u32, u32);

/// Checks the property counts and values a source gave, normalising
/// normals and clamping colours.
fn check_properties(p: &mut Properties, n: usize) -> std::result::Result<(), String> {
    p.check_counts(n)?;
    if let Some(normals) = &mut p.normals {
        for (v, x) in normals.iter_mut().enumerate() {
            if !x.is_finite() {
                return Err(format!("normal of vertex {v} is not finite"));
            }
            *x = x.normalize_or_zero();
        }
    }
    if let Some(v) = p.uvs.iter().flatten().position(|t| !t.is_finite()) {
        return Err(format!("texture coordinate of vertex {v} is not finite"));
    }
    if let Some(colors) = &mut p.colors {
        for (v, c) in colors.iter_mut().enumerate() {
            if c.is_nan() {
                return Err(format!("colour of vertex {v} is not a number"));
            }
            *c = c.clamp(Vec4::ZERO, Vec4::ONE);
        }
    }
    Ok(())
}

/// The bits of vertex `v`'s properties (for the weld's key).
fn property_bits(p: &Properties, v: usize) -> Vec<u32> {
    let mut bits = Vec::new();
    if let Some(s) = &p.normals {
        bits.extend(s[v].to_array().map(f32::to_bits));
    }
    if let Some(s) = &p.uvs {
        bits.extend(s[v].to_array().map(f32::to_bits));
    }
    if let Some(s) = &p.colors {
        bits.extend(s[v].to_array().map(f32::to_bits));
    }
    bits
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
            properties: Default::default(),
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
            properties: Default::default(),
        };
        match clean(raw, CleanOptions::default(), "empty.ply").unwrap_err() {
            Error::InvalidMesh { source_name, .. } => assert_eq!(source_name, "empty.ply"),
            other => panic!("expected an invalid-mesh error, got {other:?}"),
        }
    }

    /// Two quads sharing the edge 1–2 with a UV seam along it: vertices 4
    /// and 5 repeat 1 and 2 with other UVs.
    fn seamed() -> RawMesh {
        let p = |x: f32, y: f32| Vec3::new(x, y, 0.0);
        let uv = glam::Vec2::new;
        RawMesh {
            positions: vec![
                p(0., 0.),
                p(1., 0.),
                p(1., 1.),
                p(0., 1.),
                p(1., 0.),
                p(1., 1.),
                p(2., 0.),
                p(2., 1.),
            ],
            triangles: vec![[0, 1, 2], [0, 2, 3], [4, 6, 7], [4, 7, 5]],
            degenerate_in_source: 0,
            properties: Properties {
                uvs: Some(vec![
                    uv(0., 0.),
                    uv(1., 0.),
                    uv(1., 1.),
                    uv(0., 1.),
                    uv(5., 0.),
                    uv(5., 1.),
                    uv(6., 0.),
                    uv(6., 1.),
                ]),
                // The source's position index: 4 and 5 are 1 and 2 again.
                position_ids: vec![0, 1, 2, 3, 1, 2, 6, 7],
                ..Properties::default()
            },
        }
    }

    #[test]
    fn a_seam_keeps_its_vertices_as_one_point() {
        let (mesh, _) = clean(seamed(), CleanOptions::default(), "t").unwrap();
        assert_eq!(mesh.vertex_count(), 8);
        assert_eq!(mesh.properties.position_ids, vec![0, 1, 2, 3, 1, 2, 4, 5]);
        assert_eq!(
            mesh.properties.uvs.as_ref().unwrap()[4],
            glam::Vec2::new(5., 0.)
        );
        mesh.validate().unwrap();
        // Welding merges nothing (the UVs differ) and finds the same points.
        let mut raw = seamed();
        raw.properties.position_ids.clear();
        let (welded, report) = clean(raw, CleanOptions { weld: true }, "t").unwrap();
        assert_eq!(report.welded, 0);
        assert_eq!(welded.properties.position_ids, mesh.properties.position_ids);
        // Equal UVs at one position are merged by the weld.
        let mut raw = seamed();
        raw.properties.position_ids.clear();
        let uvs = raw.properties.uvs.as_mut().unwrap();
        (uvs[4], uvs[5]) = (uvs[1], uvs[2]);
        let (welded, report) = clean(raw, CleanOptions { weld: true }, "t").unwrap();
        assert_eq!((report.welded, welded.vertex_count()), (2, 6));
        assert!(welded.properties.position_ids.is_empty());
        assert_eq!(welded.triangles[2], [1, 4, 5]);
    }

    /// Without position ids (PLY, glTF) equal positions are one point.
    #[test]
    fn streams_without_ids_make_equal_positions_one_point() {
        let mut raw = seamed();
        raw.properties.position_ids.clear();
        let (mesh, report) = clean(raw, CleanOptions::default(), "t").unwrap();
        assert_eq!((report.welded, mesh.vertex_count()), (0, 8));
        assert_eq!(mesh.properties.position_ids, vec![0, 1, 2, 3, 1, 2, 4, 5]);
    }

    #[test]
    fn a_triangle_on_two_corners_of_one_point_is_degenerate() {
        let mut raw = seamed();
        raw.triangles.push([1, 4, 6]);
        let (mesh, report) = clean(raw, CleanOptions::default(), "t").unwrap();
        assert_eq!((mesh.triangle_count(), report.degenerate_dropped), (4, 1));
    }

    #[test]
    fn property_counts_and_shared_positions_are_checked() {
        let mut raw = seamed();
        raw.properties.uvs.as_mut().unwrap().pop();
        assert!(matches!(
            clean(raw, CleanOptions::default(), "t"),
            Err(Error::InvalidMesh { .. })
        ));
        let mut raw = seamed();
        raw.positions[4].z = 1.0;
        assert!(matches!(
            clean(raw, CleanOptions::default(), "t"),
            Err(Error::InvalidMesh { .. })
        ));
    }
}
