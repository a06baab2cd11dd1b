//! The OBJ reader on arbitrary bytes (see `loaded_mesh.rs` for what an
//! accepted mesh must satisfy).
#![no_main]

#[path = "loaded_mesh.rs"]
mod loaded_mesh;

use libfuzzer_sys::fuzz_target;
use std::path::Path;

fuzz_target!(|data: &[u8]| {
    if let Ok(raw) = mts::mesh::io::parse_obj(data, Path::new("fuzz.obj")) {
        loaded_mesh::check(raw);
    }
});
