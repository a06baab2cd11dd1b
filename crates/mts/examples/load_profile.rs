//! Times loading an `.mts` file from bytes in memory (parse, validate,
//! extractor ready), repeatedly, for profiling.
//!
//! `cargo run --release -p mts --example load_profile -- MODEL.mts [RUNS]`.

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let path = std::path::Path::new(args.get(1).ok_or("usage: load_profile MODEL.mts [RUNS]")?);
    let runs: usize = args.get(2).map_or(Ok(10), |s| s.parse())?;
    let bytes = std::fs::read(path)?;
    let mut times = Vec::new();
    for _ in 0..runs {
        let t = std::time::Instant::now();
        let m = mts::MtsModel::from_bytes(&bytes, path)?;
        let ex = mts::Extractor::new(&m);
        std::hint::black_box(ex.buffer().len());
        times.push(t.elapsed().as_secs_f64() * 1e3);
    }
    times.sort_by(f64::total_cmp);
    println!(
        "median {:.1} ms over {runs} runs (min {:.1})",
        times[runs / 2],
        times[0]
    );
    Ok(())
}
