//! OBJ texture coordinates, normals, seams and textures: read against
//! `tobj`, written and read back, and the material file's texture.

mod common;

use glam::{Vec2, Vec3};
use mts::mesh::io::{load, parse_obj_with, save_obj, LoadOptions};
use mts::mesh::{Mesh, Texture};
use std::path::{Path, PathBuf};

fn with_properties() -> LoadOptions {
    LoadOptions {
        properties: true,
        ..LoadOptions::default()
    }
}

/// A fresh folder under the target directory for one test's files.
fn scratch(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// The values at every corner, triangle by triangle: what a renderer
/// draws, whatever the vertex numbering.
fn corners(mesh: &Mesh) -> Vec<(Vec3, Option<Vec2>, Option<Vec3>)> {
    let p = &mesh.properties;
    mesh.triangles
        .iter()
        .flatten()
        .map(|&v| {
            let v = v as usize;
            (
                mesh.positions[v],
                p.uvs.as_ref().map(|s| s[v]),
                p.normals.as_ref().map(|s| s[v]),
            )
        })
        .collect()
}

#[test]
fn properties_match_tobj_single_index_on_every_model_with_them() {
    let Some(dir) = common::models_dir() else {
        return;
    };
    let mut compared = 0;
    for name in ["spot.obj", "pirate.obj", "beetle.obj", "suzanne.obj"] {
        let path = dir.join(name);
        let raw = parse_obj_with(&std::fs::read(&path).unwrap(), &path, true).unwrap();
        let options = tobj::LoadOptions {
            single_index: true,
            triangulate: true,
            ..tobj::LoadOptions::default()
        };
        let (models, _) = tobj::load_obj(&path, &options).unwrap();
        let (mut positions, mut uvs, mut normals, mut triangles) =
            (Vec::new(), Vec::new(), Vec::new(), Vec::new());
        for m in &models {
            let base = positions.len() as u32;
            let m = &m.mesh;
            positions.extend(m.positions.chunks_exact(3).map(Vec3::from_slice));
            uvs.extend(m.texcoords.chunks_exact(2).map(Vec2::from_slice));
            normals.extend(m.normals.chunks_exact(3).map(Vec3::from_slice));
            triangles.extend(
                m.indices
                    .chunks_exact(3)
                    .map(|t| [t[0] + base, t[1] + base, t[2] + base]),
            );
        }
        assert_eq!(raw.positions, positions, "{name}");
        assert_eq!(raw.triangles, triangles, "{name}");
        let p = &raw.properties;
        assert_eq!(p.uvs.clone().unwrap_or_default(), uvs, "{name}");
        assert_eq!(p.normals.clone().unwrap_or_default(), normals, "{name}");
        // Every vertex's point is its `v`: same position wherever it repeats.
        assert_eq!(p.position_ids.len(), raw.positions.len(), "{name}");
        let (mesh, _) = load(&path, with_properties()).unwrap();
        mesh.validate().unwrap();
        compared += 1;
    }
    assert_eq!(compared, 4);
}

#[test]
fn spot_splits_at_its_uv_seams() {
    let Some(spot) = common::model("spot.obj") else {
        return;
    };
    let dir = common::models_dir().unwrap();
    let (mesh, _) = load(&dir.join("spot.obj"), with_properties()).unwrap();
    assert_eq!(mesh.triangle_count(), spot.triangle_count());
    // 3,225 `vt` over 2,930 positions: more vertices than points.
    assert!(mesh.vertex_count() > spot.vertex_count());
    let points = 1 + *mesh.properties.position_ids.iter().max().unwrap() as usize;
    assert_eq!(points, spot.vertex_count());
    assert!(mesh.properties.uvs.is_some() && mesh.properties.normals.is_none());
}

#[test]
fn a_seam_a_material_texture_and_a_missing_library() {
    let dir = scratch("obj_seam");
    std::fs::write(
        dir.join("m.mtl"),
        "newmtl plain\nKd 1 0 0\nnewmtl checker\nmap_Kd -s 1 1 1 checker.png\n",
    )
    .unwrap();
    // Two triangles over the edge 2–3, with other UVs on each side.
    let obj = "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n\
               vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvt 5 5\nvt 6 6\nvn 0 0 2\n\
               usemtl checker\nf 1/1/1 2/2/1 3/3/1\nf 1/5/1 3/6/1 4/4/1\n";
    let path = dir.join("seam.obj");
    std::fs::write(&path, obj).unwrap();
    // A texture file that does not exist is a warning: the mesh is read
    // untextured (a later .glb write or draw has nothing to read).
    let (missing, _) = load(&path, with_properties()).unwrap();
    assert_eq!(missing.properties.texture, None);
    std::fs::write(dir.join("checker.png"), b"not read by the loader").unwrap();
    let (mesh, _) = load(&path, with_properties()).unwrap();
    assert_eq!(mesh.vertex_count(), 6);
    assert_eq!(mesh.properties.position_ids, vec![0, 1, 2, 0, 2, 3]);
    let uvs = mesh.properties.uvs.as_ref().unwrap();
    assert_eq!(uvs[3], Vec2::new(5.0, 5.0));
    // Normals are normalised.
    assert_eq!(mesh.properties.normals.as_ref().unwrap()[0], Vec3::Z);
    assert_eq!(
        mesh.properties.texture,
        Some(Texture::File(dir.join("checker.png")))
    );
    // Without the library: the same mesh, untextured.
    std::fs::remove_file(dir.join("m.mtl")).unwrap();
    let (bare, _) = load(&path, with_properties()).unwrap();
    assert_eq!(bare.properties.texture, None);
    assert_eq!(bare.properties.uvs, mesh.properties.uvs);
    // Without properties: positions only, as before.
    let (plain, _) = load(&path, LoadOptions::default()).unwrap();
    assert_eq!(plain.vertex_count(), 4);
    assert!(plain.properties.is_empty());
}

#[test]
fn written_obj_reads_back_with_its_seams_and_properties() {
    let Some(dir) = common::models_dir() else {
        return;
    };
    let out = scratch("obj_round_trip");
    for name in ["spot.obj", "pirate.obj", "suzanne.obj"] {
        let (mesh, _) = load(&dir.join(name), with_properties()).unwrap();
        let path = out.join(name);
        save_obj(&mesh, &path).unwrap();
        let (back, _) = load(&path, with_properties()).unwrap();
        back.validate().unwrap();
        assert_eq!(back.vertex_count(), mesh.vertex_count(), "{name}");
        assert_eq!(back.triangles.len(), mesh.triangles.len(), "{name}");
        // Positions and UVs to the bit; normals within rounding (they are
        // normalised again on the way in).
        for (i, (a, b)) in corners(&back).iter().zip(corners(&mesh)).enumerate() {
            let same_normal = match (a.2, b.2) {
                (Some(x), Some(y)) => x.abs_diff_eq(y, 1e-6),
                (x, y) => x == y,
            };
            assert!(
                a.0 == b.0 && a.1 == b.1 && same_normal,
                "{name}: corner {i}: {a:?} against {b:?}"
            );
        }
        assert_eq!(
            back.properties.position_ids.iter().max(),
            mesh.properties.position_ids.iter().max(),
            "{name}: points"
        );
    }
}
