//! Optimal placement on meshes with properties: each step creates one
//! vertex per seam pair, with interpolated properties; seams are neither
//! torn nor multiplied, and every drawn vertex has valid properties.

mod common;

use glam::{Vec2, Vec3, Vec4};
use mts::mesh::{Mesh, Properties};
use mts::simplify::{Placement, SimplifyOptions};
use mts::{simplify, Collapses};
use proptest::prelude::*;
use std::collections::HashMap;

fn optimal() -> SimplifyOptions {
    SimplifyOptions {
        placement: Placement::Optimal,
        ..SimplifyOptions::default()
    }
}

/// The checks every LoD in `lods` must pass: the mesh at it is valid (its
/// properties one per vertex, finite, colours in range, one position per
/// point), is the oracle's, has unit normals, tears no point, and has no
/// more seam points than the input (nor, with `check_borders`, border
/// edges).
fn check_lods(
    mesh: &Mesh,
    c: &Collapses,
    lods: impl IntoIterator<Item = usize>,
    name: &str,
    check_borders: bool,
) {
    c.validate().unwrap();
    let (borders0, seams0) = common::borders_and_seam_points(mesh);
    let all = c
        .properties(mesh)
        .expect("created vertices have properties");
    let total = mesh.vertex_count() + c.appended().len();
    all.check_counts(total).unwrap();
    for lod in lods {
        let at = c.mesh_at(mesh, lod);
        at.validate().unwrap();
        let oracle = c.triangles_at(mesh, lod);
        assert_eq!(at.triangle_count(), oracle.len(), "{name} at {lod}");
        assert_eq!(oracle.len(), c.triangle_count(lod), "{name} at {lod}");
        let p = &at.properties;
        p.check_counts(at.vertex_count()).unwrap();
        assert_eq!(p.normals.is_some(), mesh.properties.normals.is_some());
        assert_eq!(p.uvs.is_some(), mesh.properties.uvs.is_some());
        assert_eq!(p.colors.is_some(), mesh.properties.colors.is_some());
        if let Some(normals) = &p.normals {
            for n in normals {
                assert!((n.length() - 1.0).abs() < 1e-3, "{name} at {lod}: {n}");
            }
        }
        if let Some(uvs) = &p.uvs {
            assert!(uvs.iter().all(|t| t.is_finite()));
        }
        // The drawn corners carry the oracle's vertices' properties.
        let rep = c.representatives(lod);
        let mut at_vertex = HashMap::new();
        for (t, o) in at.triangles.iter().zip(&oracle) {
            for k in 0..3 {
                at_vertex.insert(o[k], t[k]);
            }
        }
        if let (Some(uvs), Some(all_uvs)) = (&p.uvs, &all.uvs) {
            for (&old, &new) in &at_vertex {
                assert_eq!(uvs[new as usize], all_uvs[old as usize]);
                assert_eq!(
                    rep[old as usize], old,
                    "drawn vertices are their own representatives"
                );
            }
        }
        // No tear: the drawn vertices that the vertices of one input point
        // stand for are one point.
        let mut point_of: HashMap<u32, u32> = HashMap::new();
        for v in 0..mesh.vertex_count() as u32 {
            let r = rep[v as usize];
            if at_vertex.contains_key(&r) {
                let now = all.position_id(r);
                let was = *point_of
                    .entry(mesh.properties.position_id(v))
                    .or_insert(now);
                assert_eq!(was, now, "{name} at {lod}: a point tore");
            }
        }
        let (borders, seams) = common::borders_and_seam_points(&at);
        assert!(
            seams <= seams0,
            "{name} at {lod}: {seams} seam points, {seams0} before"
        );
        // Open random surfaces (holes, flipped and doubled triangles) may
        // change their borders; closed or clean models keep theirs.
        assert!(
            !check_borders || borders <= borders0,
            "{name} at {lod}: {borders} border edges, {borders0} before"
        );
    }
}

