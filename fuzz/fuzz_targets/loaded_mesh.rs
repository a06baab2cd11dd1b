//! What the loader fuzz targets check on every mesh a reader accepted: it
//! cleans to a valid mesh (or to a clean error), never a panic; a small one
//! is also stripified (the strips must draw exactly its triangles) and
//! simplified (the sequence and its middle LoD must be valid: with
//! properties, through the seam-keeping path).

pub fn check(raw: mts::mesh::RawMesh) {
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
        let s = mts::simplify(&mesh, &Default::default());
        s.collapses.validate().unwrap();
        s.collapses
            .mesh_at(&mesh, s.collapses.max_lod() / 2)
            .validate()
            .unwrap();
    }
}
