//! Compressed glTF bytes of one mesh for four triangle orders given to the
//! writer: mts's vertex-cache order (Forsyth's), the order of mts's
//! strips, and meshoptimizer's strip-like and plain cache orders. (The
//! writer now puts every level in meshoptimizer's strip-like order before
//! coding, so the four differ only where that order depends on its input;
//! before it did, they measured the orders themselves:
//! `docs/experiments/gltf-compression.md`.)
//!
//! `cargo run --release -p mts --features gltf --example gltf_order -- MESH`.
fn main() -> Result<(), Box<dyn std::error::Error>> {
    let path = std::env::args().nth(1).ok_or("usage: gltf_order MESH")?;
    let (mesh, _) = mts::mesh::io::load(std::path::Path::new(&path), Default::default())?;
    let dir = std::env::temp_dir();
    let cache = mts::mesh::io::order_for_cache(&mesh);
    let strips = mts::stripify(&mesh, &Default::default());
    let by_strips = mts::Mesh::level(&mesh.positions, &strips.triangles(), &mesh.properties);
    let flat = mesh.index_list();
    let opt = meshopt::optimize_vertex_cache_strip(&flat, mesh.vertex_count());
    let tri: Vec<[u32; 3]> = opt.chunks(3).map(|t| [t[0], t[1], t[2]]).collect();
    let by_meshopt = mts::Mesh::level(&mesh.positions, &tri, &mesh.properties);
    let opt = meshopt::optimize_vertex_cache(&flat, mesh.vertex_count());
    let tri: Vec<[u32; 3]> = opt.chunks(3).map(|t| [t[0], t[1], t[2]]).collect();
    let by_meshopt_cache = mts::Mesh::level(&mesh.positions, &tri, &mesh.properties);
    for (name, m) in [
        ("cache", &cache),
        ("strips", &by_strips),
        ("meshopt_strip", &by_meshopt),
        ("meshopt_cache", &by_meshopt_cache),
    ] {
        let out = dir.join(format!("order-{name}.glb"));
        mts::mesh::io::save_gltf_as(m, &out, mts::mesh::io::Encoding::Compressed)?;
        println!("{name}: {} bytes", std::fs::metadata(&out)?.len());
    }
    Ok(())
}
