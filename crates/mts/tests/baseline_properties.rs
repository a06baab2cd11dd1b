//! The baselines on meshes with properties and seams: contraction steps
//! that move a point's several vertices (companions), the property streams
//! carried in each baseline's vertex order, the progressive mesh file and
//! the cluster-tree stream in their second format, and damage to the new
//! fields.

mod common;

use common::{model_with_properties, random_surface};
use glam::Vec2;
use mts::baselines::cluster::stream;
use mts::baselines::{ClusterTree, MultilevelMesh, ProgressiveMesh};
use mts::mesh::generate::Generated;
use mts::mesh::{clean, Properties, RawMesh};
use mts::model::requests;
use mts::strip::sorted_canonical;
use mts::{Collapses, LodSource, Mesh};
use proptest::prelude::*;

fn seamed_torus() -> Mesh {
    "torus:2k"
        .parse::<Generated>()
        .unwrap()
        .build_with_properties()
}

fn collapses(mesh: &Mesh) -> Collapses {
    mts::simplify(mesh, &Default::default()).collapses
}

/// A vertex as drawn: its position and property values, bit for bit.
fn key(positions: &[glam::Vec3], p: &Properties, v: u32) -> Vec<u32> {
    let v = v as usize;
    let mut k: Vec<u32> = positions[v].to_array().map(f32::to_bits).to_vec();
    if let Some(n) = &p.normals {
        k.extend(n[v].to_array().map(f32::to_bits));
    }
    if let Some(t) = &p.uvs {
        k.extend(t[v].to_array().map(f32::to_bits));
    }
    if let Some(c) = &p.colors {
        k.extend(c[v].to_array().map(f32::to_bits));
    }
    k
}

/// Triangles as drawn vertices, each rotated to start at its least vertex,
/// sorted: equal for two sources exactly when they draw the same oriented
/// triangles with the same positions and properties.
fn drawn(positions: &[glam::Vec3], p: &Properties, triangles: &[[u32; 3]]) -> Vec<[Vec<u32>; 3]> {
    let mut out: Vec<[Vec<u32>; 3]> = triangles
        .iter()
        .map(|t| {
            let k = t.map(|v| key(positions, p, v));
            let m = (0..3).min_by(|&a, &b| k[a].cmp(&k[b])).unwrap();
            [k[m].clone(), k[(m + 1) % 3].clone(), k[(m + 2) % 3].clone()]
        })
        .collect();
    out.sort();
    out
}

fn source_triangles(source: &dyn LodSource) -> Vec<[u32; 3]> {
    source
        .indices()
        .chunks_exact(3)
        .map(|c| [c[0], c[1], c[2]])
        .collect()
}

/// At every LoD of `lods`: the source's triangles, mapped to the input, are
/// the oracle's, and the vertices it draws carry the oracle's properties.
fn check(mesh: &Mesh, c: &Collapses, source: &mut dyn LodSource, lods: &[usize]) {
    let streams = Properties {
        position_ids: Vec::new(),
        texture: None,
        ..mesh.properties.clone()
    };
    assert_eq!(
        source.properties().check_counts(source.positions().len()),
        Ok(())
    );
    assert!(source.properties().position_ids.is_empty());
    for &lod in lods {
        assert_eq!(source.set_lod(lod), lod);
        let want = c.triangles_at(mesh, lod);
        assert_eq!(
            sorted_canonical(&source.triangles()),
            sorted_canonical(&want),
            "{}: LoD {lod} triangles",
            source.name()
        );
        assert_eq!(
            drawn(
                source.positions(),
                source.properties(),
                &source_triangles(source)
            ),
            drawn(&mesh.positions, &streams, &want),
            "{}: LoD {lod} properties",
            source.name()
        );
    }
}

fn spread(max_lod: usize) -> Vec<usize> {
    let mut l: Vec<usize> = (0..=max_lod).step_by((max_lod / 40).max(1)).collect();
    l.push(max_lod);
    l.extend((0..=max_lod).rev().step_by((max_lod / 25).max(1)));
    l.extend(requests::random(max_lod, 60, 3));
    l
}

