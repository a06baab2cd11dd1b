//! Simplification of meshes with seams (vertices split by texture
//! coordinates or normals): seams are neither torn nor smeared at any LoD.

mod common;

use mts::mesh::Mesh;
use mts::{simplify, SimplifyOptions};

#[test]
fn seams_stay_closed_and_never_multiply() {
    for name in ["spot.obj", "pirate.obj", "suzanne.obj", "beetle.obj"] {
        let Some(mesh) = common::model_with_properties(name) else {
            return;
        };
        let (borders0, seam_points0) = common::borders_and_seam_points(&mesh);
        // Suzanne's normals are one per position: no seam there.
        assert_eq!(seam_points0 > 0, name != "suzanne.obj", "{name}");
        let s = simplify(&mesh, &SimplifyOptions::default());
        s.collapses.validate().unwrap();
        let c = &s.collapses;
        for share in [0.5, 0.25, 0.1, 0.05, 0.01] {
            let lod = c.lod_for_ratio(share);
            let at = c.mesh_at(&mesh, lod);
            at.validate().unwrap();
            let (borders, seam_points) = common::borders_and_seam_points(&at);
            assert!(
                borders <= borders0,
                "{name} at {share}: {borders} border edges, {borders0} in the input"
            );
            assert!(
                seam_points <= seam_points0,
                "{name} at {share}: {seam_points} seam points, {seam_points0} in the input"
            );
        }
    }
}

/// The MTS model of a mesh with seams: the extractor draws the oracle's
/// triangles at every LoD checked (so every corner's properties are the
/// oracle's: they belong to the vertices), and the ready (version-3) file
/// and the recipe-only (version-2) file give the same model back.
#[test]
fn models_of_seamed_meshes_match_the_oracle_and_round_trip() {
    use mts::model::build_from_mesh;
    use mts::strip::sorted_canonical;
    use mts::{Extractor, MtsModel};
    for name in ["spot.obj", "pirate.obj"] {
        let Some(mesh) = common::model_with_properties(name) else {
            return;
        };
        let (model, _, _) = build_from_mesh(&mesh, &Default::default(), &mut |_, _| {});
        model.validate().unwrap();
        assert_eq!(model.properties(), &mesh.properties, "{name}");
        assert!(model.collapses().has_companions(), "{name}");
        let recipe = model.to_recipe_bytes();
        assert_eq!(u32::from_le_bytes(recipe[8..12].try_into().unwrap()), 2);
        let built = MtsModel::from_bytes(&recipe, std::path::Path::new(name)).unwrap();
        assert_eq!(built, model, "{name}");
        let bytes = model.to_bytes();
        assert_eq!(u32::from_le_bytes(bytes[8..12].try_into().unwrap()), 3);
        let back = MtsModel::from_bytes(&bytes, std::path::Path::new(name)).unwrap();
        assert_eq!(back, model, "{name}");
        assert_eq!(back.properties(), model.properties(), "{name}");
        assert_eq!(back.collapses(), model.collapses(), "{name}");
        let (mut ex, mut ex_back) = (Extractor::new(&model), Extractor::new(&back));
        let c = model.collapses();
        for share in [1.0, 0.5, 0.1, 0.01] {
            let lod = c.lod_for_ratio(share);
            ex.set_lod(lod);
            ex_back.set_lod(lod);
            let oracle = sorted_canonical(&c.triangles_at(&mesh, lod));
            assert_eq!(
                sorted_canonical(&ex.triangles()),
                oracle,
                "{name} at {share}"
            );
            assert_eq!(ex_back.triangles(), ex.triangles(), "{name} at {share}");
        }
    }
}

