//! The OBJ reader on arbitrary bytes: an error or a raw mesh that cleans
//! to a valid mesh (or to a clean error), never a panic; small accepted
//! meshes are also stripified and the strips must draw exactly the mesh's
//! triangles.
#![no_main]

use libfuzzer_sys::fuzz_target;
use std::path::Path;

fuzz_target!(|data: &[u8]| {
    if let Ok(raw) = mts::mesh::io::parse_obj(data, Path::new("fuzz.obj")) {
        check(raw);
    }
});

fn check(raw: mts::mesh::RawMesh) {
    let Ok((mesh, _report)) = mts::mesh::clean(raw, Default::default(), "fuzz") else {
        return;
    };
    mesh.validate().unwrap();
    if mesh.triangle_count() <= 2000 {
        let strips = mts::stripify(&mesh, &Default::default());
        assert_eq!(
            mts::strip::sorted_canonical(&strips.triangles()),
            mts::strip::sorted_canonical(&mesh.triangles),
            "the strips do not draw exactly the mesh's triangles"
        );
    }
}
