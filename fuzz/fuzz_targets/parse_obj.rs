//! The OBJ reader on arbitrary bytes, positions only and with properties
//! (split vertices, `vt`/`vn`; see `loaded_mesh.rs` for what an accepted
//! mesh must satisfy).
#![no_main]

#[path = "loaded_mesh.rs"]
mod loaded_mesh;

use libfuzzer_sys::fuzz_target;
use std::path::Path;

fuzz_target!(|data: &[u8]| {
    for properties in [false, true] {
        let path = Path::new("/nonexistent/fuzz.obj");
        if let Ok(raw) = mts::mesh::io::parse_obj_with(data, path, properties) {
            loaded_mesh::check(raw);
        }
    }
});
