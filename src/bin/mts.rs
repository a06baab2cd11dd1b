//! The `mts` command: multiresolution triangle strips from the command line.

use anyhow::{bail, Context, Result};
use clap::{Args, Parser, Subcommand};
use mts::mesh::generate::Generated;
use mts::mesh::io::{load, LoadOptions};
use mts::mesh::{CleanOptions, CleanReport, Mesh};
use mts::strip::stats::StripStats;
use mts::{peers, stripify, StripifyOptions};
use serde_json::json;
use std::path::PathBuf;
use std::time::Instant;

#[derive(Parser)]
#[command(
    name = "mts",
    version,
    about = "Continuous level of detail with multiresolution triangle strips"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Cut a mesh into triangle strips and compare with meshoptimizer's.
    Strips(StripsArgs),
}

/// Where a mesh comes from: a file or a built-in generator.
#[derive(Args)]
struct MeshSource {
    /// OBJ or PLY file.
    #[arg(conflicts_with = "generated")]
    mesh: Option<PathBuf>,
    /// Built-in mesh NAME:SIZE, SIZE in triangles (k/M suffixes):
    /// icosphere:100k, torus:1M, grid:20k. The default when no file is given.
    #[arg(long, value_name = "NAME:SIZE")]
    generated: Option<Generated>,
    /// Merge vertices with identical positions.
    #[arg(long)]
    weld: bool,
}

impl MeshSource {
    fn load(&self) -> Result<(String, Mesh, CleanReport)> {
        let clean = CleanOptions { weld: self.weld };
        if let Some(path) = &self.mesh {
            let (mesh, report) =
                load(path, LoadOptions { clean }).context("cannot load the mesh")?;
            Ok((path.display().to_string(), mesh, report))
        } else {
            let g = self.generated.unwrap_or(Generated::DEFAULT);
            let mesh = g.build();
            let raw = mts::mesh::RawMesh {
                positions: mesh.positions,
                triangles: mesh.triangles,
                degenerate_in_source: 0,
            };
            let (mesh, report) = mts::mesh::clean(raw, clean, &g.to_string())?;
            Ok((format!("generated {g}"), mesh, report))
        }
    }
}

#[derive(Args)]
struct StripsArgs {
    #[command(flatten)]
    source: MeshSource,
    /// Print JSON instead of a table.
    #[arg(long)]
    json: bool,
    /// Timed repetitions; the median is reported.
    #[arg(long, default_value_t = 5)]
    repeat: usize,
    /// Skip the global quadrilateral-patch pass.
    #[arg(long)]
    no_patches: bool,
    /// Smallest patch kept by the global pass, in quads.
    #[arg(long)]
    min_patch: Option<usize>,
    /// Only this swap penalty in the local pass (see StripifyOptions).
    #[arg(long)]
    swap_penalty: Option<f32>,
    /// Do not join strips whose ends are neighbours.
    #[arg(long)]
    no_join: bool,
}

fn median_ms<T>(repeat: usize, mut f: impl FnMut() -> T) -> (T, f64) {
    let mut times = Vec::with_capacity(repeat.max(1));
    let mut out = None;
    for _ in 0..repeat.max(1) {
        let t = Instant::now();
        let r = f();
        times.push(t.elapsed().as_secs_f64() * 1e3);
        out = Some(r);
    }
    times.sort_by(f64::total_cmp);
    (out.expect("at least one run"), times[times.len() / 2])
}

fn stats_json(s: &StripStats) -> serde_json::Value {
    json!({
        "triangles": s.triangles,
        "strips": s.strips,
        "swaps": s.swaps,
        "indices_restart": s.indices_restart,
        "indices_per_triangle": s.indices_per_triangle,
        "acmr": s.acmr,
        "ms": s.ms,
    })
}

fn strips(args: &StripsArgs) -> Result<()> {
    let (name, mesh, report) = args.source.load()?;
    let defaults = StripifyOptions::default();
    let options = StripifyOptions {
        patches: !args.no_patches,
        min_patch_quads: args.min_patch.unwrap_or(defaults.min_patch_quads),
        swap_penalties: match args.swap_penalty {
            Some(p) => [Some(p), None],
            None => defaults.swap_penalties,
        },
        join_ends: !args.no_join,
    };
    let (ours, ms) = median_ms(args.repeat, || stripify(&mesh, &options));
    let (theirs, their_ms) = median_ms(args.repeat, || peers::meshopt::stripify(&mesh));
    let mine = StripStats::new(&ours, ms);
    let peer = StripStats::new(&theirs, their_ms);
    // The invariant, checked on every run: a wrong strip is never reported.
    if mts::strip::sorted_canonical(&ours.triangles())
        != mts::strip::sorted_canonical(&mesh.triangles)
    {
        bail!("internal error: the strips do not draw exactly the mesh's triangles");
    }
    if args.json {
        let mut v = stats_json(&mine);
        v["meshopt"] = stats_json(&peer);
        v["mesh"] = json!(name);
        v["vertices"] = json!(mesh.vertex_count());
        println!("{}", serde_json::to_string_pretty(&v)?);
        return Ok(());
    }
    println!(
        "{name}: {} vertices, {} triangles ({} degenerate and {} unreferenced dropped, {} welded)",
        mesh.vertex_count(),
        mesh.triangle_count(),
        report.degenerate_dropped,
        report.unreferenced_dropped,
        report.welded
    );
    println!("{:<22}{:>14}{:>14}", "", "mts", "meshopt");
    let rows: [(&str, String, String); 7] = [
        (
            "triangles",
            mine.triangles.to_string(),
            peer.triangles.to_string(),
        ),
        ("strips", mine.strips.to_string(), peer.strips.to_string()),
        ("swaps", mine.swaps.to_string(), peer.swaps.to_string()),
        (
            "indices (restart)",
            mine.indices_restart.to_string(),
            peer.indices_restart.to_string(),
        ),
        (
            "indices / triangle",
            format!("{:.4}", mine.indices_per_triangle),
            format!("{:.4}", peer.indices_per_triangle),
        ),
        (
            "ACMR (cache 16)",
            format!("{:.3}", mine.acmr),
            format!("{:.3}", peer.acmr),
        ),
        (
            "ms (median)",
            format!("{:.2}", mine.ms),
            format!("{:.2}", peer.ms),
        ),
    ];
    for (label, a, b) in rows {
        println!("{label:<22}{a:>14}{b:>14}");
    }
    Ok(())
}

fn run(cli: &Cli) -> Result<()> {
    match &cli.command {
        Command::Strips(args) => strips(args),
    }
}

fn main() -> std::process::ExitCode {
    let cli = Cli::parse();
    match run(&cli) {
        Ok(()) => std::process::ExitCode::SUCCESS,
        Err(e) => {
            // One line: the context, then each cause not already said.
            let mut line = e.to_string();
            for cause in e.chain().skip(1) {
                let text = cause.to_string();
                if !line.contains(&text) {
                    line = format!("{line}: {text}");
                }
            }
            eprintln!("error: {line}");
            std::process::ExitCode::FAILURE
        }
    }
}
