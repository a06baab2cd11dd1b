//! Simplification of meshes with seams (vertices split by texture
//! coordinates or normals): seams are neither torn nor smeared at any LoD.

mod common;

use mts::mesh::io::{load, LoadOptions};
use mts::mesh::Mesh;
use mts::{simplify, SimplifyOptions};
use std::collections::HashMap;

fn with_properties(name: &str) -> Option<Mesh> {
    let dir = common::models_dir()?;
    let options = LoadOptions {
        properties: true,
        ..LoadOptions::default()
    };
    Some(load(&dir.join(name), options).unwrap().0)
}

/// Edges between points (not vertices) used by one triangle only, and the
/// points that carry more than one vertex, of `mesh` at a LoD.
fn borders_and_seam_points(mesh: &Mesh) -> (usize, usize) {
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

#[test]
fn seams_stay_closed_and_never_multiply() {
    for name in ["spot.obj", "pirate.obj", "suzanne.obj", "beetle.obj"] {
        let Some(mesh) = with_properties(name) else {
            return;
        };
        let (borders0, seam_points0) = borders_and_seam_points(&mesh);
        // Suzanne's normals are one per position: no seam there.
        assert_eq!(seam_points0 > 0, name != "suzanne.obj", "{name}");
        let s = simplify(&mesh, &SimplifyOptions::default());
        s.collapses.validate().unwrap();
        let c = &s.collapses;
        for share in [0.5, 0.25, 0.1, 0.05, 0.01] {
            let lod = c.lod_for_ratio(share);
            let at = c.mesh_at(&mesh, lod);
            at.validate().unwrap();
            let (borders, seam_points) = borders_and_seam_points(&at);
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
