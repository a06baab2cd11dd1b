//! The glTF reader (`.gltf` JSON and `.glb`) on arbitrary bytes: external
//! buffers resolve against a folder that does not exist, so only embedded
//! data is read (see `loaded_mesh.rs` for what an accepted mesh must
//! satisfy).
#![no_main]

#[path = "loaded_mesh.rs"]
mod loaded_mesh;

use libfuzzer_sys::fuzz_target;
use std::path::Path;

fuzz_target!(|data: &[u8]| {
    let path = if data.starts_with(b"glTF") {
        Path::new("/nonexistent/fuzz.glb")
    } else {
        Path::new("/nonexistent/fuzz.gltf")
    };
    if let Ok(raw) = mts::mesh::io::parse_gltf(data, path) {
        loaded_mesh::check(raw);
    }
});
