//! Helpers shared by the integration tests.
#![allow(dead_code)]

use glam::Vec3;
use mts::mesh::io::{load, LoadOptions};
use mts::mesh::Mesh;
use proptest::prelude::*;
use std::path::Path;

/// A random open surface: a height field over a grid with random holes,
/// triangles flipped or duplicated, and a second flat component.
pub fn random_surface() -> impl Strategy<Value = Mesh> {
    (2u32..10, 2u32..10, prop::collection::vec(0u8..20, 400)).prop_map(|(w, h, dice)| {
        let mut d = dice.iter().cycle();
        let mut roll = || *d.next().unwrap();
        let id = |x: u32, y: u32| y * (w + 1) + x;
        let mut positions = Vec::new();
        for y in 0..=h {
            for x in 0..=w {
                let z = f32::from(roll()) * 0.05;
                positions.push(Vec3::new(x as f32, y as f32, z));
            }
        }
        let mut triangles = Vec::new();
        for y in 0..h {
            for x in 0..w {
                let (a, b, c, e) = (id(x, y), id(x + 1, y), id(x + 1, y + 1), id(x, y + 1));
                for t in [[a, b, c], [a, c, e]] {
                    match roll() {
                        0 => {}
                        1 => triangles.push([t[0], t[2], t[1]]),
                        2 => {
                            triangles.push(t);
                            triangles.push(t);
                        }
                        _ => triangles.push(t),
                    }
                }
            }
        }
        let base = positions.len() as u32;
        positions.extend([
            Vec3::new(0.0, 0.0, 5.0),
            Vec3::new(1.0, 0.0, 5.0),
            Vec3::new(1.0, 1.0, 5.0),
            Vec3::new(0.0, 1.0, 5.0),
        ]);
        triangles.extend([[base, base + 1, base + 2], [base, base + 2, base + 3]]);
        let raw = mts::mesh::RawMesh {
            positions,
            triangles,
            degenerate_in_source: 0,
            properties: Default::default(),
        };
        mts::mesh::clean(raw, Default::default(), "random")
            .unwrap()
            .0
    })
}

/// Whether `MTS_REQUIRE` (a comma-separated list, set by `.ci/run`) names
/// `what`: then a missing resource fails the test instead of skipping it.
pub fn required(what: &str) -> bool {
    std::env::var("MTS_REQUIRE").is_ok_and(|v| v.split(',').any(|w| w.trim() == what))
}

/// `../shared/models`, or `None` (with a message saying the test is
/// skipped) when it is absent; a failure instead when `MTS_REQUIRE` names
/// `models`.
pub fn models_dir() -> Option<std::path::PathBuf> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/models");
    if dir.is_dir() {
        return Some(dir);
    }
    assert!(
        !required("models"),
        "{} not found and MTS_REQUIRE names models",
        dir.display()
    );
    eprintln!("skipped: {} not found", dir.display());
    None
}

/// A model from `../shared/models`, or `None` (with a message saying the test
/// is skipped) when the directory is absent (a failure when `MTS_REQUIRE`
/// names `models`).
pub fn model(name: &str) -> Option<Mesh> {
    let path = models_dir()?.join(name);
    if !path.exists() {
        assert!(
            !required("models"),
            "{} not found and MTS_REQUIRE names models",
            path.display()
        );
        eprintln!(
            "skipped: {} not found (needs ../shared/models)",
            path.display()
        );
        return None;
    }
    Some(load(&path, LoadOptions::default()).unwrap().0)
}

/// [`model`] loaded with its properties (normals, texture coordinates,
/// colours; vertices split at seams).
pub fn model_with_properties(name: &str) -> Option<Mesh> {
    let path = models_dir()?.join(name);
    let options = LoadOptions {
        properties: true,
        ..LoadOptions::default()
    };
    Some(load(&path, options).unwrap().0)
}

/// Edges between points (not vertices) used by one triangle only, and the
/// points that carry more than one vertex, of `mesh` (at a LoD).
pub fn borders_and_seam_points(mesh: &Mesh) -> (usize, usize) {
    use std::collections::HashMap;
    let p = &mesh.properties;
    let mut edges: HashMap<(u32, u32), u32> = HashMap::new();
    for t in &mesh.triangles {
        let t = t.map(|v| p.position_id(v));
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            *edges.entry((a.min(b), a.max(b))).or_default() += 1;
        }
    }
    let borders = edges.values().filter(|&&n| n == 1).count();
    let mut vertices_of: HashMap<u32, u32> = HashMap::new();
    for v in 0..mesh.vertex_count() as u32 {
        *vertices_of.entry(p.position_id(v)).or_default() += 1;
    }
    (borders, vertices_of.values().filter(|&&n| n > 1).count())
}

/// A 2 × 2 RGB PNG (red, green / blue, white).
pub const PNG: &[u8] = &[
    137, 80, 78, 71, 13, 10, 26, 10, 0, 0, 0, 13, 73, 72, 68, 82, 0, 0, 0, 2, 0, 0, 0, 2, 8, 2, 0,
    0, 0, 253, 212, 154, 115, 0, 0, 0, 17, 73, 68, 65, 84, 120, 156, 99, 248, 207, 192, 192, 0,
    194, 64, 18, 8, 0, 33, 237, 5, 251, 97, 102, 21, 174, 0, 0, 0, 0, 73, 69, 78, 68, 174, 66, 96,
    130,
];

/// A fresh folder `group/name` under Cargo's scratch space for
/// integration tests.
pub fn scratch(group: &str, name: &str) -> std::path::PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join(group)
        .join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Standard base64 with padding (glTF data URIs).
pub fn base64(bytes: &[u8]) -> String {
    const ALPHABET: &[u8] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut out = String::new();
    for group in bytes.chunks(3) {
        let b = [
            group[0],
            *group.get(1).unwrap_or(&0),
            *group.get(2).unwrap_or(&0),
        ];
        let n = u32::from(b[0]) << 16 | u32::from(b[1]) << 8 | u32::from(b[2]);
        for k in 0..4 {
            if k <= group.len() {
                out.push(ALPHABET[(n >> (18 - 6 * k) & 63) as usize] as char);
            } else {
                out.push('=');
            }
        }
    }
    out
}