/// Each created vertex's properties are the interpolation of its pair's
/// at the projection of the created position on their segment.
fn check_created_properties(mesh: &Mesh, c: &Collapses) {
    let all = c.properties(mesh).unwrap();
    let positions: Vec<Vec3> = mesh.positions.iter().chain(c.appended()).copied().collect();
    for i in 0..c.max_lod() {
        let moves: Vec<(u32, u32)> = c.moves(i).collect();
        assert_eq!(moves.len(), 2 * c.created(i).len());
        for (pair, created) in moves.chunks(2).zip(c.created(i)) {
            let [(va, ca), (vb, cb)] = [pair[0], pair[1]];
            assert_eq!((ca, cb), (created, created));
            let (pa, pb, p) = (
                positions[va as usize].as_dvec3(),
                positions[vb as usize].as_dvec3(),
                positions[created as usize].as_dvec3(),
            );
            let e = pb - pa;
            let t = if e.length_squared() > 0.0 {
                ((p - pa).dot(e) / e.length_squared()).clamp(0.0, 1.0) as f32
            } else {
                0.5
            };
            if let Some(uvs) = &all.uvs {
                let want = uvs[va as usize].lerp(uvs[vb as usize], t);
                let got = uvs[created as usize];
                // `t` from the rounded created position.
                let scale = (uvs[va as usize] - uvs[vb as usize]).length() + 1.0;
                assert!(
                    (got - want).length() <= 1e-3 * scale,
                    "step {i}: {got} != {want}"
                );
            }
        }
    }
}

#[test]
fn a_seamed_torus_keeps_its_seams_closed_with_optimal_placement() {
    let g: mts::mesh::generate::Generated = "torus:2000".parse().unwrap();
    let mesh = g.build_with_properties();
    let c = simplify(&mesh, &optimal()).collapses;
    assert!(c.is_optimal_placement() && c.has_companions());
    // One created vertex per pair moved.
    let pairs: usize = (0..c.max_lod()).map(|i| c.moves(i).count() / 2).sum();
    assert_eq!(c.appended().len(), pairs);
    assert!(c.appended().len() > c.max_lod());
    let lods: Vec<usize> = (0..=c.max_lod()).step_by(37).chain([c.max_lod()]).collect();
    check_lods(&mesh, &c, lods, "torus", true);
    check_created_properties(&mesh, &c);
    let (_, seams0) = common::borders_and_seam_points(&mesh);
    assert!(seams0 > 0);
}

#[test]
fn real_models_with_seams_keep_them_with_optimal_placement() {
    for name in ["spot.obj", "pirate.obj"] {
        let Some(mesh) = common::model_with_properties(name) else {
            return;
        };
        let c = simplify(&mesh, &optimal()).collapses;
        let lods = [1.0, 0.5, 0.25, 0.1, 0.05, 0.01].map(|r| c.lod_for_ratio(r));
        check_lods(&mesh, &c, lods, name, true);
        check_created_properties(&mesh, &c);
        // The written OBJ carries the created vertices' texture coordinates.
        let at = c.mesh_at(&mesh, c.lod_for_ratio(0.1));
        let path = std::env::temp_dir().join(format!("mts-optimal-{}-{name}", std::process::id()));
        mts::mesh::io::save_mesh(&at, &path).unwrap();
        let text = std::fs::read_to_string(&path).unwrap();
        std::fs::remove_file(&path).ok();
        let vt = text.lines().filter(|l| l.starts_with("vt ")).count();
        assert!(vt > 0, "{name}: no vt written");
    }
}

