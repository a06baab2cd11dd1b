//! Reads glTF files from bytes in memory, repeatedly, and prints for each
//! its triangles, vertices and the median read time (parse, decode, check;
//! the `RawMesh` ready) as one JSON line: the decode column of
//! `scripts/gltf-table.py`.
//!
//! `cargo run --release -p mts --features gltf --example gltf_read -- [--runs N] FILE...`.

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args: Vec<String> = std::env::args().skip(1).collect();
    let mut runs = 11usize;
    if args.first().map(String::as_str) == Some("--runs") {
        runs = args.get(1).ok_or("--runs needs a number")?.parse()?;
        args.drain(..2);
    }
    if args.is_empty() || runs == 0 {
        return Err("usage: gltf_read [--runs N] FILE...".into());
    }
    for file in &args {
        let path = std::path::Path::new(file);
        let bytes = std::fs::read(path)?;
        let mut times = Vec::with_capacity(runs);
        let mut shape = (0, 0);
        for _ in 0..runs {
            let t = std::time::Instant::now();
            let raw = mts::mesh::io::parse_gltf(&bytes, path)?;
            times.push(t.elapsed().as_secs_f64() * 1e3);
            shape = (raw.triangles.len(), raw.positions.len());
        }
        times.sort_by(f64::total_cmp);
        println!(
            "{{\"file\": {:?}, \"bytes\": {}, \"triangles\": {}, \"vertices\": {}, \"read_ms\": {:.3}}}",
            file,
            bytes.len(),
            shape.0,
            shape.1,
            times[runs / 2]
        );
    }
    Ok(())
}
