//! The `mts` command: multiresolution triangle strips from the command line.

use crate::stdout::{out, outln, warnln};
use anyhow::{bail, Context, Result};
use clap::{Args, Parser, Subcommand};
use mts::mesh::generate::Generated;
use mts::mesh::io::{load, LoadOptions};
use mts::mesh::{CleanOptions, CleanReport, Mesh};
use mts::strip::stats::StripStats;
use mts::{peers, stripify, StripifyOptions};
use results::MethodRow;
use serde_json::json;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::time::Instant;

mod bench;
mod bench_render;
mod charts;
mod check;
mod demo;
mod demo_scene;
mod figure6;
mod render;
mod results;
mod stdout;
mod summary;
mod viewer;

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
    /// The main job: build the model of the built-in mesh (or a file),
    /// sweep its LoDs and print the side-by-side summary.
    Demo(DemoArgs),
    /// Cut a mesh into triangle strips and compare with meshoptimizer's.
    Strips(StripsArgs),
    /// Record the quadric-error contraction sequence, take one LoD of it and
    /// measure its error beside meshoptimizer's simplify.
    Simplify(SimplifyArgs),
    /// Hausdorff and RMS distance of a mesh to a reference mesh.
    Distance(DistanceArgs),
    /// Write a mesh (a file or a generated one) as .obj, .ply, .glb or .gltf (by the output's extension).
    Convert(ConvertArgs),
    /// Build the MTS model (strips, contraction sequence, per-strip graphs)
    /// and write it as an .mts file.
    Build(BuildArgs),
    /// Describe an .mts file: sizes, bands, and strip quality at several
    /// LoDs against stripifying that LoD's mesh from scratch.
    Info(InfoArgs),
    /// Extract one LoD of a model as restart-encoded strips.
    Extract(ExtractArgs),
    /// Encode a mesh as the cluster tree's packet stream (a progressive,
    /// incrementally decodable file).
    Encode(EncodeArgs),
    /// Decode a packet stream, or only its first bytes (what a receiver
    /// draws while the stream arrives).
    Decode(DecodeArgs),
    /// Every method side by side on one mesh: bytes, build time and
    /// microseconds per LoD change on the linear, exponential and random
    /// request sequences.
    Compare(CompareArgs),
    /// Check a model against the replay oracle and coherent against
    /// from-scratch extraction; exits non-zero on any mismatch.
    Verify(VerifyArgs),
    /// Measure the MTS paper's tables on this machine: report.md and
    /// results.json (`mts bench render`: render throughput alone).
    Bench(BenchArgs),
    /// Draw one LoD headless (Mesa's lavapipe without a GPU) into a PNG,
    /// by the MTS strips or the oracle triangle list.
    Render(render::RenderArgs),
    /// Open a window on a model (orbit camera; wheel, Up/Down change the
    /// LoD, A toggles the automatic LoD, Escape quits).
    View(render::ViewArgs),
}

#[derive(Args)]
struct DemoArgs {
    #[command(flatten)]
    source: MeshSource,
    /// Where the strip of thumbnails (PNG) goes.
    #[arg(long, default_value = "demo-thumbnails.png")]
    thumbnails: PathBuf,
}

#[derive(Subcommand)]
enum BenchCommand {
    /// Frames and triangles per second: MTS strips against
    /// meshoptimizer-ordered triangle lists at 100%, 50% and 10%.
    Render(bench_render::BenchRenderArgs),
    /// The README's "Latest bench report" section, made from a report's
    /// results.json.
    Summary(SummaryArgs),
    /// Load a results.json through its typed layout and check the
    /// invariants CI holds a run to; exits non-zero naming each broken one.
    Check(CheckArgs),
}

#[derive(Args)]
struct CheckArgs {
    /// The report's results.json.
    results: PathBuf,
    /// The layout of `mts bench --quick` (one model, no scale section).
    #[arg(long)]
    quick: bool,
}

fn bench_check(args: &CheckArgs) -> Result<()> {
    let r = results::Results::load(&args.results)?;
    let bad = check::check(&r, args.quick);
    if !bad.is_empty() {
        bail!(
            "{}: {} broken:\n  {}",
            args.results.display(),
            bad.len(),
            bad.join("\n  ")
        );
    }
    match &r.machine.adapter {
        Some(a) => outln!(
            "{}: complete ({} models; Figure 6 and the scene on {a})",
            args.results.display(),
            r.models.len()
        ),
        None => outln!(
            "{}: complete ({} models; no adapter: {})",
            args.results.display(),
            r.models.len(),
            r.machine.adapter_note.as_deref().unwrap_or("?")
        ),
    }
}

#[derive(Args)]
struct SummaryArgs {
    /// The report's results.json.
    results: PathBuf,
    /// Rewrite this README's generated section in place.
    #[arg(long)]
    readme: Option<PathBuf>,
    /// With --readme: change nothing, fail when the section differs from
    /// what the results give.
    #[arg(long, requires = "readme")]
    check: bool,
}