/// A grid with a UV seam down its middle column: the triangles right of it
/// use copies of the column's vertices with other texture coordinates.
fn seamed_grid() -> Mesh {
    use glam::Vec2;
    use mts::mesh::{clean, Properties, RawMesh};
    let grid: Mesh = "grid:200"
        .parse::<mts::mesh::generate::Generated>()
        .unwrap()
        .build();
    let xs: Vec<f32> = grid.positions.iter().map(|p| p.x).collect();
    let (lo, hi) = xs
        .iter()
        .fold((f32::MAX, f32::MIN), |(a, b), &x| (a.min(x), b.max(x)));
    let mid = *xs
        .iter()
        .min_by(|a, b| {
            (*a - (lo + hi) / 2.0)
                .abs()
                .total_cmp(&(*b - (lo + hi) / 2.0).abs())
        })
        .unwrap();
    let n = grid.vertex_count() as u32;
    let mut positions = grid.positions.clone();
    let mut ids: Vec<u32> = (0..n).collect();
    let mut uvs: Vec<Vec2> = grid.positions.iter().map(|p| Vec2::new(p.x, p.y)).collect();
    let mut copy = std::collections::HashMap::new();
    let mut triangles = grid.triangles.clone();
    for t in &mut triangles {
        let cx: f32 = t.iter().map(|&v| xs[v as usize]).sum::<f32>() / 3.0;
        if cx <= mid {
            continue;
        }
        for v in t.iter_mut() {
            if xs[*v as usize] == mid {
                *v = *copy.entry(*v).or_insert_with(|| {
                    positions.push(grid.positions[*v as usize]);
                    ids.push(*v);
                    uvs.push(uvs[*v as usize] + Vec2::new(5.0, 0.0));
                    positions.len() as u32 - 1
                });
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
    clean(raw, Default::default(), "seamed grid").unwrap().0
}

#[test]
fn corrupt_version_2_files_are_errors_or_valid_models() {
    use mts::model::{build_from_mesh, format::seal};
    use mts::MtsModel;
    let mesh = seamed_grid();
    let (_, seam_points) = common::borders_and_seam_points(&mesh);
    assert!(seam_points > 5);
    let (model, _, _) = build_from_mesh(&mesh, &Default::default(), &mut |_, _| {});
    assert!(model.collapses().has_companions());
    let good = model.to_bytes();
    let path = std::path::Path::new("grid.mts");
    assert_eq!(
        MtsModel::from_bytes(&good, path).unwrap().collapses(),
        model.collapses()
    );
    // Version 1 cannot hold it: a file claiming 1 is refused at its
    // section count.
    let mut b = good.clone();
    b[8] = 1;
    seal(&mut b);
    match MtsModel::from_bytes(&b, path).unwrap_err() {
        mts::Error::Parse { place, .. } => assert_eq!(place.byte, Some(12)),
        e => panic!("{e:?}"),
    }
    for cut in (0..good.len()).step_by(5) {
        assert!(MtsModel::from_bytes(&good[..cut], path).is_err());
    }
    for i in (32..good.len()).step_by(2) {
        let mut b = good.clone();
        b[i] ^= 0x5a;
        seal(&mut b);
        if let Ok(m) = MtsModel::from_bytes(&b, path) {
            m.validate().unwrap();
        }
    }
}

#[test]
fn generated_properties_are_valid_and_the_torus_seams_stay_closed() {
    use mts::mesh::generate::Generated;
    for name in ["torus:2000", "grid:2000", "icosphere:2000"] {
        let g: Generated = name.parse().unwrap();
        let mesh = g.build_with_properties();
        mesh.validate().unwrap();
        let plain = g.build();
        assert_eq!(mesh.triangle_count(), plain.triangle_count(), "{name}");
        let p = &mesh.properties;
        assert!(p.colors.is_some() && p.normals.is_some(), "{name}");
        assert_eq!(p.uvs.is_some(), !name.starts_with("icosphere"), "{name}");
        let (borders0, seam_points0) = common::borders_and_seam_points(&mesh);
        // The torus's two seam loops meet at one point.
        assert_eq!(seam_points0 > 0, name.starts_with("torus"), "{name}");
        let s = simplify(&mesh, &SimplifyOptions::default());
        for share in [0.1, 0.01] {
            let at = s.collapses.mesh_at(&mesh, s.collapses.lod_for_ratio(share));
            at.validate().unwrap();
            let (borders, seam_points) = common::borders_and_seam_points(&at);
            assert!(
                borders <= borders0 && seam_points <= seam_points0,
                "{name} at {share}"
            );
        }
    }
}

/// On a flat grid whose texture coordinates bend (u = e^4x), geometry
/// costs nothing and only the attribute quadrics tell contractions apart:
/// with them the texture coordinates are kept better.
#[test]
fn attribute_quadrics_lower_uv_error_where_geometry_is_silent() {
    use glam::Vec2;
    let g: mts::mesh::generate::Generated = "grid:5000".parse().unwrap();
    let mut mesh = g.build_with_properties();
    let uvs = mesh.properties.uvs.as_mut().unwrap();
    for t in uvs.iter_mut() {
        *t = Vec2::new((4.0 * t.x).exp() / 54.6, t.y);
    }
    let error_at = |uv: f32| {
        let o = SimplifyOptions {
            attribute_weights: mts::simplify::AttributeWeights {
                uv,
                normal: 0.0,
                color: 0.0,
            },
            ..SimplifyOptions::default()
        };
        let c = simplify(&mesh, &o).collapses;
        let at = c.mesh_at(&mesh, c.lod_for_ratio(0.05));
        mts::distance::property_error(&mesh, &at, 20_000)
            .uv
            .unwrap()
            .rms
    };
    // Measured: 0.0035 without, 0.00031 at weight 0.2, 0.000066 at 1.
    let (without, with) = (error_at(0.0), error_at(0.2));
    assert!(with < 0.2 * without, "without {without}, with {with}");
}

/// glTF and PLY cannot say which vertices a seam split: loading them with
/// properties takes equal positions as one point, so a written seamed
/// torus comes back with the points it had.
#[test]
fn written_seams_come_back_as_points_from_every_format() {
    use mts::mesh::io::{load, save_mesh, LoadOptions};
    let mesh: Mesh = "torus:2000"
        .parse::<mts::mesh::generate::Generated>()
        .unwrap()
        .build_with_properties();
    let points = |m: &Mesh| 1 + *m.properties.position_ids.iter().max().unwrap() as usize;
    let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("seams_formats");
    std::fs::create_dir_all(&dir).unwrap();
    let options = LoadOptions {
        properties: true,
        ..LoadOptions::default()
    };
    let mut formats = vec!["obj", "ply"];
    if cfg!(feature = "gltf") {
        formats.push("glb");
    }
    for ext in formats {
        let path = dir.join(format!("torus.{ext}"));
        save_mesh(&mesh, &path).unwrap();
        let (back, _) = load(&path, options).unwrap();
        assert_eq!(back.vertex_count(), mesh.vertex_count(), "{ext}");
        assert_eq!(points(&back), points(&mesh), "{ext}");
    }
}
