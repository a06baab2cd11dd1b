//! Where a coherent request sequence spends its time: requests that cross
//! into another band (every strip of the new band walked whole) against
//! requests inside one band (only changed strips, from their first changed
//! segment), with the indices each kind walks. Issue 34's first
//! measurement (`docs/experiments/strip-lifetimes.md`, step 0a): strips
//! with lifetimes remove the crossings' cost, not the in-band one.
//!
//! `cargo run --release -p mts --example coherence_split -- MESH [REQUESTS] [PASSES]`
//! prints, per sequence (the report's Table 2: linear, exponential,
//! random), the requests of each kind, their total and median
//! microseconds, and the indices they walked; then the sum over bands of
//! each band's region (the indices walked at its first LoD), which a
//! linear sweep over every band pays once.

use mts::mesh::io::{load, LoadOptions};
use mts::model::{build, requests, BuildOptions};
use mts::{stripify, Extractor, SimplifyOptions, StripifyOptions};
use std::path::Path;
use std::time::Instant;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let path = args
        .get(1)
        .ok_or("usage: coherence_split MESH [REQUESTS] [PASSES]")?;
    let n: usize = args.get(2).map_or(Ok(1000), |s| s.parse())?;
    let passes: usize = args.get(3).map_or(Ok(5), |s| s.parse())?;
    let (mesh, _) = load(Path::new(path), LoadOptions::default())?;
    let strips = stripify(&mesh, &StripifyOptions::default());
    let collapses = mts::simplify(&mesh, &SimplifyOptions::default()).collapses;
    let model = build(&mesh, &strips, &collapses, &BuildOptions::default());
    println!(
        "{path}: {} triangles, {} LoDs, {} bands, {} strips",
        mesh.triangle_count(),
        model.max_lod(),
        model.band_count(),
        model.strip_count()
    );
    for (name, sequence) in requests::table2(model.triangle_counts(), n) {
        // Per request: (crossed a band, microseconds, indices walked),
        // the median over the passes of each request's time.
        let mut times = vec![Vec::with_capacity(passes); sequence.len()];
        let mut kinds = vec![(false, 0usize); sequence.len()];
        for _ in 0..passes {
            let mut ex = Extractor::new(&model);
            ex.set_lod(0);
            for (i, &lod) in sequence.iter().enumerate() {
                let before = ex.lod().map(|l| model.band_of(l));
                let t = Instant::now();
                let u = ex.set_lod(lod);
                times[i].push(t.elapsed().as_secs_f64() * 1e6);
                kinds[i] = (before != Some(model.band_of(lod)), u.indices_walked);
            }
        }
        let per_request: Vec<f64> = times
            .iter_mut()
            .map(|t| {
                t.sort_by(f64::total_cmp);
                t[t.len() / 2]
            })
            .collect();
        for crossing in [true, false] {
            let mut us: Vec<f64> = Vec::new();
            let mut walked = 0usize;
            for (k, &t) in kinds.iter().zip(&per_request) {
                if k.0 == crossing {
                    us.push(t);
                    walked += k.1;
                }
            }
            let total: f64 = us.iter().sum();
            us.sort_by(f64::total_cmp);
            println!(
                "{name:>11} {:>9}: {:>5} requests, {:>9.0} us in all ({:>6.1} us a request of the {n}), median {:>7.1} us, {:>9} indices walked",
                if crossing { "crossing" } else { "in band" },
                us.len(),
                total,
                total / n as f64,
                us.get(us.len() / 2).copied().unwrap_or(0.0),
                walked
            );
        }
    }
    let mut ex = Extractor::new(&model);
    let regions: usize = (0..model.band_count())
        .map(|b| {
            ex.set_lod_from_scratch(model.band_first_lod(b));
            ex.indices_sent()
        })
        .sum();
    println!("sum of the bands' regions at their first LoDs: {regions} indices");
    Ok(())
}
