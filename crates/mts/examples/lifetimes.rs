//! Strips with their own lifetimes against bands and the single band
//! (issue 34, item 1; `mts::model::lifetimes`): per renewal, the strips
//! born, the records and bytes a model would hold (one layout for all), and
//! the indices per triangle sent at every share of the triangles from 100%
//! to 1%, against today's bands.
//!
//! `cargo run --release -p mts --example lifetimes -- MESH [SLACK...]
//! [MIN:MAX...]`, e.g. `… -- ../shared/models/bunny.ply 0.1 0.3 0:256
//! 64:1024`: bands at each slack, and strips at each slack with each
//! neighbourhood size (`MIN:MAX` triangles); defaults as in the example.

use mts::mesh::io::{load, LoadOptions};
use mts::model::lifetimes::{measure_renewal, Renewal, RenewalMeasure};
use mts::model::{build, BuildOptions, DEFAULT_BAND_SLACK};
use mts::{stripify, SimplifyOptions, StripifyOptions};
use std::path::Path;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let path = args
        .get(1)
        .ok_or("usage: lifetimes MESH [SLACK...] [MIN:MAX...]")?;
    let mut slacks: Vec<f64> = Vec::new();
    let mut units: Vec<(u32, u32)> = Vec::new();
    for a in args.iter().skip(2) {
        if let Some((lo, hi)) = a.split_once(':') {
            units.push((lo.parse()?, hi.parse()?));
        } else {
            slacks.push(a.parse()?);
        }
    }
    if slacks.is_empty() {
        slacks = vec![DEFAULT_BAND_SLACK, 0.3];
    }
    if units.is_empty() {
        units = vec![(0, 256), (64, 1024)];
    }
    let (mesh, _) = load(Path::new(path), LoadOptions::default())?;
    let strips = stripify(&mesh, &StripifyOptions::default());
    let collapses = mts::simplify(&mesh, &SimplifyOptions::default()).collapses;
    let shares: Vec<f64> = (1..=100).rev().map(|p| f64::from(p) / 100.0).collect();
    let lods: Vec<usize> = shares.iter().map(|&r| collapses.lod_for_ratio(r)).collect();
    let raw = 12 * mesh.vertex_count() + 12 * mesh.triangle_count();
    let options = |slack: f64| BuildOptions {
        band_slack: slack,
        ..BuildOptions::default()
    };
    let measure = |slack: f64, renewal: Renewal| {
        let t = std::time::Instant::now();
        let m = measure_renewal(&mesh, &strips, &collapses, &options(slack), renewal, &lods);
        (m, t.elapsed().as_secs_f64())
    };
    let (reference, _) = measure(DEFAULT_BAND_SLACK, Renewal::Bands);
    let model = build(&mesh, &strips, &collapses, &options(DEFAULT_BAND_SLACK));
    println!(
        "{path}: {} triangles, raw {raw} bytes; today's model (bands {DEFAULT_BAND_SLACK}) {} bytes ({:.2} x raw, {} records)",
        mesh.triangle_count(),
        model.stats().memory_bytes,
        model.stats().memory_bytes as f64 / raw as f64,
        model.stats().records,
    );
    println!();
    println!("| renewal | strips born | renewals | triangles renewed (indices each at birth) | records | bytes (x raw) | indices / triangle at 100 / 50 / 10 / 1% | mean / worst ratio to bands {DEFAULT_BAND_SLACK} | shares > 2% above | replay s |");
    println!("|---|---|---|---|---|---|---|---|---|---|");
    let row = |name: String, m: &RenewalMeasure, secs: f64| {
        let at = |r: f64| {
            let i = shares
                .iter()
                .position(|&s| (s - r).abs() < 1e-9)
                .expect("a share");
            m.indices[i] as f64 / m.triangles[i].max(1) as f64
        };
        let ratios: Vec<f64> = m
            .indices
            .iter()
            .zip(&reference.indices)
            .map(|(&a, &b)| a as f64 / b.max(1) as f64)
            .collect();
        let mean = ratios.iter().sum::<f64>() / ratios.len() as f64;
        let worst = ratios.iter().copied().fold(0.0, f64::max);
        let above = ratios.iter().filter(|&&r| r > 1.02).count();
        println!(
            "| {name} | {} | {} | {} ({:.3}) | {} | {} ({:.2}) | {:.3} / {:.3} / {:.3} / {:.3} | {mean:.3} / {worst:.3} | {above} | {secs:.1} |",
            m.strips,
            m.renewals,
            m.renewed_triangles,
            m.renewed_indices as f64 / m.renewed_triangles.max(1) as f64,
            m.records,
            m.memory_bytes,
            m.memory_bytes as f64 / raw as f64,
            at(1.0),
            at(0.5),
            at(0.1),
            at(0.01),
        );
    };
    let (single, single_s) = measure(f64::INFINITY, Renewal::Bands);
    row("single band".into(), &single, single_s);
    for &slack in &slacks {
        let (m, s) = measure(slack, Renewal::Bands);
        row(format!("bands {slack}"), &m, s);
    }
    for &slack in &slacks {
        for &(lo, hi) in &units {
            let (m, s) = measure(
                slack,
                Renewal::Strips {
                    min_triangles: lo,
                    max_triangles: hi,
                },
            );
            row(format!("strips {slack}, {lo}..{hi}"), &m, s);
        }
    }
    Ok(())
}
