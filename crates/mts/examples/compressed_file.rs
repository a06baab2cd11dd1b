//! The version-5 file against version 3: bytes, writing time and loading
//! time (from bytes in memory, extractor ready; medians) per Zstandard
//! level, with each section's coded size.
//!
//! `cargo run --release -p mts --example compressed_file -- MODEL.mts [RUNS] [LEVELS] [OUT]`
//! (a model file of any version; LEVELS comma-separated, default 3,9,15,19;
//! with OUT, each level's file is written to `OUT.LEVEL.mts`).

use std::time::Instant;

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn load_ms(bytes: &[u8], path: &std::path::Path, runs: usize) -> Result<f64, mts::Error> {
    let mut times = Vec::new();
    for _ in 0..runs {
        let t = Instant::now();
        let m = mts::MtsModel::from_bytes(bytes, path)?;
        let ex = mts::Extractor::new(&m);
        std::hint::black_box(ex.buffer().len());
        times.push(t.elapsed().as_secs_f64() * 1e3);
    }
    Ok(median(times))
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let usage = "usage: compressed_file MODEL.mts [RUNS] [LEVELS] [OUT]";
    let path = std::path::Path::new(args.get(1).ok_or(usage)?);
    let runs: usize = args.get(2).map_or(Ok(11), |s| s.parse())?;
    let levels: Vec<i32> = args
        .get(3)
        .map_or("3,9,15,19", String::as_str)
        .split(',')
        .map(str::parse)
        .collect::<Result<_, _>>()?;
    let model = mts::MtsModel::load(path)?;
    let raw = model.raw_bytes() as f64;
    let v3 = model.to_bytes();
    println!(
        "{}: {} triangles, raw {} bytes",
        path.display(),
        model.triangle_count(0),
        model.raw_bytes()
    );
    println!(
        "version 3: {} bytes ({:.2} x raw), load {:.1} ms",
        v3.len(),
        v3.len() as f64 / raw,
        load_ms(&v3, path, runs)?
    );
    for level in levels {
        let mut write = Vec::new();
        let mut bytes = Vec::new();
        for _ in 0..3 {
            let t = Instant::now();
            bytes = model.to_compressed_bytes(level);
            write.push(t.elapsed().as_secs_f64() * 1e3);
        }
        if let Some(out) = args.get(4) {
            std::fs::write(format!("{out}.{level}.mts"), &bytes)?;
        }
        let back = mts::MtsModel::from_bytes(&bytes, path)?;
        assert!(back == model, "level {level}: the model read back differs");
        println!(
            "version 5, level {level}: {} bytes ({:.2} x raw, {:.3} of version 3), written in {:.0} ms, load {:.1} ms",
            bytes.len(),
            bytes.len() as f64 / raw,
            bytes.len() as f64 / v3.len() as f64,
            median(write),
            load_ms(&bytes, path, runs)?
        );
    }
    Ok(())
}