fn bench_summary(args: &SummaryArgs) -> Result<()> {
    let path = &args.results;
    let results = results::Results::load(path)?;
    let Some(readme) = &args.readme else {
        let dir = path
            .parent()
            .map_or_else(String::new, |p| p.display().to_string());
        out!("{}", summary::summary(&results, &dir))?;
        return Ok(());
    };
    // Links are relative to the README.
    let base = readme.parent().unwrap_or(std::path::Path::new(""));
    let dir = path
        .parent()
        .map(|p| p.strip_prefix(base).unwrap_or(p).display().to_string())
        .unwrap_or_default();
    let section = summary::summary(&results, &dir);
    let old = std::fs::read_to_string(readme)
        .with_context(|| format!("cannot read {}", readme.display()))?;
    let Some(new) = summary::splice(&old, &section) else {
        bail!(
            "{} has no generated section: put the two lines\n{}\n{}\nwhere it goes",
            readme.display(),
            summary::BEGIN,
            summary::END
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
struct BenchArgs {
    #[command(subcommand)]
    command: Option<BenchCommand>,
    /// Meshes, or folders whose .obj and .ply files are all measured.
    /// Default: ../shared/models when it exists, else the built-in mesh.
    #[arg(long, num_args = 1..)]
    models: Vec<PathBuf>,
    /// Where report.md and results.json go.
    #[arg(long, default_value = "bench-report")]
    out: PathBuf,
    /// The built-in mesh only, fewer requests, no scale section (a smoke
    /// test of under two minutes).
    #[arg(long)]
    quick: bool,
    /// Skip Figure 6 (frames per second through the headless renderer).
    #[arg(long)]
    no_render: bool,
}

fn bench_cmd(args: &BenchArgs) -> Result<()> {
    match &args.command {
        Some(BenchCommand::Render(args)) => return bench_render::bench_render(args),
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
    let options = bench::BenchOptions {
        models,
        quick: args.quick,
        command: std::env::args().collect::<Vec<_>>().join(" "),
        render: !args.no_render,
    };
    let results = bench::run(&options, &|what| {
        bar.set_message(format!("measuring {what}"))
    })?;
    bar.finish_and_clear();
    bench::write(&args.out, &results)?;
    outln!(
        "wrote {} and {} in {:.0} s",
        args.out.join("report.md").display(),
        args.out.join("results.json").display(),
        t.elapsed().as_secs_f64()
    )?;
    Ok(())
}

#[derive(Args)]
struct BuildArgs {
    #[command(flatten)]
    source: MeshSource,
    /// The .mts file to write.
    #[arg(short, long)]
    output: PathBuf,
    /// Print JSON instead of a table.
    #[arg(long)]
    json: bool,
    /// Start a new band of strips when they send this much more indices per
    /// triangle than at the band's start (see BuildOptions::band_slack).
    #[arg(allow_negative_numbers = true, long, default_value_t = mts::model::DEFAULT_BAND_SLACK,
          value_parser = band_slack)]
    band_slack: f64,
    /// One band only: the paper's model, whose strips degrade as the mesh
    /// is simplified.
    #[arg(long, conflicts_with = "band_slack")]
    single_band: bool,
    /// Optimal placement in the contraction sequence (new vertices).
    #[arg(long)]
    optimal: bool,
    /// Cache-aware strips for LoD 0 and every band (see
    /// StripifyOptions::cache_aware).
    #[arg(long)]
    cache_aware: bool,
    /// Write the recipe only (strips, contraction sequence, options; the
    /// file format's version 1 or 2): about a seventh of the ready file,
    /// but loading builds the graphs again (hundreds of milliseconds
    /// instead of a few).
    #[arg(long)]
    recipe_only: bool,
}

impl BuildArgs {
    fn pipeline_options(&self) -> mts::model::PipelineOptions {
        use mts::simplify::{Placement, SimplifyOptions};
        let bands = mts::model::BuildOptions::default().stripify;
        mts::model::PipelineOptions {
            stripify: StripifyOptions {
                cache_aware: self.cache_aware,
                ..StripifyOptions::default()
            },
            simplify: SimplifyOptions {
                placement: if self.optimal {
                    Placement::Optimal
                } else {
                    Placement::Endpoint
                },
                ..SimplifyOptions::default()
            },
            build: mts::model::BuildOptions {
                band_slack: if self.single_band {
                    f64::INFINITY
                } else {
                    self.band_slack
                },
                stripify: StripifyOptions {
                    cache_aware: self.cache_aware,
                    ..bands
                },
            },
        }
    }
}

#[derive(Args)]
struct InfoArgs {
    /// The .mts file.
    model: PathBuf,
    /// Print JSON instead of a table.
    #[arg(long)]
    json: bool,
}

/// Where a mesh comes from: a file or a built-in generator.
#[derive(Args)]
struct MeshSource {
    /// OBJ or PLY file (or an .mts model, for the commands that read a
    /// model).
    #[arg(conflicts_with = "generated")]
    pub(crate) mesh: Option<PathBuf>,
    /// Built-in mesh NAME:SIZE, SIZE in triangles (k/M suffixes):
    /// icosphere:100k, torus:1M, grid:20k. The default when no file is given.
    #[arg(long, value_name = "NAME:SIZE")]
    generated: Option<Generated>,
    /// Merge vertices with identical positions.
    #[arg(long)]
    weld: bool,
    /// Read normals, texture coordinates, colours and the texture (OBJ
    /// vertices are split where a position has several); every LoD keeps
    /// every seam, and `simplify -o`, `build`, `extract -o`, the baselines
    /// (`encode`, `compare`) and `decode -o` keep them. `demo` refuses
    /// them (its scenes do not carry them yet).
    #[arg(long)]
    properties: bool,
    /// The most triangles the input file may ask for (polygons
    /// triangulated, strips decoded, glTF instances counted each time;
    /// three times as many vertices): a bound on the work and memory a
    /// small file can ask for. About 650 bytes a triangle to build.
    #[arg(long, value_name = "N", default_value_t = mts::mesh::io::DEFAULT_MAX_TRIANGLES as usize,
          value_parser = count_in::<1, { 1 << 32 }>, allow_negative_numbers = true)]
    max_triangles: usize,
}

impl MeshSource {
    /// The model to read: an `.mts` file (recognised by its magic bytes),
    /// or the model of the mesh, built first with the default options (a
    /// progress bar on large inputs).
    fn model(&self) -> Result<(String, mts::MtsModel)> {
        let (name, mesh) = match &self.mesh {
            Some(path) => {
                let bytes = mts::mesh::io::read_file(path)?;
                if bytes.starts_with(mts::model::format::MAGIC) {
                    let model = mts::MtsModel::from_bytes(&bytes, path)?;
                    return Ok((path.display().to_string(), model));
                }
                let (mesh, _) = mts::mesh::io::load_bytes(&bytes, path, self.load_options())
                    .context("cannot load the mesh")?;
                (path.display().to_string(), mesh)
            }
            None => {
                let (name, mesh, _) = self.load()?;
                (name, mesh)
            }
        };
        let (model, _, _) = build_with_bar(&mesh, &Default::default())?;
        Ok((name, model))
    }

    /// [`MeshSource::load`] for the commands that lay out scenes, which do
    /// not carry properties yet.
    fn load_for_scene(&self) -> Result<(String, Mesh, CleanReport)> {
        if self.properties {
            bail!("scenes do not carry vertex properties yet: drop --properties");
        }
        self.load()
    }

    /// Refuses `output` when it names the input file (or one of `more`):
    /// the input would be replaced by what was made from it.
    fn check_output(&self, output: &Path) -> Result<()> {
        check_output(
            output,
            &self.mesh.iter().map(PathBuf::as_path).collect::<Vec<_>>(),
        )
    }

    fn load_options(&self) -> LoadOptions {
        LoadOptions {
            clean: CleanOptions { weld: self.weld },
            properties: self.properties,
            max_triangles: self.max_triangles as u64,
        }
    }

