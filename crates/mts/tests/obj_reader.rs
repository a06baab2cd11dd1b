//! The OBJ reader against `tobj` (the reader it replaced) on every OBJ of
//! `../shared/models`: the same positions and triangles, vertex for vertex,
//! so no output of the CLI changed with the reader.

mod common;

use glam::Vec3;
use std::path::Path;

fn with_tobj(path: &Path) -> (Vec<Vec3>, Vec<[u32; 3]>) {
    let options = tobj::LoadOptions {
        triangulate: true,
        single_index: false,
        ignore_points: true,
        ignore_lines: true,
    };
    let (models, _) = tobj::load_obj(path, &options).expect("tobj reads the model");
    let (mut positions, mut triangles) = (Vec::new(), Vec::new());
    for m in &models {
        let base = positions.len() as u32;
        positions.extend(
            m.mesh
                .positions
                .chunks_exact(3)
                .map(|p| Vec3::new(p[0], p[1], p[2])),
        );
        triangles.extend(
            m.mesh
                .indices
                .chunks_exact(3)
                .map(|t| [t[0] + base, t[1] + base, t[2] + base]),
        );
    }
    (positions, triangles)
}

#[test]
fn obj_reader_matches_tobj_on_every_model() {
    let Some(dir) = common::models_dir() else {
        return;
    };
    let mut compared = 0;
    for entry in std::fs::read_dir(&dir).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().and_then(|e| e.to_str()) != Some("obj") {
            continue;
        }
        let bytes = std::fs::read(&path).unwrap();
        let raw = mts::mesh::io::parse_obj(&bytes, &path).unwrap();
        let (positions, triangles) = with_tobj(&path);
        assert_eq!(raw.positions, positions, "{}", path.display());
        assert_eq!(raw.triangles, triangles, "{}", path.display());
        compared += 1;
    }
    assert!(compared >= 10, "{compared} OBJ models compared");
}