#[test]
fn every_baseline_carries_the_seamed_torus_properties() {
    let mesh = seamed_torus();
    assert!(!mesh.properties.position_ids.is_empty());
    let c = collapses(&mesh);
    assert!(c.has_companions(), "the torus seams give companion moves");
    let lods = spread(c.max_lod());
    let mut pm = ProgressiveMesh::new(&mesh, &c).unwrap();
    pm.validate().unwrap();
    check(&mesh, &c, &mut pm, &lods);
    let mut ml = MultilevelMesh::new(&mesh, &c).unwrap();
    ml.validate().unwrap();
    check(&mesh, &c, &mut ml, &lods);
    // Geomorphs use the stored vertex counts: at t = 1 a LoD's own shape.
    let mut g = Vec::new();
    ml.geomorph(10, 200, 1.0, &mut g).unwrap();
    assert_eq!(&g[..], &ml.positions()[..g.len()]);
    let tree = ClusterTree::new(&mesh).unwrap();
    let tc = tree.collapses().clone();
    check(&mesh, &tc, &mut tree.clone(), &spread(tc.max_lod()));
    // Property bytes are counted: 12 + 8 + 16 bytes per vertex of streams.
    let bytes = mesh.properties.bytes_per_vertex() * mesh.vertex_count();
    assert_eq!(mesh.properties.bytes_per_vertex(), 36);
    assert!(pm.structure_bytes() > bytes && ml.structure_bytes() > bytes);
}

#[cfg(feature = "peers")]
#[test]
fn discrete_lods_draw_the_input_properties() {
    let mesh = seamed_torus();
    let c = collapses(&mesh);
    let mut d = mts::baselines::DiscreteLods::new(&mesh, c.triangle_counts());
    assert_eq!(d.properties().uvs, mesh.properties.uvs);
    assert_eq!(d.properties().normals, mesh.properties.normals);
    assert_eq!(d.properties().colors, mesh.properties.colors);
    let without = mts::baselines::DiscreteLods::new(
        &Mesh {
            properties: Properties::default(),
            ..mesh.clone()
        },
        c.triangle_counts(),
    );
    assert_eq!(
        d.memory_bytes() - without.memory_bytes(),
        36 * mesh.vertex_count()
    );
    d.set_lod(c.max_lod() / 2);
    assert!(d
        .indices()
        .iter()
        .all(|&v| (v as usize) < mesh.vertex_count()));
}

#[test]
fn progressive_mesh_file_keeps_properties_and_companions() {
    let mesh = seamed_torus();
    let c = collapses(&mesh);
    let mut pm = ProgressiveMesh::new(&mesh, &c).unwrap();
    let bytes = pm.to_bytes();
    assert_eq!(&bytes[..8], mts::baselines::pm::MAGIC_V2);
    let mut back = ProgressiveMesh::from_bytes(&bytes, "torus.pm").unwrap();
    back.validate().unwrap();
    assert_eq!(back.to_bytes(), bytes);
    assert_eq!(back.properties(), pm.properties());
    for lod in [0, 1, 7, c.max_lod() / 3, c.max_lod() / 2, c.max_lod(), 3] {
        pm.set_lod(lod);
        back.set_lod(lod);
        assert_eq!(pm.indices(), back.indices(), "LoD {lod}");
    }
}

#[test]
fn stream_of_a_seamed_mesh_decodes_with_its_properties() {
    let mesh = seamed_torus();
    let streams = Properties {
        position_ids: Vec::new(),
        texture: None,
        ..mesh.properties.clone()
    };
    // The cluster tree's own hierarchy (no companions)...
    let tree = ClusterTree::new(&mesh).unwrap();
    let bytes = tree.to_stream();
    assert_eq!(&bytes[..8], stream::MAGIC_V2);
    let d = stream::decode(&bytes, "torus.stream").unwrap();
    assert!(d.is_complete());
    assert_eq!(
        d.properties,
        mesh.properties.gather(tree.stream_order()).clone_streams()
    );
    assert_eq!(
        drawn(&d.positions, &d.properties, &d.triangles),
        drawn(&mesh.positions, &streams, &mesh.triangles)
    );
    // ...and a simplification's, whose steps move several vertices.
    let c = collapses(&mesh);
    let pm = ProgressiveMesh::new(&mesh, &c).unwrap();
    let bytes = stream::encode(&pm);
    let d = stream::decode(&bytes, "pm.stream").unwrap();
    assert_eq!(
        drawn(&d.positions, &d.properties, &d.triangles),
        drawn(&mesh.positions, &streams, &mesh.triangles)
    );
    for len in (stream::HEADER_BYTES_V2..bytes.len()).step_by(53) {
        let p = stream::decode_prefix(&bytes[..len], "prefix").unwrap();
        p.mesh().validate().unwrap();
        assert_eq!(p.positions[..], d.positions[..p.positions.len()]);
    }
}

