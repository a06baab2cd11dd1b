use std::time::Instant;
fn main() {
    let path = std::env::args().nth(1).unwrap();
    let (mesh, _) = mts::mesh::io::load(std::path::Path::new(&path), Default::default()).unwrap();
    for _ in 0..3 {
        let t = Instant::now();
        let adj = mts::mesh::TriangleAdjacency::new(&mesh);
        let a = t.elapsed();
        let s = mts::strip::stripify::stripify_with_adjacency(&mesh, &adj, &mts::StripifyOptions { ..Default::default() });
        println!("adjacency {:?} rest {:?} {}", a, t.elapsed() - a, s.run_count());
    }
}
