//! `mts bench`: the report (measured by [`crate::bench`]) and its
//! subcommands `render`, `summary` and `check`.

use crate::stdout::{out, outln};
use anyhow::{bail, Context, Result};
use clap::{Args, Subcommand};
use std::path::PathBuf;
use std::time::Instant;

#[derive(Subcommand)]
pub enum BenchCommand {
    /// Frames and triangles per second: MTS strips against
    /// meshoptimizer-ordered triangle lists at 100%, 50% and 10%.
    Render(crate::bench::render::BenchRenderArgs),
    /// Detail per region along a fixed flight: the strip hierarchy against
    /// meshoptimizer's cluster LoD, the cluster tree and the per-object
    /// model (triangles, indices, update time, cracks, popping, memory,
    /// image error).
    ViewDependent(crate::bench::view_dependent::BenchViewDependentArgs),
    /// The README's "Latest bench report" section, made from a report's
    /// results.json.
    Summary(SummaryArgs),
    /// Load a results.json through its typed layout and check the
    /// invariants CI holds a run to; exits non-zero naming each broken one.
    Check(CheckArgs),
}

#[derive(Args)]
pub struct CheckArgs {
    /// The report's results.json.
    pub results: PathBuf,
    /// The layout of `mts bench --quick` (one model, no scale section).
    #[arg(long)]
    pub quick: bool,
}

fn bench_check(args: &CheckArgs) -> Result<()> {
    let r = crate::bench::results::Results::load(&args.results)?;
    let bad = crate::bench::check::check(&r, args.quick);
    if !bad.is_empty() {
        bail!(
            "{}: {} broken:\n  {}",
            args.results.display(),
            bad.len(),
            bad.join("\n  ")
        );
    }
    let flights = r.view_dependent.len();
    match &r.machine.adapter {
        Some(a) => outln!(
            "{}: complete ({} models, {flights} view-dependent flights; Figure 6, the scene and the flights' images on {a})",
            args.results.display(),
            r.models.len()
        ),
        None => outln!(
            "{}: complete ({} models, {flights} view-dependent flights; no adapter: {})",
            args.results.display(),
            r.models.len(),
            r.machine.adapter_note.as_deref().unwrap_or("?")
        ),
    }
}

#[derive(Args)]
pub struct SummaryArgs {
    /// The report's results.json.
    pub results: PathBuf,
    /// Rewrite this README's generated section in place.
    #[arg(long)]
    pub readme: Option<PathBuf>,
    /// With --readme: change nothing, fail when the section differs from
    /// what the results give.
    #[arg(long, requires = "readme")]
    pub check: bool,
}

fn bench_summary(args: &SummaryArgs) -> Result<()> {
    let path = &args.results;
    let results = crate::bench::results::Results::load(path)?;
    let Some(readme) = &args.readme else {
        let dir = path
            .parent()
            .map_or_else(String::new, |p| p.display().to_string());
        out!("{}", crate::bench::summary::summary(&results, &dir))?;
        return Ok(());
    };
    // Links are relative to the README.
    let base = readme.parent().unwrap_or(std::path::Path::new(""));
    let dir = path
        .parent()
        .map(|p| p.strip_prefix(base).unwrap_or(p).display().to_string())
        .unwrap_or_default();
    let section = crate::bench::summary::summary(&results, &dir);
    let old = std::fs::read_to_string(readme)
        .with_context(|| format!("cannot read {}", readme.display()))?;
    let Some(new) = crate::bench::summary::splice(&old, &section) else {
        bail!(
            "{} has no generated section: put the two lines\n{}\n{}\nwhere it goes",
            readme.display(),
            crate::bench::summary::BEGIN,
            crate::bench::summary::END
        );
    };
    if args.check {
        if new != old {
            bail!(
                "{}'s bench section differs from {}: run `mts bench summary {} --readme {}`",
                readme.display(),
                path.display(),
                path.display(),
                readme.display()
            );
        }
        outln!("{} matches {}", readme.display(), path.display())?;
        return Ok(());
    }
    mts::output::write_file(readme, new.as_bytes())?;
    outln!("rewrote the bench section of {}", readme.display())?;
    Ok(())
}

#[derive(Args)]
#[command(args_conflicts_with_subcommands = true)]
pub struct BenchArgs {
    #[command(subcommand)]
    pub command: Option<BenchCommand>,
    /// Meshes, or folders whose .obj and .ply files are all measured.
    /// Default: ../shared/models when it exists, else the built-in mesh.
    #[arg(long, num_args = 1..)]
    pub models: Vec<PathBuf>,
    /// Where report.md and results.json go.
    #[arg(long, default_value = "bench-report")]
    pub out: PathBuf,
    /// The built-in mesh only, fewer requests, no scale section, one small
    /// view-dependent flight (a smoke test of under two minutes).
    #[arg(long)]
    pub quick: bool,
    /// Skip Figure 6 (frames per second through the headless renderer).
    #[arg(long)]
    pub no_render: bool,
}

pub fn run(args: &BenchArgs) -> Result<()> {
    match &args.command {
        Some(BenchCommand::Render(args)) => return crate::bench::render::bench_render(args),
        Some(BenchCommand::ViewDependent(args)) => {
            return crate::bench::view_dependent::bench_view_dependent(args)
        }
        Some(BenchCommand::Summary(args)) => return bench_summary(args),
        Some(BenchCommand::Check(args)) => return bench_check(args),
        None => {}
    }
    let mut models = Vec::new();
    let mut sources = args.models.clone();
    if sources.is_empty() && !args.quick {
        let shared = PathBuf::from("../shared/models");
        if shared.is_dir() {
            sources.push(shared);
        }
    }
    for p in sources {
        if p.is_dir() {
            let mut found: Vec<PathBuf> = std::fs::read_dir(&p)
                .with_context(|| format!("cannot read {}", p.display()))?
                .flatten()
                .map(|e| e.path())
                .filter(|f| f.extension().is_some_and(|x| x == "obj" || x == "ply"))
                .collect();
            found.sort();
            models.extend(found);
        } else {
            models.push(p);
        }
    }
    let bar = indicatif::ProgressBar::new_spinner();
    bar.enable_steady_tick(std::time::Duration::from_millis(200));
    let t = Instant::now();
    let options = crate::bench::measure::BenchOptions {
        models,
        quick: args.quick,
        command: std::env::args().collect::<Vec<_>>().join(" "),
        render: !args.no_render,
    };
    let results = crate::bench::measure::run(&options, &|what| {
        bar.set_message(format!("measuring {what}"))
    })?;
    bar.finish_and_clear();
    crate::bench::report::write(&args.out, &results)?;
    outln!(
        "wrote {} and {} in {:.0} s",
        args.out.join("report.md").display(),
        args.out.join("results.json").display(),
        t.elapsed().as_secs_f64()
    )?;
    Ok(())
}
