//! The band slack's trade-off: the model's memory against the indices its
//! strips send, over every share of the triangles from 100% to 1% in steps
//! of 1% (not only the report's six shares, where a band's phase can flatter
//! or hurt a setting), each against the default slack's.
//!
//! Run with `cargo run --release -p mts --example band_tradeoff -- MESH
//! [SLACK...]` (`inf` for the paper's single band), e.g. `… --
//! ../shared/models/bunny.ply 0.1 0.15 0.2 0.3 inf`. One line per slack:
//! bands, memory (bytes and × the raw mesh), indices per triangle at 50, 10
//! and 1%, and over the 100 shares the mean and the worst ratio of its
//! indices to the default's, and how many shares are more than 2% above.

use mts::mesh::io::{load, LoadOptions};
use mts::model::{build, BuildOptions, DEFAULT_BAND_SLACK};
use mts::{stripify, Extractor, SimplifyOptions, StripifyOptions};
use std::path::Path;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let path = args.get(1).ok_or("usage: band_tradeoff MESH [SLACK...]")?;
    let mut slacks: Vec<f64> = args[2..]
        .iter()
        .map(|s| s.parse::<f64>())
        .collect::<Result<_, _>>()?;
    if slacks.is_empty() {
        slacks = vec![0.05, 0.1, 0.15, 0.2, 0.3, f64::INFINITY];
    }
    let (mesh, _) = load(Path::new(path), LoadOptions::default())?;
    let strips = stripify(&mesh, &StripifyOptions::default());
    let collapses = mts::simplify(&mesh, &SimplifyOptions::default()).collapses;
    let shares: Vec<f64> = (1..=100).rev().map(|p| f64::from(p) / 100.0).collect();
    let indices = |slack: f64| {
        let options = BuildOptions {
            band_slack: slack,
            ..BuildOptions::default()
        };
        let model = build(&mesh, &strips, &collapses, &options);
        let mut ex = Extractor::new(&model);
        let sent: Vec<f64> = shares
            .iter()
            .map(|&r| {
                ex.set_ratio(r);
                ex.indices_sent() as f64
            })
            .collect();
        (model, sent)
    };
    let (_, reference) = indices(DEFAULT_BAND_SLACK);
    println!("| slack | bands | memory bytes | × raw | indices / triangle at 50 / 10 / 1% | mean ratio to {DEFAULT_BAND_SLACK} | worst | shares > 2% above |");
    println!("|---|---|---|---|---|---|---|---|");
    for slack in slacks {
        let (model, sent) = indices(slack);
        let at = |r: f64| {
            let i = shares
                .iter()
                .position(|&s| (s - r).abs() < 1e-9)
                .expect("a share");
            sent[i] / model.triangle_count(model.lod_for_ratio(r)).max(1) as f64
        };
        let ratios: Vec<f64> = sent.iter().zip(&reference).map(|(a, b)| a / b).collect();
        let mean = ratios.iter().sum::<f64>() / ratios.len() as f64;
        let worst = ratios.iter().copied().fold(0.0, f64::max);
        let above = ratios.iter().filter(|&&x| x > 1.02).count();
        let memory = model.stats().memory_bytes;
        println!(
            "| {slack} | {} | {memory} | {:.2} | {:.3} / {:.3} / {:.3} | {mean:.3} | {worst:.3} | {above} |",
            model.band_count(),
            memory as f64 / model.raw_bytes() as f64,
            at(0.5),
            at(0.1),
            at(0.01),
        );
    }
    Ok(())
}