/// A mesh with properties but no seam: one created vertex per step, as
/// without properties, each with properties.
#[test]
fn a_mesh_without_seams_creates_one_vertex_per_step() {
    let g: mts::mesh::generate::Generated = "icosphere:2000".parse().unwrap();
    let mesh = g.build_with_properties();
    assert!(mesh.properties.position_ids.is_empty());
    let c = simplify(&mesh, &optimal()).collapses;
    assert!(!c.has_companions());
    assert_eq!(c.appended().len(), c.max_lod());
    let lods = [0.5, 0.1, 0.01].map(|r| c.lod_for_ratio(r));
    check_lods(&mesh, &c, lods, "icosphere", true);
    check_created_properties(&mesh, &c);
}

/// The baselines that need endpoint placement refuse these sequences with
/// an error, and the MTS model says it cannot hold them.
#[test]
fn endpoint_only_consumers_refuse_cleanly() {
    let g: mts::mesh::generate::Generated = "torus:500".parse().unwrap();
    let mesh = g.build_with_properties();
    let c = simplify(&mesh, &optimal()).collapses;
    assert!(mts::baselines::pm::ProgressiveMesh::new(&mesh, &c).is_err());
    assert!(mts::baselines::multilevel::MultilevelMesh::new(&mesh, &c).is_err());
    assert!(!mts::model::can_build(&c));
    let plain = simplify(&g.build(), &optimal()).collapses;
    assert!(mts::model::can_build(&plain));
}

/// `surface` with every triangle given a chart (by `charts`), each
/// (position, chart) a vertex of its own: seams run between charts.
fn with_random_seams(surface: &Mesh, charts: &[u8]) -> Mesh {
    let chart_of = |t: usize| charts[t % charts.len()] % 3;
    let mut used: Vec<(u32, u8)> = Vec::new();
    for (t, tri) in surface.triangles.iter().enumerate() {
        for &v in tri {
            used.push((v, chart_of(t)));
        }
    }
    used.sort_unstable();
    used.dedup();
    let index: HashMap<(u32, u8), u32> = used
        .iter()
        .enumerate()
        .map(|(i, &k)| (k, i as u32))
        .collect();
    let mut ids = Vec::new();
    let mut id_of: HashMap<u32, u32> = HashMap::new();
    for &(v, _) in &used {
        let next = id_of.len() as u32;
        ids.push(*id_of.entry(v).or_insert(next));
    }
    let positions: Vec<Vec3> = used
        .iter()
        .map(|&(v, _)| surface.positions[v as usize])
        .collect();
    let triangles = surface
        .triangles
        .iter()
        .enumerate()
        .map(|(t, tri)| tri.map(|v| index[&(v, chart_of(t))]))
        .collect();
    let properties = Properties {
        uvs: Some(
            used.iter()
                .zip(&positions)
                .map(|(&(_, c), p)| Vec2::new(0.1 * p.x + f32::from(c), 0.1 * p.y))
                .collect(),
        ),
        normals: Some(
            used.iter()
                .zip(&positions)
                .map(|(&(_, c), p)| Vec3::new(p.z, f32::from(c), 1.0).normalize())
                .collect(),
        ),
        colors: Some(
            used.iter()
                .map(|&(_, c)| Vec4::new(f32::from(c) / 2.0, 0.5, 1.0, 1.0))
                .collect(),
        ),
        position_ids: ids,
        texture: None,
    };
    Mesh {
        positions,
        triangles,
        properties,
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]

    #[test]
    fn random_seamed_surfaces_keep_the_invariants_with_optimal_placement(
        surface in common::random_surface(),
        charts in prop::collection::vec(0u8..3, 1..40),
    ) {
        let mesh = with_random_seams(&surface, &charts);
        mesh.validate().unwrap();
        let c = simplify(&mesh, &optimal()).collapses;
        prop_assert!(c.validate().is_ok());
        check_lods(&mesh, &c, 0..=c.max_lod(), "random", false);
        check_created_properties(&mesh, &c);
        for lod in 0..=c.max_lod() {
            let rep = c.representatives(lod);
            for v in 0..rep.len() as u32 {
                prop_assert_eq!(rep[v as usize], c.representative(v, lod));
            }
        }
    }
}
