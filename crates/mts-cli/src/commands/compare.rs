//! `mts compare`: every method side by side on one mesh.

use crate::args::*;
use crate::bench::methods::measure_methods;
use crate::bench::results::MethodRow;
use crate::commands::build::build_with_bar;
use crate::commands::encode::{raw_bytes_u16, with_properties};
use crate::stdout::outln;
use anyhow::Result;
use clap::Args;
use serde_json::json;
use std::time::Instant;

#[derive(Args)]
pub struct CompareArgs {
    #[command(flatten)]
    pub source: MeshSource,
    /// Requests in each sequence (linear, exponential, random; 1 to 10
    /// million).
    #[arg(long, default_value_t = 100, value_parser = count_in::<1, MAX_REQUESTS>, allow_negative_numbers = true)]
    pub requests: usize,
    /// Print JSON instead of a table.
    #[arg(long)]
    pub json: bool,
}

pub fn run(args: &CompareArgs) -> Result<()> {
    let (name, mesh, _) = args.source.load()?;
    let t = Instant::now();
    let (model, _, _) = build_with_bar(&mesh, &Default::default())?;
    let mts_ms = t.elapsed().as_secs_f64() * 1e3;
    let raw = raw_bytes_u16(&mesh);
    let coded = model.to_streamed_bytes(
        mts::model::compress::DEFAULT_LEVEL,
        &mts::model::DEFAULT_PREFIX_SHARES,
    );
    let rows = measure_methods(&model, &mesh, mts_ms, args.requests, &coded)?;
    let mesh_info = json!({
        "input": name,
        "vertices": mesh.vertex_count(),
        "triangles": mesh.triangle_count(),
        "raw_bytes_u16": raw,
        "requests": args.requests,
    });
    if args.json {
        outln!("{}", json!({"mesh": mesh_info, "methods": rows}))?;
        return Ok(());
    }
    outln!(
        "{name}: {} vertices, {} triangles, raw {raw} bytes (12 per vertex{} + 6 per triangle); {} requests per sequence",
        mesh.vertex_count(),
        mesh.triangle_count(),
        with_properties(&mesh),
        args.requests
    )?;
    outln!(
        "{:<12}{:>10}{:>12}{:>12}{:>8}{:>10}{:>10}{:>10}{:>10}",
        "method",
        "build ms",
        "memory B",
        "file B",
        "/raw",
        "load ms",
        "us lin",
        "us exp",
        "us rand"
    )?;
    for r in &rows {
        let r = match r {
            MethodRow::Measured(r) => r,
            MethodRow::Skipped { method, skipped } => {
                outln!("{method:<12}{skipped}")?;
                continue;
            }
        };
        let us = |seq: &str| r.us_per_change.get(seq).copied().unwrap_or(0.0);
        outln!(
            "{:<12}{:>10.1}{:>12}{:>12}{:>8.3}{:>10}{:>10.1}{:>10.1}{:>10.1}",
            r.method,
            r.build_ms,
            r.memory_bytes,
            r.file_bytes,
            r.file_ratio_to_raw_u16,
            r.load_ms.map_or("-".to_string(), |ms| format!("{ms:.2}")),
            us("linear"),
            us("exponential"),
            us("random"),
        )?;
        if let Some(scratch) = &r.us_per_change_scratch {
            let s = |seq: &str| scratch.get(seq).copied().unwrap_or(0.0);
            outln!(
                "{:<12}{:>62}{:>10.1}{:>10.1}{:>10.1}  (coherent {:.2}x / {:.2}x / {:.2}x faster)",
                "  scratch",
                "",
                s("linear"),
                s("exponential"),
                s("random"),
                s("linear") / us("linear"),
                s("exponential") / us("exponential"),
                s("random") / us("random"),
            )?;
        }
    }
    Ok(())
}
