//! `mts lods`: a chain of levels in one glTF file the way engines load
//! one (`MSFT_lod` on the finest level's node, screen-coverage hints from
//! the recorded errors; each level an indexed list in vertex-cache order
//! holding only its own vertices). See [`mts::mesh::io::save_lod_chain`].

use crate::args::{pixel_error, GltfOut, MeshSource};
use crate::stdout::{outln, warnln};
use anyhow::{bail, Result};
use clap::Args;
use mts::mesh::io::{chain_from_collapses, save_lod_chain, screen_coverages, Coverage};
use serde_json::json;
use std::path::PathBuf;

#[derive(Args)]
pub struct LodsArgs {
    #[command(flatten)]
    pub source: MeshSource,
    /// Shares of the full triangle count, one level each (finest first
    /// once sorted; shares that give the same LoD make one level).
    #[arg(long, value_delimiter = ',', default_value = "1,0.5,0.25,0.1,0.02",
          allow_negative_numbers = true, value_parser = share)]
    pub ratios: Vec<f64>,
    /// The glTF file to write (.glb or .gltf, by extension).
    #[arg(short, long)]
    pub output: PathBuf,
    #[command(flatten)]
    pub gltf: GltfOut,
    /// The screen-coverage hints let a level show at most this error, in
    /// pixels ...
    #[arg(long, default_value_t = 1.0, allow_hyphen_values = true, value_parser = pixel_error)]
    pub pixel_error: f32,
    /// ... on a screen this many pixels high.
    #[arg(long, default_value_t = 1080, allow_negative_numbers = true,
          value_parser = crate::args::count_in::<1, 65536>)]
    pub screen_height: usize,
    /// Print JSON instead of a table.
    #[arg(long)]
    pub json: bool,
}

/// A share of the triangles: a finite number in `0..=1`.
fn share(s: &str) -> std::result::Result<f64, String> {
    let v: f64 = s
        .trim()
        .parse()
        .map_err(|_| format!("`{s}` is not a share of the triangles"))?;
    if (0.0..=1.0).contains(&v) {
        Ok(v)
    } else {
        Err(format!("{v} is outside 0..=1"))
    }
}

pub fn run(args: &LodsArgs) -> Result<()> {
    args.source.check_output(&args.output)?;
    let (name, mesh, _) = args.source.load()?;
    let collapses = mts::simplify(&mesh, &Default::default()).collapses;
    let mut ratios = args.ratios.clone();
    ratios.sort_by(|a, b| b.total_cmp(a));
    let mut lods: Vec<(f64, usize)> = Vec::new();
    for r in ratios {
        let lod = collapses.lod_for_ratio(r);
        match lods.last() {
            Some(&(_, last)) if last == lod => {}
            _ => lods.push((r, lod)),
        }
    }
    let dropped = args.ratios.len() - lods.len();
    if dropped > 0 {
        warnln!(
            "{name}: {dropped} of the shares give a LoD another share gives: {} levels",
            lods.len()
        );
    }
    let lod_list: Vec<usize> = lods.iter().map(|&(_, l)| l).collect();
    let levels = chain_from_collapses(&mesh, &collapses, &lod_list)?;
    if let Some(empty) = levels.iter().position(|l| l.mesh.triangle_count() == 0) {
        bail!(
            "{name}: the share {} leaves no triangle: give shares that keep some",
            lods[empty].0
        );
    }
    let coverage = Coverage {
        pixel_threshold: args.pixel_error,
        screen_height: args.screen_height as f32,
    };
    let lost = mts::mesh::io::dropped_by(&mesh, &args.output);
    if !lost.is_empty() {
        warnln!(
            "{}: glTF cannot hold the {} of {name}: dropped",
            args.output.display(),
            lost.join(", ")
        );
    }
    save_lod_chain(&levels, &coverage, &args.output, args.gltf.encoding())?;
    let bytes = std::fs::metadata(&args.output).map_or(0, |m| m.len());
    let errors: Vec<f32> = levels.iter().map(|l| l.error).collect();
    let coverages = screen_coverages(&errors, &coverage);
    let rows: Vec<_> = lods
        .iter()
        .zip(&levels)
        .zip(&coverages)
        .map(|((&(ratio, lod), level), &c)| {
            json!({
                "ratio": ratio,
                "lod": lod,
                "triangles": level.mesh.triangle_count(),
                "vertices": level.mesh.vertex_count(),
                "error": level.error,
                "screen_coverage": c,
            })
        })
        .collect();
    if args.json {
        outln!(
            "{}",
            json!({
                "input": name,
                "output": args.output.display().to_string(),
                "bytes": bytes,
                "pixel_error": args.pixel_error,
                "screen_height": args.screen_height,
                "levels": rows,
            })
        )?;
        return Ok(());
    }
    outln!(
        "{name}: {} levels -> {} ({bytes} bytes; coverage for {} px on a {}-pixel-high screen)",
        levels.len(),
        args.output.display(),
        args.pixel_error,
        args.screen_height
    )?;
    outln!(
        "  {:>6} {:>7} {:>9} {:>9} {:>10} {:>9}",
        "share",
        "LoD",
        "triangles",
        "vertices",
        "error",
        "coverage"
    )?;
    for r in &rows {
        outln!(
            "  {:>5.1}% {:>7} {:>9} {:>9} {:>10.6} {:>9.4}",
            r["ratio"].as_f64().unwrap_or(0.0) * 100.0,
            r["lod"].as_u64().unwrap_or(0),
            r["triangles"].as_u64().unwrap_or(0),
            r["vertices"].as_u64().unwrap_or(0),
            r["error"].as_f64().unwrap_or(0.0),
            r["screen_coverage"].as_f64().unwrap_or(0.0)
        )?;
    }
    Ok(())
}