/// Only the streams a baseline carries (no position ids, no texture).
trait CloneStreams {
    fn clone_streams(&self) -> Properties;
}

impl CloneStreams for Properties {
    fn clone_streams(&self) -> Properties {
        Properties {
            position_ids: Vec::new(),
            texture: None,
            ..self.clone()
        }
    }
}

#[test]
fn damaged_second_format_files_get_located_errors() {
    let mesh = seamed_torus();
    let c = collapses(&mesh);
    let pm = ProgressiveMesh::new(&mesh, &c).unwrap();
    let bytes = pm.to_bytes();
    let err = |b: &[u8]| {
        ProgressiveMesh::from_bytes(b, "bad.pm")
            .unwrap_err()
            .to_string()
    };
    // Header: magic, counts (3 × 4 bytes), roots (4), flags (1).
    let mut flags = bytes.clone();
    flags[24] = 0xf8;
    assert!(err(&flags).contains("property flags"), "{}", err(&flags));
    let mut roots = bytes.clone();
    roots[20..24].copy_from_slice(&0u32.to_le_bytes());
    assert!(err(&roots).contains("root count"), "{}", err(&roots));
    let mut roots = bytes.clone();
    roots[20..24].copy_from_slice(&u32::MAX.to_le_bytes());
    assert!(err(&roots).contains("root count"), "{}", err(&roots));
    // The first vertex's normal (after its position) scaled: not unit.
    let mut normal = bytes.clone();
    normal[25 + 12..25 + 16].copy_from_slice(&2.0f32.to_le_bytes());
    let e = err(&normal);
    assert!(e.contains("normal") && e.contains("bad.pm"), "{e}");
    let mut colour = bytes.clone();
    colour[25 + 32..25 + 36].copy_from_slice(&7.0f32.to_le_bytes());
    assert!(err(&colour).contains("colour"), "{}", err(&colour));
    for len in (0..bytes.len()).step_by(89).chain([bytes.len() - 1]) {
        match ProgressiveMesh::from_bytes(&bytes[..len], "cut.pm").unwrap_err() {
            mts::Error::Parse { .. } => {}
            other => panic!("{len} bytes: expected a parse error, got {other:?}"),
        }
    }
    let records = 25 + (12 + 36) * mesh.vertex_count();
    for at in (records..bytes.len()).step_by(7) {
        let mut b = bytes.clone();
        b[at] ^= 0x5a;
        if let Ok(pm) = ProgressiveMesh::from_bytes(&b, "flip.pm") {
            pm.validate().unwrap();
        }
    }

    let s = stream::encode(&pm);
    let serr = |b: &[u8]| stream::decode(b, "bad.stream").unwrap_err().to_string();
    let mut flags = s.clone();
    flags[24..28].copy_from_slice(&0x40u32.to_le_bytes());
    assert!(serr(&flags).contains("flags"), "{}", serr(&flags));
    assert!(serr(&s[..HEADER_SHORT]).contains("truncated"));
    for len in (stream::HEADER_BYTES_V2..s.len()).step_by(61) {
        assert!(stream::decode(&s[..len], "cut").is_err());
    }
    for at in (stream::HEADER_BYTES_V2..s.len()).step_by(41) {
        let mut b = s.clone();
        b[at] ^= 0x21;
        assert!(serr(&b).contains("checksum"));
        if let Ok(d) = stream::decode_prefix(&b, "flip") {
            d.mesh().validate().unwrap();
        }
    }
}

/// Longer than the first format's header, shorter than the second's.
const HEADER_SHORT: usize = stream::HEADER_BYTES + 2;

