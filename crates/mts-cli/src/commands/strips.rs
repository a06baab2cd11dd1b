//! `mts strips`: cut a mesh into triangle strips and compare them with
//! meshoptimizer's.

use crate::args::*;
use crate::stdout::outln;
use crate::timing::median_ms;
use anyhow::{bail, Result};
use clap::Args;
use mts::mesh::Mesh;
use mts::strip::stats::StripStats;
use mts::{peers, stripify, StripifyOptions};
use serde_json::json;

#[derive(Args)]
pub struct StripsArgs {
    #[command(flatten)]
    pub source: MeshSource,
    /// Print JSON instead of a table.
    #[arg(long)]
    pub json: bool,
    /// Timed repetitions (1 to 10,000); the median is reported.
    #[arg(long, default_value_t = 5, value_parser = count_in::<1, MAX_REPEAT>, allow_negative_numbers = true)]
    pub repeat: usize,
    /// Skip the global quadrilateral-patch pass.
    #[arg(long)]
    pub no_patches: bool,
    /// Smallest patch kept by the global pass, in quads.
    #[arg(long)]
    pub min_patch: Option<usize>,
    /// Only this swap penalty in the local pass (see StripifyOptions).
    #[arg(allow_negative_numbers = true, long, value_parser = non_negative::<f32>)]
    pub swap_penalty: Option<f32>,
    /// Do not join strips whose ends are neighbours.
    #[arg(long)]
    pub no_join: bool,
    /// Short strips side by side in vertex-cache order (see
    /// StripifyOptions::cache_aware; the options above are then ignored).
    #[arg(long)]
    pub cache_aware: bool,
}

/// `mts strips --json`'s figures of one stripifier: the bench's row.
/// The bench's strip row plus the other cache models' invocations per
/// triangle (kept out of the typed bench results).
fn stats_json(s: &StripStats) -> serde_json::Value {
    let mut v = json!(crate::bench::results::StripRow::from(s));
    v["acmr_batch96"] = json!(s.acmr_batch96);
    v["acmr_batch384"] = json!(s.acmr_batch384);
    v["acmr_lru32"] = json!(s.acmr_lru32);
    v["acmr_lru32_run"] = json!(s.acmr_lru32_run);
    v
}

/// `list_acmr` (FIFO 16) and `list_acmr_batch96` of the
/// meshoptimizer-ordered triangle list of `mesh`: the list strips compete
/// with.
fn list_acmr_json(mesh: &Mesh) -> (serde_json::Value, serde_json::Value) {
    let list = peers::meshopt::optimize_vertex_cache(&mesh.triangles, mesh.vertex_count());
    let (fifo, batch96) = mts::strip::vertex_work::list_fifo16_batch96(&list, mesh.vertex_count());
    (json!(fifo), json!(batch96))
}

pub fn run(args: &StripsArgs) -> Result<()> {
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
        cache_aware: args.cache_aware,
    };
    let (ours, ms) = median_ms(args.repeat, || stripify(&mesh, &options));
    let skipped = peers::meshopt::refusal(&mesh);
    let peer = skipped.is_none().then(|| {
        let (theirs, their_ms) = median_ms(args.repeat, || peers::meshopt::stripify(&mesh));
        StripStats::new(&theirs, their_ms)
    });
    let mine = StripStats::new(&ours, ms);
    // The invariant, checked on every run: a wrong strip is never reported.
    if mts::strip::sorted_canonical(&ours.triangles())
        != mts::strip::sorted_canonical(&mesh.triangles)
    {
        bail!("internal error: the strips do not draw exactly the mesh's triangles");
    }
    if args.json {
        let mut v = stats_json(&mine);
        v["meshopt"] = peer.as_ref().map_or(serde_json::Value::Null, stats_json);
        if let Some(why) = &skipped {
            v["meshopt_skipped"] = json!(why);
        }
        let (list_acmr, list_batch96) = match &skipped {
            None => list_acmr_json(&mesh),
            Some(_) => (serde_json::Value::Null, serde_json::Value::Null),
        };
        v["list_acmr"] = list_acmr;
        v["list_acmr_batch96"] = list_batch96;
        v["mesh"] = json!(name);
        v["vertices"] = json!(mesh.vertex_count());
        outln!("{}", serde_json::to_string_pretty(&v)?)?;
        return Ok(());
    }
    outln!(
        "{name}: {} vertices, {} triangles ({} degenerate and {} unreferenced dropped, {} welded)",
        mesh.vertex_count(),
        mesh.triangle_count(),
        report.degenerate_dropped,
        report.unreferenced_dropped,
        report.welded
    )?;
    if let Some(why) = &skipped {
        outln!("{why}")?;
    }
    outln!("{:<22}{:>14}{:>14}", "", "mts", "meshopt")?;
    let peer = peer.unwrap_or_default();
    // Each row: its label and the figure of a side.
    type Figure = fn(&StripStats) -> String;
    let rows: [(&str, Figure); 11] = [
        ("triangles", |s| s.triangles.to_string()),
        ("strips", |s| s.strips.to_string()),
        ("swaps", |s| s.swaps.to_string()),
        ("indices (restart)", |s| s.indices_restart.to_string()),
        ("indices / triangle", |s| {
            format!("{:.4}", s.indices_per_triangle)
        }),
        ("ACMR (FIFO 16)", |s| format!("{:.3}", s.acmr)),
        ("ACMR (batch 96)", |s| format!("{:.3}", s.acmr_batch96)),
        ("ACMR (batch 384)", |s| format!("{:.3}", s.acmr_batch384)),
        ("ACMR (LRU 32)", |s| format!("{:.3}", s.acmr_lru32)),
        ("ACMR (LRU 32 per run)", |s| {
            format!("{:.3}", s.acmr_lru32_run)
        }),
        ("ms (median)", |s| format!("{:.2}", s.ms)),
    ];
    for (label, figure) in rows {
        outln!("{label:<22}{:>14}{:>14}", figure(&mine), figure(&peer))?;
    }
    if skipped.is_none() {
        // The list the strips are weighed against: meshoptimizer's
        // cache-ordered triangles.
        let (fifo, batch) = list_acmr_json(&mesh);
        outln!(
            "meshoptimizer-ordered list: ACMR {:.3} (FIFO 16), {:.3} (batch 96)",
            fifo.as_f64().unwrap_or(f64::NAN),
            batch.as_f64().unwrap_or(f64::NAN)
        )?;
    }
    Ok(())
}