    fn load(&self) -> Result<(String, Mesh, CleanReport)> {
        let clean = CleanOptions { weld: self.weld };
        if let Some(path) = &self.mesh {
            let (mesh, report) = load(path, self.load_options()).context("cannot load the mesh")?;
            Ok((path.display().to_string(), mesh, report))
        } else {
            let g = self.generated.unwrap_or(Generated::DEFAULT);
            let mesh = if self.properties {
                g.build_with_properties()
            } else {
                g.build()
            };
            let raw = mts::mesh::RawMesh {
                positions: mesh.positions,
                triangles: mesh.triangles,
                degenerate_in_source: 0,
                properties: mesh.properties,
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
    /// Timed repetitions (1 to 10,000); the median is reported.
    #[arg(long, default_value_t = 5, value_parser = count_in::<1, MAX_REPEAT>, allow_negative_numbers = true)]
    repeat: usize,
    /// Skip the global quadrilateral-patch pass.
    #[arg(long)]
    no_patches: bool,
    /// Smallest patch kept by the global pass, in quads.
    #[arg(long)]
    min_patch: Option<usize>,
    /// Only this swap penalty in the local pass (see StripifyOptions).
    #[arg(allow_negative_numbers = true, long, value_parser = non_negative::<f32>)]
    swap_penalty: Option<f32>,
    /// Do not join strips whose ends are neighbours.
    #[arg(long)]
    no_join: bool,
    /// Short strips side by side in vertex-cache order (see
    /// StripifyOptions::cache_aware; the options above are then ignored).
    #[arg(long)]
    cache_aware: bool,
}

#[derive(Args)]
#[command(group(clap::ArgGroup::new("target").required(true).args(["ratio", "triangles"])))]
struct SimplifyArgs {
    #[command(flatten)]
    source: MeshSource,
    /// Keep this share of the triangles (0..1).
    #[arg(allow_negative_numbers = true, long)]
    ratio: Option<f64>,
    /// Keep at most this many triangles.
    #[arg(allow_negative_numbers = true, long)]
    triangles: Option<usize>,
    /// Write the simplified mesh (.obj, .ply, .glb or .gltf, by extension; with --properties, its properties).
    #[arg(short, long)]
    output: Option<PathBuf>,
    /// Print JSON instead of a table.
    #[arg(long)]
    json: bool,
    /// Place each surviving vertex at the quadric's optimum (new vertices)
    /// instead of keeping an endpoint.
    #[arg(long)]
    optimal: bool,
    /// Also contract vertex pairs closer than this share of the diagonal.
    #[arg(allow_negative_numbers = true, long, value_name = "SHARE", value_parser = non_negative::<f32>)]
    pair_distance: Option<f32>,
    /// Weight of the boundary-preserving planes.
    #[arg(allow_negative_numbers = true, long, value_parser = non_negative::<f64>)]
    boundary_weight: Option<f64>,
    /// Weight of texture-coordinate distortion in the cost, with
    /// --properties (an error of 1/weight costs one bounding-box diagonal).
    #[arg(long, value_name = "WEIGHT", allow_hyphen_values = true, value_parser = non_negative::<f32>)]
    uv_weight: Option<f32>,
    /// Weight of normal distortion in the cost, with --properties.
    #[arg(long, value_name = "WEIGHT", allow_hyphen_values = true, value_parser = non_negative::<f32>)]
    normal_weight: Option<f32>,
    /// Weight of colour distortion in the cost, with --properties.
    #[arg(long, value_name = "WEIGHT", allow_hyphen_values = true, value_parser = non_negative::<f32>)]
    color_weight: Option<f32>,
    /// Surface samples per side for the error measurement.
    #[arg(long, default_value_t = mts::distance::DEFAULT_SAMPLES, value_parser = count_in::<1, MAX_SAMPLES>, allow_negative_numbers = true)]
    samples: usize,
    /// Skip meshoptimizer.
    #[arg(long)]
    no_meshopt: bool,
}

#[derive(Args)]
struct DistanceArgs {
    /// The reference mesh (errors are relative to its bounding-box diagonal).
    reference: PathBuf,
    /// The mesh measured against it.
    other: PathBuf,
    /// Surface samples per side.
    #[arg(long, default_value_t = mts::distance::DEFAULT_SAMPLES, value_parser = count_in::<1, MAX_SAMPLES>, allow_negative_numbers = true)]
    samples: usize,
    /// Print JSON.
    #[arg(long)]
    json: bool,
}

#[derive(Args)]
struct ConvertArgs {
    #[command(flatten)]
    source: MeshSource,
    /// The OBJ file to write.
    #[arg(short, long)]
    output: PathBuf,
}

/// Refuses `output` when it is one of `inputs` (the same file, whatever
/// the path): writing it would replace what the command reads.
pub(crate) fn check_output(output: &Path, inputs: &[&Path]) -> Result<()> {
    if let Some(input) = inputs.iter().find(|i| mts::output::is_same_file(output, i)) {
        bail!(
            "{}: the output is the input file {}: write to another file",
            output.display(),
            input.display()
        );
    }
    Ok(())
}

/// A count argument in `MIN..=MAX`: what clap calls for `--repeat`,
/// `--samples`, `--requests`, `--frames` and `--scene`, so that no
/// allocation or loop is sized by an absurd number, and a negative or
/// fractional one is named as such.
pub(crate) fn count_in<const MIN: u64, const MAX: u64>(
    s: &str,
) -> std::result::Result<usize, String> {
    let n: i128 = s
        .trim()
        .parse()
        .map_err(|_| format!("`{s}` is not a whole number (expected {MIN} to {MAX})"))?;
    if n < i128::from(MIN) || n > i128::from(MAX) {
        return Err(format!("{n} is outside {MIN}..={MAX}"));
    }
    Ok(n as usize)
}

/// `--pixel-error`: a finite number of pixels, 0 to 1000 (0: full
/// detail).
pub(crate) fn pixel_error(s: &str) -> std::result::Result<f32, String> {
    let v: f32 = s
        .trim()
        .parse()
        .map_err(|_| format!("`{s}` is not a number of pixels"))?;
    if (0.0..=1000.0).contains(&v) {
        Ok(v)
    } else {
        Err(format!("{v} is outside 0..=1000 pixels"))
    }
}

/// `--band-slack`: a number of at least [`mts::model::MIN_BAND_SLACK`]
/// (`inf` is one band, as `--single-band`).
fn band_slack(s: &str) -> std::result::Result<f64, String> {
    let v: f64 = s
        .trim()
        .parse()
        .map_err(|_| format!("`{s}` is not a number"))?;
    if v >= mts::model::MIN_BAND_SLACK {
        Ok(v)
    } else {
        Err(format!(
            "{v} is below the smallest slack, {} (use --single-band for one band)",
            mts::model::MIN_BAND_SLACK
        ))
    }
}

/// A finite number of at least 0 (weights and distances).
fn non_negative<T: std::str::FromStr + Into<f64> + Copy>(
    s: &str,
) -> std::result::Result<T, String> {
    let v: T = s
        .trim()
        .parse()
        .map_err(|_| format!("`{s}` is not a number"))?;
    let x: f64 = v.into();
    if x.is_finite() && x >= 0.0 {
        Ok(v)
    } else {
        Err(format!("{x} is not a finite number of at least 0"))
    }
}

/// Most timed repetitions `--repeat` takes.
const MAX_REPEAT: u64 = 10_000;
/// Most surface samples per side `--samples` takes (about 1 GB of points).
const MAX_SAMPLES: u64 = 20_000_000;
/// Most requests per sequence `compare --requests` takes.
const MAX_REQUESTS: u64 = 10_000_000;

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

/// `mts strips --json`'s figures of one stripifier: the bench's row.
/// The bench's strip row plus the other cache models' invocations per
/// triangle (kept out of the typed bench results).
fn stats_json(s: &StripStats) -> serde_json::Value {
    let mut v = json!(results::StripRow::from(s));
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

fn simplify(args: &SimplifyArgs) -> Result<()> {
    if let Some(out) = &args.output {
        args.source.check_output(out)?;
    }
    use mts::distance::surface_distance;
    use mts::peers::quality::{self, Measurement};
    use mts::simplify::{Placement, SimplifyOptions};
    let (name, mesh, _) = args.source.load()?;
    let input = mesh.triangle_count();
    let target = match (args.triangles, args.ratio) {
        (Some(n), _) => n,
        (None, Some(r)) if (0.0..=1.0).contains(&r) => (r * input as f64).round() as usize,
        (None, Some(r)) => bail!("--ratio must be between 0 and 1, not {r}"),
        (None, None) => bail!("give --ratio or --triangles"),
    };
    let defaults = SimplifyOptions::default();
    let mut options = SimplifyOptions {
        placement: if args.optimal {
            Placement::Optimal
        } else {
            Placement::Endpoint
        },
        pair_distance: args.pair_distance,
        boundary_weight: args.boundary_weight.unwrap_or(defaults.boundary_weight),
        stop_at_triangles: None,
        attribute_weights: mts::simplify::AttributeWeights {
            uv: args.uv_weight.unwrap_or(defaults.attribute_weights.uv),
            normal: args
                .normal_weight
                .unwrap_or(defaults.attribute_weights.normal),
            color: args
                .color_weight
                .unwrap_or(defaults.attribute_weights.color),
        },
    };
    let t = Instant::now();
    let whole = mts::simplify(&mesh, &options);
    let ms = t.elapsed().as_secs_f64() * 1e3;
    options.stop_at_triangles = Some(target);
    let t = Instant::now();
    let partial = mts::simplify(&mesh, &options);
    let ms_to_target = t.elapsed().as_secs_f64() * 1e3;
    let collapses = &whole.collapses;
    let lod = collapses.lod_for_triangles(target);
    // The early-stopped run must be a prefix of the whole sequence.
    if partial.collapses.steps() != &collapses.steps()[..partial.collapses.max_lod()] {
        bail!("internal error: the sequence stopped at the target differs from the whole one");
    }
    let skipped = peers::meshopt::refusal(&mesh);
    if let Some(why) = &skipped {
        warnln!("{name}: {why}");
    }
    // Our LoD over every input and appended position, referenced or not:
    // the surface `mts simplify` has always measured (the bench drops the
    // unreferenced ones, and both keep their own figures).
    let ours_at = |lod| Mesh {
        positions: mesh
            .positions
            .iter()
            .chain(collapses.appended())
            .copied()
            .collect(),
        triangles: collapses.triangles_at(&mesh, lod),
        properties: Default::default(),
    };
    // Compare at one triangle count: ours at the target, meshoptimizer
    // asked for the same; when it stops above it, ours at its count.
    let (lod, d, peer) = if !args.no_meshopt && skipped.is_none() {
        let q = quality::compare(&mesh, collapses, lod, args.samples, ours_at);
        let peer = json!({
            "triangles": q.meshopt.triangle_count,
            "ms": q.meshopt_ms,
            "hausdorff": q.meshopt.distance.hausdorff,
            "rms": q.meshopt.distance.rms,
        });
        (q.lod, q.ours, peer)
    } else {
        let ours = ours_at(lod);
        let d = Measurement {
            triangle_count: ours.triangle_count(),
            distance: surface_distance((&mesh).into(), (&ours).into(), args.samples),
        };
        (lod, d, serde_json::Value::Null)
    };
    if let Some(path) = &args.output {
        mts::mesh::io::save_mesh(&collapses.mesh_at(&mesh, lod), path)?;
    }
    let v = json!({
        "mesh": name,
        "input_triangles": input,
        "target": target,
        "triangles": d.triangle_count,
        "lod": lod,
        "max_lod": collapses.max_lod(),
        "ms": ms,
        "ms_to_target": ms_to_target,
        "quadric_error": collapses.error(lod),
        "hausdorff": d.distance.hausdorff,
        "rms": d.distance.rms,
        "stop": whole.stop.to_string(),
        "meshopt": peer,
    });
    if args.json {
        outln!("{}", serde_json::to_string_pretty(&v)?)?;
        return Ok(());
    }
    outln!(
        "{name}: {input} triangles -> target {target}; sequence of {} contractions, {}",
        collapses.max_lod(),
        whole.stop
    )?;
    outln!("{:<26}{:>14}{:>14}", "", "mts", "meshopt")?;
    let peer = &v["meshopt"];
    let show = |x: &serde_json::Value, digits: usize| {
        x.as_f64()
            .map_or_else(|| "-".to_string(), |x| format!("{x:.digits$}"))
    };
    let rows = [
        (
            "triangles",
            show(&v["triangles"], 0),
            show(&peer["triangles"], 0),
        ),
        (
            "ms (to target)",
            format!("{ms_to_target:.1}"),
            show(&peer["ms"], 1),
        ),
        (
            "Hausdorff / diagonal",
            show(&v["hausdorff"], 6),
            show(&peer["hausdorff"], 6),
        ),
        ("RMS / diagonal", show(&v["rms"], 6), show(&peer["rms"], 6)),
    ];
    for (label, mine, theirs) in rows {
        outln!("{label:<26}{mine:>14}{theirs:>14}")?;
    }
    outln!("{:<26}{:>14.1}", "ms (whole sequence)", ms)?;
    Ok(())
}

fn distance(args: &DistanceArgs) -> Result<()> {
    let options = LoadOptions::default();
    let (a, _) = load(&args.reference, options).context("cannot load the reference")?;
    let (b, _) = load(&args.other, options).context("cannot load the measured mesh")?;
    let d = mts::distance::surface_distance((&a).into(), (&b).into(), args.samples);
    if args.json {
        let v = json!({
            "reference_triangles": a.triangle_count(),
            "triangles": b.triangle_count(),
            "hausdorff": d.hausdorff,
            "rms": d.rms,
            "forward": d.forward,
            "backward": d.backward,
        });
        outln!("{v}")?;
    } else {
        outln!(
            "Hausdorff {:.6}  RMS {:.6}  (relative to the reference's diagonal; \
             reference -> other {:.6}, other -> reference {:.6})",
            d.hausdorff,
            d.rms,
            d.forward,
            d.backward
        )?;
    }
    Ok(())
}

fn convert(args: &ConvertArgs) -> Result<()> {
    args.source.check_output(&args.output)?;
    let (_, mesh, _) = args.source.load()?;
    mts::mesh::io::save_mesh(&mesh, &args.output)?;
    Ok(())
}

fn run(cli: &Cli) -> Result<()> {
    match &cli.command {
        Command::Strips(args) => strips(args),
        Command::Simplify(args) => simplify(args),
        Command::Distance(args) => distance(args),
        Command::Convert(args) => convert(args),
        Command::Build(args) => build(args),
        Command::Info(args) => info(args),
        Command::Extract(args) => extract(args),
        Command::Bench(args) => bench_cmd(args),
        Command::Demo(args) => {
            let (name, mesh, _) = args.source.load_for_scene()?;
            demo::run(&name, &mesh, &args.thumbnails)
        }
        Command::Encode(args) => encode(args),
        Command::Decode(args) => decode(args),
        Command::Compare(args) => compare(args),
        Command::Verify(args) => verify(args),
        Command::Render(args) => render::render(args),
        Command::View(args) => render::view(args),
    }
}

/// Inputs of this many triangles or more get a progress bar.
const PROGRESS_MIN_TRIANGLES: usize = 200_000;

fn build(args: &BuildArgs) -> Result<()> {
    args.source.check_output(&args.output)?;
    let started = std::time::Instant::now();
    let (name, mesh, _) = args.source.load()?;
    let load = started.elapsed();
    let options = args.pipeline_options();
    if args.optimal && !mesh.properties.is_empty() {
        bail!(
            "{name}: the MTS model cannot hold the vertices optimal placement creates with \
             properties; drop --optimal or --properties (`mts simplify --optimal --properties` \
             writes such levels)"
        );
    }
    let (model, _, t) = build_with_bar(&mesh, &options)?;
    let recipe = model.to_recipe_bytes();
    let bytes = if args.recipe_only {
        recipe.clone()
    } else {
        model.to_bytes()
    };
    mts::output::write_file(&args.output, &bytes)?;
    let st = model.stats();
    let ms = |d: std::time::Duration| d.as_secs_f64() * 1e3;
    if args.json {
        outln!(
            "{}",
            json!({
                "input": name,
                "vertices": mesh.vertex_count(),
                "triangles": mesh.triangle_count(),
                "max_lod": model.max_lod(),
                "strips": st.strips,
                "bytes": bytes.len(),
                "recipe_bytes": recipe.len(),
                "raw_bytes": model.raw_bytes(),
                "bands": model.band_count(),
                "nodes": st.nodes,
                "arcs": st.arcs,
                "memory_bytes": st.memory_bytes,
                "ms_load": ms(load),
                "ms_stripify": ms(t.stripify),
                "ms_simplify": ms(t.simplify),
                "ms_model": ms(t.model),
                "ms": ms(t.total),
            })
        )?;
    } else {
        outln!(
            "{name}: {} triangles, {} vertices, {} LoDs",
            mesh.triangle_count(),
            mesh.vertex_count(),
            model.max_lod() + 1
        )?;
        outln!(
            "  time      load {:.1} ms; stripify {:.1} ms beside simplify {:.1} ms, model {:.1} ms, total {:.1} ms",
            ms(load),
            ms(t.stripify),
            ms(t.simplify),
            ms(t.model),
            ms(t.total)
        )?;
        outln!(
            "  model     {} bands, {} strips, {} nodes, {} arcs, {:.1} MB in memory",
            model.band_count(),
            st.strips,
            st.nodes,
            st.arcs,
            st.memory_bytes as f64 / 1e6
        )?;
        outln!(
            "  file      {} bytes = {:.2} x raw ({} bytes: 12 per vertex and its properties, 12 per triangle) -> {}",
            bytes.len(),
            bytes.len() as f64 / model.raw_bytes() as f64,
            model.raw_bytes(),
            args.output.display()
        )?;
        if !args.recipe_only {
            outln!(
                "            of which the recipe {} bytes = {:.2} x raw (what --recipe-only writes)",
                recipe.len(),
                recipe.len() as f64 / model.raw_bytes() as f64
            )?;
        }
    }
    Ok(())
}

/// The whole pipeline with a progress bar on large inputs.
fn build_with_bar(
    mesh: &Mesh,
    options: &mts::model::PipelineOptions,
) -> mts::Result<(
    mts::MtsModel,
    mts::simplify::Stop,
    mts::model::PipelineTimings,
)> {
    use indicatif::{ProgressBar, ProgressStyle};
    let bar = if mesh.triangle_count() >= PROGRESS_MIN_TRIANGLES {
        ProgressBar::new(1)
    } else {
        ProgressBar::hidden()
    };
    bar.set_style(
        ProgressStyle::with_template("{spinner} {msg:16} [{bar:30}] {pos}/{len} {elapsed}")
            .expect("valid template"),
    );
    bar.enable_steady_tick(std::time::Duration::from_millis(200));
    bar.set_message("strips + QEM");
    let mut started = false;
    let out = mts::model::try_build_from_mesh(mesh, options, &mut |done, max_lod| {
        if !started {
            bar.set_message("graphs (LoDs)");
            bar.set_length(max_lod.max(1) as u64);
            started = true;
        }
        bar.set_position(done as u64);
    });
    bar.finish_and_clear();
    out
}

/// Which LoD a command reads: by number, triangle budget or share.
#[derive(Args)]
#[command(group(clap::ArgGroup::new("level").args(["lod", "triangles", "ratio"])))]
struct LevelArgs {
    /// The LoD (0 is the full mesh; clamped to the last).
    #[arg(allow_negative_numbers = true, long)]
    lod: Option<usize>,
    /// The finest LoD with at most this many triangles.
    #[arg(allow_negative_numbers = true, long)]
    triangles: Option<usize>,
    /// The LoD with this share of the full triangle count (0..1).
    #[arg(allow_negative_numbers = true, long)]
    ratio: Option<f64>,
}

impl LevelArgs {
    /// The LoD asked for in `source`'s own numbering (`None` when none
    /// was given). See [`LevelArgs::resolve_in`].
    fn resolve(&self, source: &dyn mts::LodSource) -> Result<Option<usize>> {
        self.resolve_in(source.max_lod(), source.triangle_count(0), |n| {
            mts::lod::lod_for_triangles(source, n)
        })
    }

    /// The LoD of an MTS model (its own triangle table; no extractor).
    fn resolve_model(&self, model: &mts::MtsModel) -> Result<Option<usize>> {
        self.resolve_in(model.max_lod(), model.triangle_count(0), |n| {
            model.lod_for_triangles(n)
        })
    }

    /// The LoD from `max_lod`, the full triangle count and the finest LoD
    /// within a budget: a share is the budget `ratio × full`, answered like
    /// `--triangles`; a LoD past the last is clamped.
    fn resolve_in(
        &self,
        max_lod: usize,
        full: usize,
        lod_for_triangles: impl Fn(usize) -> usize,
    ) -> Result<Option<usize>> {
        Ok(match (self.lod, self.triangles, self.ratio) {
            (Some(l), _, _) => Some(l.min(max_lod)),
            (_, Some(n), _) => Some(lod_for_triangles(n)),
            (_, _, Some(r)) => {
                if !(0.0..=1.0).contains(&r) {
                    bail!("--ratio must be between 0 and 1, not {r}");
                }
                Some(lod_for_triangles((r * full as f64).round() as usize))
            }
            _ => None,
        })
    }
}

#[derive(Args)]
struct ExtractArgs {
    #[command(flatten)]
    source: MeshSource,
    #[command(flatten)]
    level: LevelArgs,
    /// Write the extracted triangles (.obj, .ply, .glb or .gltf, by extension).
    #[arg(short, long)]
    output: Option<PathBuf>,
    /// Timed extractions from scratch (1 to 10,000); the median is reported.
    #[arg(long, default_value_t = 11, value_parser = count_in::<1, MAX_REPEAT>, allow_negative_numbers = true)]
    repeat: usize,
    /// Print JSON instead of a table.
    #[arg(long)]
    json: bool,
    /// The method extracting the LoD: mts (strips) or a baseline. The
    /// cluster tree has its own clustering, so its LoD k differs; use
    /// --triangles or --ratio to compare methods.
    #[arg(long, value_enum, default_value_t = Method::Mts)]
    method: Method,
}

/// The LoD methods (`LodSource` implementations).
#[derive(Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
enum Method {
    /// Multiresolution triangle strips.
    Mts,
    /// Progressive mesh (Hoppe 1996).
    Pm,
    /// Progressive multilevel mesh.
    Multilevel,
    /// Cluster tree.
    Cluster,
    /// meshoptimizer simplify at fixed ratios.
    Discrete,
}

impl Method {
    const ALL: [Method; 5] = [
        Method::Mts,
        Method::Pm,
        Method::Multilevel,
        Method::Cluster,
        Method::Discrete,
    ];

    /// The core's method of the same name.
    fn core(self) -> mts::methods::Method {
        use mts::methods::Method as M;
        match self {
            Method::Mts => M::Mts,
            Method::Pm => M::Pm,
            Method::Multilevel => M::Multilevel,
            Method::Cluster => M::Cluster,
            Method::Discrete => M::Discrete,
        }
    }
}

/// The source of `method` over `model` (its mesh and contraction sequence).
fn make_source<'m>(
    method: Method,
    model: &'m mts::MtsModel,
    mesh: &Mesh,
) -> Result<Box<dyn mts::LodSource + 'm>> {
    Ok(method.core().source(model, mesh)?)
}

fn extract(args: &ExtractArgs) -> Result<()> {
    use mts::Extractor;
    if let Some(out) = &args.output {
        args.source.check_output(out)?;
    }
    if args.method != Method::Mts {
        return extract_baseline(args);
    }
    let started = Instant::now();
    let (name, model) = args.source.model()?;
    // Opening, validating (and, today, rebuilding the graphs from the
    // file's recipe), until an extractor is ready.
    let ready = Extractor::new(&model);
    let load_ms = started.elapsed().as_secs_f64() * 1e3;
    drop(ready);
    let lod = args
        .level
        .resolve_model(&model)?
        .context("give --lod, --triangles or --ratio")?;
    // Each timed extraction starts from an empty extractor (no coherence).
    let mut times = Vec::with_capacity(args.repeat.max(1));
    let mut ex = Extractor::new(&model);
    for _ in 0..args.repeat.max(1) {
        ex = Extractor::new(&model);
        let t = Instant::now();
        ex.set_lod(lod);
        times.push(t.elapsed().as_secs_f64() * 1e6);
    }
    times.sort_by(f64::total_cmp);
    let us = times[times.len() / 2];
    let mut compact = Vec::new();
    ex.write_compact(&mut compact);
    let runs = compact
        .split(|&i| i == mts::strip::encode::RESTART_U32)
        .filter(|r| !r.is_empty())
        .count();
    let triangles = model.triangle_count(lod);
    let mut vertices_written = None;
    if let Some(out) = &args.output {
        // The level's own vertices only, renumbered; their properties are
        // the input vertices' (a model with properties has no created
        // vertices: endpoint placement).
        let mesh = Mesh::level(model.positions(), &ex.triangles(), model.properties());
        mts::mesh::io::save_mesh(&mesh, out)?;
        vertices_written = Some(mesh.vertex_count());
    }
    if args.json {
        let mut v = json!({
            "input": name,
            "lod": lod,
            "max_lod": model.max_lod(),
            "triangles": triangles,
            "strips": runs,
            "indices": ex.indices_sent(),
            "indices_per_triangle": ex.indices_sent() as f64 / triangles.max(1) as f64,
            "us": us,
            "load_ms": load_ms,
        });
        if let Some(n) = vertices_written {
            v["vertices_written"] = json!(n);
        }
        outln!("{v}")?;
    } else {
        outln!(
            "{name}: LoD {lod} of {}: {triangles} triangles in {runs} strips, {} indices sent ({:.3} per triangle), extracted in {us:.1} us (median of {} from scratch)",
            model.max_lod(),
            ex.indices_sent(),
            ex.indices_sent() as f64 / triangles.max(1) as f64,
            times.len()
        )?;
    }
    Ok(())
}

#[derive(Args)]
struct VerifyArgs {
    #[command(flatten)]
    source: MeshSource,
    /// `all`, or a number of LoDs (at least 1) spread evenly from 0 to the
    /// last; a number above the model's LoD count checks them all.
    #[arg(long, default_value = "all", allow_negative_numbers = true)]
    lods: String,
    /// Print JSON instead of a sentence.
    #[arg(long)]
    json: bool,
}

fn verify(args: &VerifyArgs) -> Result<()> {
    let (name, model) = args.source.model()?;
    let n = match args.lods.as_str() {
        "all" => None,
        text => {
            let n: u128 = text.trim().parse().map_err(|_| {
                anyhow::anyhow!("--lods takes `all` or a whole number of at least 1, not `{text}`")
            })?;
            if n == 0 {
                bail!("--lods 0 checks nothing: give `all` or at least 1");
            }
            // More than the model has is all of them.
            let all = model.max_lod() as u128 + 1;
            (n < all).then_some(n as usize)
        }
    };
    let lods = mts::model::spread_lods(model.max_lod(), n);
    let t = Instant::now();
    let report = mts::model::verify(&model, &model.mesh(), &lods);
    let secs = t.elapsed().as_secs_f64();
    if args.json {
        outln!(
            "{}",
            json!({
                "input": name,
                "lods_checked": report.lods_checked,
                "mismatches": report.mismatches,
                "first_mismatch": report.first_mismatch.as_ref().map(|(l, what)| json!({"lod": l, "what": what})),
                "seconds": secs,
            })
        )?;
    } else {
        outln!(
            "{name}: {} LoDs checked against the replay oracle and from-scratch extraction in {secs:.2} s, {} mismatches",
            report.lods_checked, report.mismatches
        )?;
        if let Some((lod, what)) = &report.first_mismatch {
            outln!("  first at LoD {lod}: {what}")?;
        }
    }
    if let Some((lod, what)) = &report.first_mismatch {
        bail!(
            "{name}: the model breaks the invariant: {} of {} LoDs mismatch, the first at LoD {lod}: {what}",
            report.mismatches,
            report.lods_checked
        );
    }
    Ok(())
}

fn info(args: &InfoArgs) -> Result<()> {
    use mts::{Extractor, MtsModel};
    let t0 = Instant::now();
    let model = MtsModel::load(&args.model)?;
    let load_ms = t0.elapsed().as_secs_f64() * 1e3;
    let file_bytes = std::fs::metadata(&args.model)
        .with_context(|| format!("cannot read {}", args.model.display()))?
        .len();
    let st = model.stats();
    let mesh = model.mesh();
    let mut ex = Extractor::new(&model);
    let mut levels = Vec::new();
    for ratio in [1.0, 0.5, 0.25, 0.1, 0.05, 0.01] {
        let lod = model.lod_for_ratio(ratio);
        ex.set_lod(lod);
        let triangles = model.triangle_count(lod);
        let fresh = stripify(
            &model.collapses().mesh_at(&mesh, lod),
            &StripifyOptions::default(),
        );
        let ours = ex.indices_sent() as f64 / triangles.max(1) as f64;
        let theirs = fresh.restart_index_count() as f64 / triangles.max(1) as f64;
        levels.push(json!({
            "ratio": ratio,
            "lod": lod,
            "triangles": triangles,
            "indices": ex.indices_sent(),
            "indices_per_triangle": ours,
            "restripified_indices_per_triangle": theirs,
            "quality_ratio": ours / theirs,
        }));
    }
    let props = model.properties();
    let mut streams = Vec::new();
    for (present, name) in [
        (props.normals.is_some(), "normals"),
        (props.uvs.is_some(), "uvs"),
        (props.colors.is_some(), "colors"),
    ] {
        if present {
            streams.push(name);
        }
    }
    let points = props
        .position_ids
        .iter()
        .max()
        .map_or(model.collapses().vertex_count(), |&m| m as usize + 1);
    let texture = props.texture.as_ref().map(|t| match t {
        mts::mesh::Texture::File(f) => f.display().to_string(),
        mts::mesh::Texture::Embedded { mime, bytes } => {
            format!("embedded {mime} ({} bytes)", bytes.len())
        }
    });
    if args.json {
        let mut v = json!({
            "file": args.model.display().to_string(),
            "file_bytes": file_bytes,
                "raw_bytes": model.raw_bytes(),
                "load_ms": load_ms,
                "vertices": model.positions().len(),
                "triangles": model.triangle_count(0),
                "max_lod": model.max_lod(),
                "bands": model.band_count(),
                "strips": st.strips,
                "nodes": st.nodes,
                "arcs": st.arcs,
            "memory_bytes": st.memory_bytes,
            "levels": levels,
        });
        // Only for a model with properties, so that the output of the
        // others stays as it was.
        if !props.is_empty() {
            v["properties"] = json!({
                "streams": streams,
                "points": points,
                "texture": texture,
            });
        }
        outln!("{}", serde_json::to_string_pretty(&v)?)?;
    } else {
        outln!(
            "{}: {} bytes ({:.2} x raw), loaded and built in {load_ms:.1} ms",
            args.model.display(),
            file_bytes,
            file_bytes as f64 / model.raw_bytes() as f64
        )?;
        outln!("  {} vertices, {} triangles, {} LoDs, {} bands, {} strips, {} nodes, {} arcs, {:.1} MB in memory",
            model.positions().len(), model.triangle_count(0), model.max_lod() + 1, model.band_count(), st.strips, st.nodes, st.arcs, st.memory_bytes as f64 / 1e6)?;
        if !props.is_empty() {
            outln!(
                "  properties: {} on {points} points; texture: {}",
                if streams.is_empty() {
                    "none".to_string()
                } else {
                    streams.join(", ")
                },
                texture.as_deref().unwrap_or("none")
            )?;
        }
        outln!(
            "  {:>6} {:>7} {:>9} {:>9} {:>11} {:>7}",
            "share",
            "LoD",
            "triangles",
            "idx/tri",
            "restripify",
            "ratio"
        )?;
        for l in &levels {
            outln!(
                "  {:>5.0}% {:>7} {:>9} {:>9.3} {:>11.3} {:>7.3}",
                l["ratio"].as_f64().unwrap_or(0.0) * 100.0,
                l["lod"].as_u64().unwrap_or(0),
                l["triangles"].as_u64().unwrap_or(0),
                l["indices_per_triangle"].as_f64().unwrap_or(0.0),
                l["restripified_indices_per_triangle"]
                    .as_f64()
                    .unwrap_or(0.0),
                l["quality_ratio"].as_f64().unwrap_or(0.0),
            )?;
        }
    }
    Ok(())
}

fn main() -> std::process::ExitCode {
    // Mesa's implicit Vulkan layer VK_LAYER_MESA_device_select connects to
    // Wayland to rank GPUs by the display they drive, and without
    // XDG_RUNTIME_DIR (no Wayland session: a headless run) libwayland prints
    // "error: XDG_RUNTIME_DIR is invalid or not set" twice, as if it were
    // ours. With no session there is no display to rank by: the layer is
    // switched off by its documented variable, unless the user set it.
    // Set before any thread starts.
    if std::env::var_os("XDG_RUNTIME_DIR").is_none()
        && std::env::var_os("NODEVICE_SELECT").is_none()
    {
        std::env::set_var("NODEVICE_SELECT", "1");
    }
    let cli = Cli::parse();
    match run(&cli) {
        Ok(()) => std::process::ExitCode::SUCCESS,
        Err(e) if e.downcast_ref::<stdout::ClosedPipe>().is_some() => {
            std::process::ExitCode::from(141)
        }
        Err(e) => {
            // One line: the context, then each cause not already said.
            let mut line = e.to_string();
            for cause in e.chain().skip(1) {
                let text = cause.to_string();
                if !line.contains(&text) {
                    line = format!("{line}: {text}");
                }
            }
            // Standard error may be closed or full too: then the status
            // alone tells.
            warnln!("error: {line}");
            std::process::ExitCode::FAILURE
        }
    }
}

fn extract_baseline(args: &ExtractArgs) -> Result<()> {
    let (name, model) = args.source.model()?;
    let mesh = model.mesh();
    let mut source = make_source(args.method, &model, &mesh)?;
    let lod = args
        .level
        .resolve(source.as_ref())?
        .context("give --lod, --triangles or --ratio")?;
    // Each timed change starts from a fresh source (no coherence).
    let mut times = Vec::with_capacity(args.repeat.max(1));
    for _ in 0..args.repeat.max(1) {
        source = make_source(args.method, &model, &mesh)?;
        let t = Instant::now();
        source.set_lod(lod);
        times.push(t.elapsed().as_secs_f64() * 1e6);
    }
    times.sort_by(f64::total_cmp);
    let us = times[times.len() / 2];
    let triangles = source.triangles();
    if let Some(out) = &args.output {
        let m = Mesh::level(&mesh.positions, &triangles, &Default::default());
        mts::mesh::io::save_mesh(&m, out)?;
    }
    let method = source.name();
    if args.json {
        outln!(
            "{}",
            json!({
                "input": name,
                "method": method,
                "lod": lod,
                "max_lod": source.max_lod(),
                "triangles": triangles.len(),
                "indices": source.indices().len(),
                "indices_per_triangle": source.indices().len() as f64 / triangles.len().max(1) as f64,
                "us": us,
            })
        )?;
    } else {
        outln!(
            "{name}: {method} LoD {lod} of {}: {} triangles, {} indices sent, set in {us:.1} us (median of {} from a fresh source)",
            source.max_lod(),
            triangles.len(),
            source.indices().len(),
            times.len()
        )?;
    }
    Ok(())
}

#[derive(Args)]
struct EncodeArgs {
    #[command(flatten)]
    source: MeshSource,
    /// The stream file to write.
    #[arg(short, long)]
    output: PathBuf,
    /// Print JSON instead of a sentence.
    #[arg(long)]
    json: bool,
}

/// The raw mesh with 16-bit indices (12 bytes per vertex, 6 per
/// triangle) plus its property values, so that a method carrying
/// properties is compared with a raw mesh carrying them too.
fn raw_bytes_u16(mesh: &Mesh) -> usize {
    mesh.raw_bytes_u16() + mesh.properties.bytes_per_vertex() * mesh.vertex_count()
}

/// What [`raw_bytes_u16`] adds per vertex, for the sentences that say
/// how raw is counted (nothing without properties).
fn with_properties(mesh: &Mesh) -> String {
    match mesh.properties.bytes_per_vertex() {
        0 => String::new(),
        b => format!(" and {b} of properties"),
    }
}

fn encode(args: &EncodeArgs) -> Result<()> {
    args.source.check_output(&args.output)?;
    let (name, mesh, _) = args.source.load()?;
    let t = Instant::now();
    let tree = mts::baselines::ClusterTree::new(&mesh)?;
    let bytes = tree.to_stream();
    let ms = t.elapsed().as_secs_f64() * 1e3;
    mts::output::write_file(&args.output, &bytes)?;
    let raw = raw_bytes_u16(&mesh);
    if args.json {
        outln!(
            "{}",
            json!({
                "input": name,
                "vertices": mesh.vertex_count(),
                "triangles": mesh.triangle_count(),
                "bytes": bytes.len(),
                "raw_bytes_u16": raw,
                "ratio": bytes.len() as f64 / raw as f64,
                "ms": ms,
            })
        )?;
    } else {
        outln!(
            "{name}: {} vertices, {} triangles -> {} bytes = {:.1}% of raw ({raw} bytes: 12 per vertex{} + 6 per triangle), {ms:.0} ms -> {}",
            mesh.vertex_count(),
            mesh.triangle_count(),
            bytes.len(),
            100.0 * bytes.len() as f64 / raw as f64,
            with_properties(&mesh),
            args.output.display()
        )?;
    }
    Ok(())
}

#[derive(Args)]
struct DecodeArgs {
    /// The stream file.
    stream: PathBuf,
    /// Decode only the first N bytes (the packets they hold completely).
    #[arg(allow_negative_numbers = true, long)]
    bytes: Option<usize>,
    /// Write the decoded mesh (.obj, .ply, .glb or .gltf, by extension).
    #[arg(short, long)]
    output: Option<PathBuf>,
    /// Print JSON instead of a sentence.
    #[arg(long)]
    json: bool,
}

fn decode(args: &DecodeArgs) -> Result<()> {
    use mts::baselines::cluster::stream;
    if let Some(out) = &args.output {
        check_output(out, &[&args.stream])?;
    }
    let all = mts::mesh::io::read_file(&args.stream)?;
    let file = args.stream.display().to_string();
    let t = Instant::now();
    // A prefix shorter than the file is decoded as far as it goes; the
    // whole file is decoded strictly (checksum and all) however it was asked.
    let d = match args.bytes {
        Some(n) if n < all.len() => stream::decode_prefix(&all[..n], &file)?,
        _ => stream::decode(&all, &file)?,
    };
    let ms = t.elapsed().as_secs_f64() * 1e3;
    let mesh = d.mesh();
    mesh.validate()?;
    if let Some(out) = &args.output {
        mts::mesh::io::save_mesh(&mesh, out)?;
    }
    if args.json {
        outln!(
            "{}",
            json!({
                "input": file,
                "bytes_read": args.bytes.unwrap_or(all.len()).min(all.len()),
                "bytes_used": d.bytes_used,
                "vertices": d.positions.len(),
                "triangles": d.triangles.len(),
                "total_vertices": d.total_vertices,
                "total_triangles": d.total_triangles,
                "complete": d.is_complete(),
                "ms": ms,
            })
        )?;
    } else {
        outln!(
            "{file}: {} of {} vertices and {} of {} triangles from {} bytes ({}), {ms:.1} ms",
            d.positions.len(),
            d.total_vertices,
            d.triangles.len(),
            d.total_triangles,
            d.bytes_used,
            if d.is_complete() {
                "complete"
            } else {
                "partial"
            }
        )?;
    }
    Ok(())
}

#[derive(Args)]
struct CompareArgs {
    #[command(flatten)]
    source: MeshSource,
    /// Requests in each sequence (linear, exponential, random; 1 to 10
    /// million).
    #[arg(long, default_value_t = 100, value_parser = count_in::<1, MAX_REQUESTS>, allow_negative_numbers = true)]
    requests: usize,
    /// Print JSON instead of a table.
    #[arg(long)]
    json: bool,
}

/// Every method (MTS and the baselines) over the same mesh and contraction
/// sequence, measured in one run: build milliseconds (MTS: `mts_ms`, the
/// whole pipeline; the baselines: their own construction from the mesh and
/// MTS's sequence), bytes in memory and on disk, and microseconds per LoD
/// change over the Table 2 sequences of `requests` requests each.
fn measure_methods(
    model: &mts::MtsModel,
    mesh: &Mesh,
    mts_ms: f64,
    requests: usize,
) -> Result<Vec<MethodRow>> {
    use mts::model::sequence;
    let raw = raw_bytes_u16(mesh);
    let mut rows = Vec::new();
    for method in Method::ALL {
        if method == Method::Discrete {
            if let Some(why) = peers::meshopt::refusal(mesh) {
                rows.push(MethodRow::Skipped {
                    method: "discrete".into(),
                    skipped: why,
                });
                continue;
            }
        }
        let t = Instant::now();
        let mut source = make_source(method, model, mesh)?;
        // The baselines start from the contraction sequence MTS recorded;
        // its time is MTS's simplify stage, counted in MTS's build.
        let build_ms =
            t.elapsed().as_secs_f64() * 1e3 + if method == Method::Mts { mts_ms } else { 0.0 };
        let max_lod = source.max_lod();
        let counts: Vec<u32> = (0..=max_lod)
            .map(|l| source.triangle_count(l) as u32)
            .collect();
        let sequences = sequence::table2(&counts, requests);
        let mut us = BTreeMap::new();
        for (label, lods) in &sequences {
            source.set_lod(max_lod);
            let t = Instant::now();
            for &l in lods {
                source.set_lod(l);
            }
            let per = t.elapsed().as_secs_f64() * 1e6 / lods.len().max(1) as f64;
            us.insert((*label).to_string(), per);
        }
        // MTS from scratch: the same requests, every strip walked each time.
        let scratch = (method == Method::Mts).then(|| {
            let mut ex = mts::Extractor::new(model);
            sequences
                .iter()
                .map(|(label, lods)| {
                    ex.set_lod_from_scratch(max_lod);
                    let t = Instant::now();
                    for &l in lods {
                        ex.set_lod_from_scratch(l);
                    }
                    let per = t.elapsed().as_secs_f64() * 1e6 / lods.len().max(1) as f64;
                    ((*label).to_string(), per)
                })
                .collect::<BTreeMap<_, _>>()
        });
        let file = source.file_bytes();
        let load_ms = load_ms_of(method, model, mesh)?;
        rows.push(MethodRow::Measured(results::Method {
            method: source.name().to_string(),
            build_ms,
            memory_bytes: source.memory_bytes() as u64,
            file_bytes: file as u64,
            file_ratio_to_raw_u16: file as f64 / raw as f64,
            load_ms,
            us_per_change: us,
            us_per_change_scratch: scratch,
        }));
    }
    Ok(rows)
}

/// Median milliseconds (of 5) from a method's file bytes in memory to a
/// source ready for its first LoD: MTS parses and validates its ready
/// `.mts` and makes an extractor; the progressive mesh parses its file; the
/// cluster tree decodes its whole packet stream (its receiver). `None` for
/// the methods without a file reader (multilevel, discrete LoDs).
fn load_ms_of(method: Method, model: &mts::MtsModel, mesh: &Mesh) -> Result<Option<f64>> {
    use mts::baselines::{cluster, ClusterTree, ProgressiveMesh};
    // Median of 5 loads of the same bytes (so an error is every run's).
    let timed = |mut load: Box<dyn FnMut() -> mts::Result<()> + '_>| -> Result<Option<f64>> {
        let (results, ms) = median_ms(5, &mut load);
        results?;
        Ok(Some(ms))
    };
    match method {
        Method::Mts => {
            let bytes = model.to_bytes();
            timed(Box::new(move || {
                let m = mts::MtsModel::from_bytes(&bytes, std::path::Path::new("model.mts"))?;
                std::hint::black_box(mts::Extractor::new(&m).buffer().len());
                Ok(())
            }))
        }
        Method::Pm => {
            let bytes = ProgressiveMesh::new(mesh, model.collapses())?.to_bytes();
            timed(Box::new(move || {
                ProgressiveMesh::from_bytes(&bytes, "model.pm").map(drop)
            }))
        }
        Method::Cluster => {
            let bytes = ClusterTree::new(mesh)?.to_stream();
            timed(Box::new(move || {
                cluster::stream::decode(&bytes, "model.stream").map(drop)
            }))
        }
        Method::Multilevel | Method::Discrete => Ok(None),
    }
}

fn compare(args: &CompareArgs) -> Result<()> {
    let (name, mesh, _) = args.source.load()?;
    let t = Instant::now();
    let (model, _, _) = build_with_bar(&mesh, &Default::default())?;
    let mts_ms = t.elapsed().as_secs_f64() * 1e3;
    let raw = raw_bytes_u16(&mesh);
    let rows = measure_methods(&model, &mesh, mts_ms, args.requests)?;
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
