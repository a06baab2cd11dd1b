//! What the benches share: the input mesh.

use mts::mesh::generate::Generated;
use mts::mesh::io::{load, LoadOptions};
use mts::Mesh;
use std::path::Path;

/// The bunny from `../shared/models`, or a generated 70K-triangle
/// icosphere (said on stderr) when it is absent.
pub fn bunny_or_generated() -> (String, Mesh) {
    let bunny = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/models/bunny.ply");
    match load(&bunny, LoadOptions::default()) {
        Ok((mesh, _)) => ("bunny".into(), mesh),
        Err(e) => {
            eprintln!("the bunny is missing ({e}); using icosphere:70k");
            let g: Generated = "icosphere:70k".parse().expect("valid name");
            ("icosphere:70k".into(), g.build())
        }
    }
}