#[test]
fn spot_baselines_match_the_oracle_with_properties() {
    let Some(mesh) = model_with_properties("spot.obj") else {
        return;
    };
    let c = collapses(&mesh);
    assert!(c.has_companions());
    let spread: Vec<usize> = [0, 1, 50, 500, 2000, c.max_lod() / 2, c.max_lod(), 10]
        .into_iter()
        .map(|l| l.min(c.max_lod()))
        .collect();
    check(
        &mesh,
        &c,
        &mut ProgressiveMesh::new(&mesh, &c).unwrap(),
        &spread,
    );
    check(
        &mesh,
        &c,
        &mut MultilevelMesh::new(&mesh, &c).unwrap(),
        &spread,
    );
    let pm = ProgressiveMesh::new(&mesh, &c).unwrap();
    let back = ProgressiveMesh::from_bytes(&pm.to_bytes(), "spot.pm").unwrap();
    assert_eq!(back.to_bytes(), pm.to_bytes());
    let tree = ClusterTree::new(&mesh).unwrap();
    let d = stream::decode(&tree.to_stream(), "spot.stream").unwrap();
    assert_eq!(
        d.properties,
        mesh.properties.gather(tree.stream_order()).clone_streams()
    );
}

/// A random surface with a UV seam along a column and another along a row:
/// triangles past each cut use copies of the cut's vertices (same position
/// id) with other texture coordinates.
fn random_seamed_surface() -> impl Strategy<Value = Mesh> {
    (random_surface(), 0u32..6, 0u32..6).prop_map(|(mesh, cx, cy)| {
        let mut positions = mesh.positions.clone();
        let mut ids: Vec<u32> = (0..positions.len() as u32).collect();
        let mut uvs: Vec<Vec2> = positions.iter().map(|p| Vec2::new(p.x, p.y)).collect();
        let mut triangles = mesh.triangles.clone();
        for axis in [0usize, 1] {
            let cut = if axis == 0 { cx } else { cy } as f32;
            let mut copy = std::collections::HashMap::new();
            for t in &mut triangles {
                let centre: f32 = t.iter().map(|&v| positions[v as usize][axis]).sum::<f32>() / 3.0;
                if centre <= cut {
                    continue;
                }
                for v in t.iter_mut() {
                    if positions[*v as usize][axis] == cut {
                        *v = *copy.entry(*v).or_insert_with(|| {
                            positions.push(positions[*v as usize]);
                            ids.push(ids[*v as usize]);
                            uvs.push(uvs[*v as usize] + Vec2::new(3.0 + axis as f32, 1.0));
                            positions.len() as u32 - 1
                        });
                    }
                }
            }
        }
        let raw = RawMesh {
            positions,
            triangles,
            degenerate_in_source: 0,
            properties: Properties {
                uvs: Some(uvs),
                position_ids: ids,
                ..Properties::default()
            },
        };
        clean(raw, Default::default(), "random seamed").unwrap().0
    })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]

    #[test]
    fn random_seamed_meshes_every_lod(mesh in random_seamed_surface()) {
        let c = collapses(&mesh);
        let mut lods: Vec<usize> = (0..=c.max_lod()).collect();
        lods.extend(requests::random(c.max_lod(), 20, 5));
        let mut pm = ProgressiveMesh::new(&mesh, &c).unwrap();
        pm.validate().unwrap();
        check(&mesh, &c, &mut pm, &lods);
        let mut ml = MultilevelMesh::new(&mesh, &c).unwrap();
        ml.validate().unwrap();
        check(&mesh, &c, &mut ml, &lods);
        let bytes = pm.to_bytes();
        let mut back = ProgressiveMesh::from_bytes(&bytes, "random.pm").unwrap();
        back.validate().unwrap();
        prop_assert_eq!(back.to_bytes(), bytes);
        for &lod in &lods {
            pm.set_lod(lod);
            back.set_lod(lod);
            prop_assert_eq!(pm.indices(), back.indices());
        }
        let s = stream::encode(&pm);
        let d = stream::decode(&s, "random.stream").unwrap();
        let streams = mesh.properties.clone_streams();
        prop_assert_eq!(
            drawn(&d.positions, &d.properties, &d.triangles),
            drawn(&mesh.positions, &streams, &mesh.triangles)
        );
    }
}
