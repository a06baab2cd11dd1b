//! `mts bench`: the MTS paper's tables measured on this machine, written as
//! `report.md` and `results.json` (schema in `docs/bench-schema.md`).
//!
//! Every figure of a row is measured in the same run as the figures it is
//! compared with. Timings are medians of a few repetitions; the machine
//! section names the CPU they come from.

use crate::results::{
    BuildMs, Bytes, Distance, Extraction, FastSimplification, FastSimplificationRun, Figure6Row,
    Level, Machine, MethodRow, Model, PeerDistance, PropertyRow, PropertySide, Quality, Results,
    Scale, ScaleExponent, ScaleRow, Scene, Simplify, StripRow, Stripify,
};
use anyhow::{Context, Result};
use mts::model::{build_from_mesh, sequence, PipelineOptions};
use mts::peers;
use mts::strip::acmr::{fifo_acmr, CACHE_SIZE};
use mts::strip::stats::StripStats;
use mts::{Extractor, Mesh, MtsModel, SimplifyOptions, StripifyOptions};
use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// Version of `results.json`'s layout (`docs/bench-schema.md`).
pub const SCHEMA_VERSION: u32 = 6;

/// Shares of the full triangle count reported in Tables 3–4.
const SHARES: [f64; 6] = mts::methods::SHARES;
/// Shares at which simplification quality is measured.
const QUALITY_SHARES: [f64; 2] = [0.1, 0.01];
/// Requests per Table 2 sequence (the full run; `--quick` uses fewer).
const REQUESTS: usize = 1000;
const QUICK_REQUESTS: usize = 200;
/// Generated sizes of the scale section (triangles).
const SCALE_SIZES: [&str; 6] = ["10k", "40k", "160k", "640k", "1M", "4M"];
/// Surface samples per side for the quality section.
const SAMPLES: usize = 100_000;
/// Timed runs of the stripifiers and simplifiers per model (medians);
/// `--quick` uses fewer.
const STAGE_REPEAT: usize = 7;
const QUICK_STAGE_REPEAT: usize = 3;
/// Instances of the scene rows (Figure 6's adapter) and their pixel
/// thresholds, and with `--quick`.
const SCENE_INSTANCES: [usize; 3] = [1_000, 10_000, 100_000];
const SCENE_THRESHOLDS: [f32; 3] = [0.5, 1.0, 2.0];
const QUICK_SCENE_INSTANCES: [usize; 1] = [250];
const QUICK_SCENE_THRESHOLDS: [f32; 1] = [1.0];
/// Models of the scene, in this order where measured (then the others),
/// at most [`SCENE_MODELS`].
const SCENE_PREFERRED: [&str; 8] = [
    "bunny.ply",
    "armadillo.obj",
    "spot.obj",
    "cow.obj",
    "teapot.obj",
    "fandisk.obj",
    "homer.obj",
    "rocker_arm.obj",
];
const SCENE_MODELS: usize = 8;

/// What to measure.
pub struct BenchOptions {
    /// Meshes to measure (files); empty with `quick` means the built-in one.
    pub models: Vec<PathBuf>,
    /// The built-in mesh only, fewer requests, no scale section.
    pub quick: bool,
    /// The command line, for the report.
    pub command: String,
    /// Measure Figure 6 (frames per second) with the headless renderer.
    pub render: bool,
}

/// Shares of Figure 6, and its timed frames per point.
const FIGURE6_SHARES: [f64; 6] = mts::methods::SHARES;
const QUICK_FIGURE6_SHARES: [f64; 3] = [1.0, 0.25, 0.05];
const FIGURE6_FRAMES: usize = 10;
const QUICK_FIGURE6_FRAMES: usize = 4;

/// The headless renderer of Figure 6, when the build and the machine have
/// one; otherwise why not.
type Figure6 = std::result::Result<super::figure6::Renderer, String>;

fn figure6_renderer(wanted: bool) -> Figure6 {
    if !wanted {
        return Err("not asked for (--no-render)".into());
    }
    super::figure6::Renderer::new().map_err(|e| format!("no adapter: {e:#}"))
}

/// Runs every section and returns what `results.json` holds (`elapsed_s`:
/// this call's wall-clock seconds); `progress` is told what is being
/// measured.
///
/// # Errors
/// When a model cannot be loaded or built into a renderer's buffers, or a
/// measurement cannot be read (peak memory, the fast-simplification
/// peer's rows).
pub fn run(options: &BenchOptions, progress: &dyn Fn(&str)) -> Result<Results> {
    let started = Instant::now();
    let mut models = Vec::new();
    let mut inputs: Vec<(String, Mesh)> = Vec::new();
    if options.models.is_empty() {
        let g = mts::mesh::generate::Generated::DEFAULT;
        inputs.push((format!("generated {g}"), g.build()));
    }
    for path in &options.models {
        let (mesh, _) = mts::mesh::io::load(path, Default::default())
            .with_context(|| format!("cannot load {}", path.display()))?;
        let name = path.file_name().map_or_else(
            || path.display().to_string(),
            |n| n.to_string_lossy().into(),
        );
        // Every section compares with meshoptimizer: a mesh where its time
        // is quadratic is left out, as every other command does.
        if let Some(why) = peers::meshopt::refusal(&mesh) {
            progress(&format!("{name} skipped: {why}"));
            continue;
        }
        inputs.push((name, mesh));
    }
    let requests = if options.quick {
        QUICK_REQUESTS
    } else {
        REQUESTS
    };
    let renderer = figure6_renderer(options.render);
    let (shares, frames): (&[f64], usize) = if options.quick {
        (&QUICK_FIGURE6_SHARES, QUICK_FIGURE6_FRAMES)
    } else {
        (&FIGURE6_SHARES, FIGURE6_FRAMES)
    };
    let repeat = if options.quick {
        QUICK_STAGE_REPEAT
    } else {
        STAGE_REPEAT
    };
    // The scene's models: the preferred ones measured, then the others.
    let mut scene_names: Vec<&String> = SCENE_PREFERRED
        .iter()
        .filter_map(|p| inputs.iter().map(|(n, _)| n).find(|n| n == p))
        .collect();
    for (n, _) in &inputs {
        if !scene_names.contains(&n) {
            scene_names.push(n);
        }
    }
    scene_names.truncate(SCENE_MODELS);
    let mut scene_models = Vec::new();
    // The vertex-work model: the scene's first (the bunny when measured).
    let vertex_name = scene_names.first().map(|n| (*n).clone());
    let mut vertex_work = None;
    for (name, mesh) in &inputs {
        progress(name);
        let (row, model) = measure_model(name, mesh, requests, repeat, &renderer, shares, frames)?;
        models.push(row);
        if let (Ok(r), true) = (&renderer, vertex_name.as_ref() == Some(name)) {
            progress(&format!("vertex work of {name}"));
            vertex_work = Some(r.measure_vertex_work(name, &model)?);
        }
        if scene_names.contains(&name) {
            scene_models.push((name.clone(), model));
        }
    }
    let scenes = measure_scenes(&scene_models, options.quick, frames, &renderer, progress)?;
    drop(scene_models);
    let scale = if options.quick {
        None
    } else {
        progress("scale");
        Some(measure_scale(progress)?)
    };
    let machine = machine(&renderer);
    let fast_simplification = if options.quick {
        None
    } else {
        progress("fast-simplification");
        Some(fast_simplification(&options.models)?)
    };
    progress("properties");
    let properties = measure_properties(&options.models, options.quick, &renderer)?;
    Ok(Results {
        schema: SCHEMA_VERSION,
        command: options.command.clone(),
        elapsed_s: started.elapsed().as_secs_f64(),
        quick: options.quick,
        machine,
        models,
        scale,
        fast_simplification,
        scenes,
        vertex_work,
        properties,
    })
}

/// The report's measured vertex work: the adapter's counts beside the
/// cache models' predictions for the buffers it drew.
fn vertex_table(s: &mut String, w: Option<&crate::results::VertexWork>) {
    let Some(w) = w else {
        return;
    };
    let _ = writeln!(
        s,
        "\n### Vertex work measured by the adapter: {}\n",
        w.model
    );
    let _ = writeln!(s, "Pipeline-statistics queries on Figure 6's adapter (`mts bench render`): vertex-shader invocations per triangle drawn, beside the invocations the cache models predict for the same index buffer (FIFO of 16, batches of 96 and 384 indices, LRU of 32, and LRU of 32 emptied at every primitive restart; per triangle), clipper primitives against the triangles drawn (degenerate strip windows included where the clipper counts them) and the pass's GPU time (timestamps, median of 5). Methods: MTS strips as the backend draws them (`mts_strips`) and stitched into one run by degenerate triangles (`mts_stitched`), the same model built with cache-aware bands (`mts_cache_aware`), meshoptimizer's strips, the cache-aware stripifier on the level's triangles (`cache_aware_strips`, and its runs stitched into one by degenerate triangles: `cache_aware_stitched`), the meshoptimizer-ordered list, the list in the oracle's order, and the baselines' lists at their finest LoD within the same triangles.\n");
    if let Some(note) = &w.note {
        let _ = writeln!(s, "Not measured: {note}.\n");
    }
    let _ = writeln!(s, "| share | method | triangles | indices | measured / triangle | FIFO16 | batch96 | batch384 | LRU32 | LRU32 per run | clipper (assembled) | GPU ms |");
    let _ = writeln!(s, "|---|---|---|---|---|---|---|---|---|---|---|---|");
    let opt =
        |x: Option<f64>, digits: usize| x.map_or("—".to_string(), |x| format!("{x:.digits$}"));
    for r in &w.rows {
        let per = |name: &str| {
            let m = r.modelled.get(name).copied().unwrap_or(0);
            format!("{:.3}", m as f64 / r.triangles.max(1) as f64)
        };
        let _ = writeln!(
            s,
            "| {:.0}% | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} ({}) | {} |",
            r.ratio * 100.0,
            r.method,
            r.triangles,
            r.indices_sent,
            opt(r.invocations_per_triangle, 3),
            per("fifo16"),
            per("batch96"),
            per("batch384"),
            per("lru32"),
            per("lru32_run"),
            r.clipper_invocations
                .map_or("—".to_string(), |c| c.to_string()),
            r.primitives_assembled,
            opt(r.gpu_ms, 2),
        );
    }
    let fits: Vec<String> = w
        .model_fit
        .iter()
        .filter_map(|(n, f)| {
            f.map(|f| {
                format!(
                    "{n} {:.3} (spread {:.3})",
                    f.ratio_geomean, f.mean_abs_log_ratio
                )
            })
        })
        .collect();
    if !fits.is_empty() {
        let _ = writeln!(
            s,
            "\nMeasured / modelled invocations, geometric mean over the rows (spread: mean |ln ratio|): {}; the best fit here: {}. Rows whose clipper count differs from the triangles drawn: {}.",
            fits.join(", "),
            w.best_model.as_deref().unwrap_or("—"),
            w.clipper_mismatches
        );
    }
}

/// The report's section on the scene.
fn scene_table(s: &mut String, rows: &[Scene]) {
    let Some(first) = rows.first() else {
        return;
    };
    let _ = writeln!(
        s,
        "\n## Scene: many instances of several models, LoD by screen-space error, shared buffers\n"
    );
    let _ = writeln!(s, "`mts bench render --scene`'s rows on Figure 6's adapter: instances of {} ({}) scaled to one radius on a ground plane, {}×{} pixels, a camera flying through the field ({} frames). Each visible instance gets the coarsest LoD whose recorded error projects within the threshold, and draws the shared buffer of its LoD bucket (10% fewer triangles a bucket), one instanced draw per (model, bucket). Update: cull, LoD choice, extractions, uploads; frame: update and draw. GPU: peak bucket buffers and transforms, against the sum of the models' full-detail strip buffers. Image: pixels covered by instances that differ at all from the same frame at full detail ({} frames of the path).\n", first.models, first.model_names.join(", "), first.width, first.height, first.frames, first.compared_frames);
    let _ = writeln!(s, "{}", scene_table_head());
    for r in rows {
        let _ = writeln!(s, "{}", scene_table_row(r));
    }
}

/// The head of the scene table (the report's, and `mts bench render
/// --scene`'s text).
pub fn scene_table_head() -> String {
    format!("| instances | px | visible | triangles (share of full) | draws | extractions / frame | update ms median / p99 | frame ms | CPU B / instance | GPU MB (× full strips) | buffers | pixels differing (by > {}/255; in coverage) |\n|---|---|---|---|---|---|---|---|---|---|---|---|", super::figure6::IMAGE_TOLERANCE)
}

/// One scene row of [`scene_table_head`]'s table.
pub fn scene_table_row(r: &Scene) -> String {
    let share = |x: Option<f64>| x.map_or("—".into(), |x| format!("{:.3}%", 100.0 * x));
    format!(
        "| {} | {} | {:.0} | {:.0} ({:.2}%) | {:.1} | {:.2} | {:.2} / {:.2} | {:.1} | {} | {:.2} ({:.2}×) | {} | {} ({}; {}) |",
        r.instances,
        r.pixel_threshold,
        r.visible,
        r.triangles_drawn,
        100.0 * r.triangles_drawn / r.triangles_full_detail.max(1.0),
        r.draws,
        r.extractions_per_frame,
        r.update_ms_median,
        r.update_ms_p99,
        r.frame_ms_median,
        r.cpu_bytes_per_instance,
        r.gpu_bytes as f64 / 1e6,
        r.gpu_bytes as f64 / r.full_detail_strip_bytes.max(1) as f64,
        r.buffers,
        share(r.differing_pixel_share),
        share(r.visibly_differing_pixel_share),
        share(r.coverage_differing_pixel_share),
    )
}

/// The report's section on vertex properties.
fn property_table(s: &mut String, rows: &[PropertyRow]) {
    let _ = writeln!(
        s,
        "\n## Vertex properties against meshoptimizer's `simplifyWithAttributes`\n"
    );
    let _ = writeln!(s, "Models loaded with `--properties` (UV and normal seams kept) and the generated `{PROPERTY_MESH}` with UVs, normals and colours; meshoptimizer's `simplifyWithAttributes` (normals 1, UV 30, colours 1) at the same triangle count. Geometric error relative to the diagonal; property error sampled like it at corresponding points, both directions pooled: UV distance, normal angle in degrees, RGBA distance (RMS; `docs/experiments/properties.md`).\n");
    let _ = writeln!(s, "Image: the LoD drawn with the model's properties (the checker texture where it has UVs, `mts render --checker`) from the fixed camera that frames it, against the full model drawn alike: share of the model's pixels whose colour moved by more than {} of 255, and the RMS RGB difference.\n", super::figure6::IMAGE_TOLERANCE);
    let _ = writeln!(s, "| model | share | triangles (mts / meshopt) | Hausdorff mts / meshopt | RMS mts / meshopt | UV mts / meshopt | normal° mts / meshopt | colour mts / meshopt | image pixels changed mts / meshopt | image RMS mts / meshopt |");
    let _ = writeln!(s, "|---|---|---|---|---|---|---|---|---|---|");
    let pair = |a: Option<f64>, b: Option<f64>, digits: usize| match (a, b) {
        (Some(a), Some(b)) => format!("{a:.digits$} / {b:.digits$}"),
        _ => "—".to_string(),
    };
    for r in rows {
        let (m, o) = (&r.mts, &r.meshopt);
        let _ = writeln!(
            s,
            "| {} | {:.0}% | {} / {} | {:.5} / {:.5} | {:.5} / {:.5} | {} | {} | {} | {} | {} |",
            r.model,
            r.share * 100.0,
            m.triangles,
            o.triangles,
            m.hausdorff,
            o.hausdorff,
            m.rms,
            o.rms,
            pair(m.uv_rms, o.uv_rms, 4),
            pair(m.normal_degrees_rms, o.normal_degrees_rms, 1),
            pair(m.color_rms, o.color_rms, 4),
            match (m.image_differing_share, o.image_differing_share) {
                (Some(a), Some(b)) => format!("{:.1}% / {:.1}%", 100.0 * a, 100.0 * b),
                _ => "—".to_string(),
            },
            pair(m.image_rms, o.image_rms, 4),
        );
    }
}

/// The generated mesh with properties every run measures (UV seams,
/// normals, colours).
const PROPERTY_MESH: &str = "torus:20k";

/// Vertex properties: every model of `models` that has some (loaded with
/// `--properties`; none with `--quick`) and the generated torus, at 10%
/// and 1%, against meshoptimizer's `simplifyWithAttributes` at the same
/// triangle count (where it stops above ours, ours at its count).
///
/// # Errors
/// When a model cannot be loaded.
fn measure_properties(
    models: &[PathBuf],
    quick: bool,
    renderer: &Figure6,
) -> Result<Vec<PropertyRow>> {
    use mts::distance::{property_error, surface_distance};
    use mts::peers::meshopt::{simplify_with_attributes_to_lod, AttributeWeights};
    let g: mts::mesh::generate::Generated = PROPERTY_MESH.parse().expect("a valid generated name");
    let mut inputs = vec![(
        format!("generated {PROPERTY_MESH}"),
        g.build_with_properties(),
    )];
    let options = mts::mesh::io::LoadOptions {
        properties: true,
        ..Default::default()
    };
    for path in models.iter().filter(|_| !quick) {
        let (mesh, _) = mts::mesh::io::load(path, options)
            .with_context(|| format!("cannot load {}", path.display()))?;
        if mesh.properties.is_empty() || peers::meshopt::refusal(&mesh).is_some() {
            continue;
        }
        let name = path.file_name().map_or_else(
            || path.display().to_string(),
            |n| n.to_string_lossy().into(),
        );
        inputs.push((name, mesh));
    }
    let mut rows = Vec::new();
    for (name, mesh) in &inputs {
        let c = mts::simplify(mesh, &Default::default()).collapses;
        for &share in &QUALITY_SHARES {
            let (theirs, lod) = simplify_with_attributes_to_lod(
                mesh,
                &c,
                c.lod_for_ratio(share),
                AttributeWeights::default(),
            );
            let ours_triangles = c.triangles_at(mesh, lod);
            let images = match renderer {
                Ok(r) => r
                    .image_differences(mesh, &[&ours_triangles, &theirs])?
                    .into_iter()
                    .map(Some)
                    .collect(),
                Err(_) => vec![None, None],
            };
            let ours = c.mesh_at(mesh, lod);
            let theirs = Mesh {
                triangles: theirs,
                ..mesh.clone()
            };
            let side = |lod: &Mesh, image: Option<mts_render::Difference>| {
                let d = surface_distance(mesh.into(), lod.into(), SAMPLES);
                let p = property_error(mesh, lod, SAMPLES);
                PropertySide {
                    triangles: lod.triangle_count() as u64,
                    hausdorff: d.hausdorff,
                    rms: d.rms,
                    uv_rms: p.uv.map(|s| s.rms),
                    normal_degrees_rms: p.normal_degrees.map(|s| s.rms),
                    color_rms: p.color.map(|s| s.rms),
                    image_differing_share: image.map(|i| i.share),
                    image_rms: image.map(|i| i.rms),
                }
            };
            rows.push(PropertyRow {
                model: name.clone(),
                share,
                mts: side(&ours, images[0]),
                meshopt: side(&theirs, images[1]),
            });
        }
    }
    Ok(rows)
}

/// The fast-simplification peer (`crates/mts-cli/peers/fast_simplification.py`)
/// at 10% and 1% of every model, its error measured by this binary's `mts
/// distance`: one row per model and share, or why there are none (Python
/// or the package missing: `pip install fast-simplification numpy`).
///
/// # Errors
/// When the script prints a JSON line that is not a row's layout.
fn fast_simplification(models: &[PathBuf]) -> Result<FastSimplificationRun> {
    let skipped = |why: &str| {
        Ok(FastSimplificationRun::Skipped {
            skipped: why.to_string(),
        })
    };
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("peers/fast_simplification.py");
    let Ok(exe) = std::env::current_exe() else {
        return skipped("cannot find this binary for `mts distance`");
    };
    if models.is_empty() {
        return skipped("no model files");
    }
    let out = std::process::Command::new("python3")
        .arg(&script)
        .args(["--ratios", "0.1,0.01", "--repeat", "1", "--mts"])
        .arg(&exe)
        .args(models)
        .output();
    let o = match out {
        Err(e) => return skipped(&format!("python3: {e}")),
        Ok(o) if !o.status.success() => {
            return skipped(
                String::from_utf8_lossy(&o.stderr)
                    .lines()
                    .last()
                    .unwrap_or("failed"),
            )
        }
        Ok(o) => o,
    };
    let mut rows = Vec::new();
    for line in String::from_utf8_lossy(&o.stdout).lines() {
        let mut row: FastSimplification = match serde_json::from_str(line) {
            Ok(row) => row,
            // A line that is not JSON (something the package printed) is
            // no row; a JSON line of another layout is the script's bug.
            Err(e) if e.is_syntax() || e.is_eof() => continue,
            Err(e) => anyhow::bail!(
                "{}: a row of another layout ({e}): {line}",
                script.display()
            ),
        };
        // The file name, as the models' rows name them.
        if let Some(name) = Path::new(&row.mesh).file_name() {
            row.mesh = name.to_string_lossy().into_owned();
        }
        rows.push(row);
    }
    Ok(FastSimplificationRun::Rows(rows))
}

/// CPU, cores and system of this machine, and the graphics adapter of
/// Figure 6 (`None` when none ran, with the reason in `adapter_note`).
fn machine(renderer: &Figure6) -> Machine {
    let cpu = std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("model name"))
                .and_then(|l| l.split(':').nth(1))
                .map(|s| s.trim().to_string())
        })
        .unwrap_or_else(|| "unknown".into());
    let os = std::fs::read_to_string("/etc/os-release")
        .ok()
        .and_then(|s| {
            s.lines().find(|l| l.starts_with("PRETTY_NAME=")).map(|l| {
                l.trim_start_matches("PRETTY_NAME=")
                    .trim_matches('"')
                    .to_string()
            })
        })
        .unwrap_or_else(|| std::env::consts::OS.into());
    let cores = std::thread::available_parallelism().map_or(1, std::num::NonZeroUsize::get);
    Machine {
        cpu,
        cores: u32::try_from(cores).unwrap_or(u32::MAX),
        os,
        adapter: renderer
            .as_ref()
            .ok()
            .map(super::figure6::Renderer::adapter),
        adapter_note: renderer.as_ref().err().cloned(),
    }
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// Median over `repeat` runs of `f`, in microseconds.
fn time_us(repeat: usize, mut f: impl FnMut()) -> f64 {
    median(
        (0..repeat.max(1))
            .map(|_| {
                let t = Instant::now();
                f();
                t.elapsed().as_secs_f64() * 1e6
            })
            .collect(),
    )
}

/// The scene rows: [`SCENE_INSTANCES`] instances of `models` at each of
/// [`SCENE_THRESHOLDS`] (fewer with `--quick`) on Figure 6's adapter,
/// `frames` frames along the camera path; none without an adapter.
///
/// # Errors
/// As [`super::bench_render::scene_row`].
fn measure_scenes(
    models: &[(String, MtsModel)],
    quick: bool,
    frames: usize,
    renderer: &Figure6,
    progress: &dyn Fn(&str),
) -> Result<Vec<Scene>> {
    let (counts, thresholds): (&[usize], &[f32]) = if quick {
        (&QUICK_SCENE_INSTANCES, &QUICK_SCENE_THRESHOLDS)
    } else {
        (&SCENE_INSTANCES, &SCENE_THRESHOLDS)
    };
    let (Ok(r), false) = (renderer, models.is_empty()) else {
        return Ok(Vec::new());
    };
    let refs: Vec<(String, &MtsModel)> = models.iter().map(|(n, m)| (n.clone(), m)).collect();
    let mut rows = Vec::new();
    for &instances in counts {
        progress(&format!(
            "scene of {instances} instances of {} models at {thresholds:?} px",
            models.len()
        ));
        let spec = super::bench_render::SceneSpec {
            instances,
            pixel_errors: thresholds,
            frames,
            compared_frames: super::bench_render::SCENE_COMPARED_FRAMES,
        };
        rows.extend(r.measure_scene(&refs, &spec)?);
    }
    Ok(rows)
}

/// Medians of `repeat` interleaved runs of `a` and `b` (so that a drift of
/// the machine's speed hits both alike), in milliseconds, with the last
/// results.
fn interleaved_ms<A, B>(
    repeat: usize,
    mut a: impl FnMut() -> A,
    mut b: impl FnMut() -> B,
) -> ((A, f64), (B, f64)) {
    let (mut ta, mut tb) = (Vec::new(), Vec::new());
    let (mut ra, mut rb) = (None, None);
    for _ in 0..repeat.max(1) {
        let t = Instant::now();
        ra = Some(a());
        ta.push(t.elapsed().as_secs_f64() * 1e3);
        let t = Instant::now();
        rb = Some(b());
        tb.push(t.elapsed().as_secs_f64() * 1e3);
    }
    (
        (ra.expect("one run"), median(ta)),
        (rb.expect("one run"), median(tb)),
    )
}

/// The project's stripifier against meshoptimizer's on `mesh` (the `mts
/// strips` row): both strip sets' figures and median milliseconds; the
/// cache-aware option beside them, and the modelled vertex work of the
/// meshoptimizer-ordered list it competes with.
fn measure_stripify(mesh: &Mesh, repeat: usize) -> Stripify {
    let options = StripifyOptions::default();
    let ((ours, ms), (theirs, their_ms)) = interleaved_ms(
        repeat,
        || mts::stripify(mesh, &options),
        || peers::meshopt::stripify(mesh),
    );
    let cache_aware = StripifyOptions {
        cache_aware: true,
        ..options
    };
    let ((aware, aware_ms), (list, _)) = interleaved_ms(
        repeat,
        || mts::stripify(mesh, &cache_aware),
        || peers::meshopt::optimize_vertex_cache(&mesh.triangles, mesh.vertex_count()),
    );
    let (list_acmr, list_acmr_batch96) =
        mts::strip::vertex_work::list_fifo16_batch96(&list, mesh.vertex_count());
    Stripify {
        mts: StripRow::from(&StripStats::new(&ours, ms)),
        meshopt: StripRow::from(&StripStats::new(&theirs, their_ms)),
        cache_aware: StripRow::from(&StripStats::new(&aware, aware_ms)),
        list_acmr,
        list_acmr_batch96,
    }
}

/// The whole contraction sequence (default options) against
/// meshoptimizer's `simplify` to 10% and to 1% of the triangles, median
/// milliseconds of interleaved runs.
fn measure_simplify(mesh: &Mesh, repeat: usize) -> Simplify {
    let n = mesh.triangle_count();
    let ((whole, ms), (_, to_10)) = interleaved_ms(
        repeat,
        || mts::simplify(mesh, &SimplifyOptions::default()),
        || peers::meshopt::simplify(mesh, n / 10),
    );
    let to_1 = time_us(1, || {
        std::hint::black_box(peers::meshopt::simplify(mesh, n / 100));
    }) / 1e3;
    Simplify {
        ms,
        max_lod: whole.collapses.max_lod() as u64,
        stop: whole.stop.to_string(),
        meshopt_ms_to_10: to_10,
        meshopt_ms_to_1: to_1,
    }
}

#[allow(clippy::too_many_arguments)]
fn measure_model(
    name: &str,
    mesh: &Mesh,
    requests: usize,
    repeat: usize,
    renderer: &Figure6,
    shares: &[f64],
    frames: usize,
) -> Result<(Model, MtsModel)> {
    let (model, _, t) = build_from_mesh(mesh, &PipelineOptions::default(), &mut |_, _| {});
    let ms = |d: std::time::Duration| d.as_secs_f64() * 1e3;
    let file_bytes = model.to_bytes().len();
    let stats = model.stats();
    // Struct fields are evaluated as written: the sections run in this
    // order.
    let row = Model {
        name: name.to_string(),
        triangles: mesh.triangle_count() as u64,
        vertices: mesh.vertex_count() as u64,
        strips: model.base_strips().run_count() as u64,
        max_lod: model.max_lod() as u64,
        bands: model.band_count() as u64,
        bytes: Bytes {
            raw: model.raw_bytes() as u64,
            raw_u16: model.raw_bytes_u16() as u64,
            mts_file: file_bytes as u64,
            mts_recipe_file: model.to_recipe_bytes().len() as u64,
            mts_memory: stats.memory_bytes as u64,
        },
        build_ms: BuildMs {
            stripify: ms(t.stripify),
            simplify: ms(t.simplify),
            model: ms(t.model),
            total: ms(t.total),
        },
        stripify: measure_stripify(mesh, repeat),
        simplify: measure_simplify(mesh, repeat),
        extraction: measure_sequences(&model, requests),
        levels: measure_levels(&model),
        quality: measure_quality(mesh, &model),
        methods: super::measure_methods(&model, mesh, ms(t.total), requests)?,
        figure6: match renderer {
            Ok(r) => Some(r.measure(&model, mesh, shares, frames)?),
            Err(_) => {
                let _ = (shares, frames);
                None
            }
        },
    };
    Ok((row, model))
}

/// Table 2: microseconds per LoD change over each sequence, with the
/// coherence cache and from scratch: medians of five passes each, the two
/// interleaved (a drift of the machine's speed hits both alike), each
/// pass from a fresh extractor whose construction is not timed.
fn measure_sequences(model: &MtsModel, requests: usize) -> BTreeMap<String, Extraction> {
    let mut out = BTreeMap::new();
    for (seq, lods) in sequence::table2(model.triangle_counts(), requests) {
        let n = lods.len().max(1) as f64;
        let pass = |coherent: bool| {
            let mut ex = Extractor::new(model);
            let t = Instant::now();
            for &l in &lods {
                if coherent {
                    ex.set_lod(l);
                } else {
                    ex.set_lod_from_scratch(l);
                }
            }
            t.elapsed().as_secs_f64() * 1e6
        };
        let (mut coherent, mut scratch) = (Vec::new(), Vec::new());
        for _ in 0..5 {
            coherent.push(pass(true));
            scratch.push(pass(false));
        }
        let (coherent, scratch) = (median(coherent), median(scratch));
        out.insert(
            seq.into(),
            Extraction {
                requests: lods.len() as u64,
                mts_coherent_us: coherent / n,
                mts_scratch_us: scratch / n,
            },
        );
    }
    out
}

/// Tables 3–4: indices sent at each share — MTS strips (restart values
/// included), the triangle list, meshoptimizer's strips of that level's
/// mesh — with ACMR (16-entry FIFO) of each order.
pub fn measure_levels(model: &MtsModel) -> Vec<Level> {
    let mesh = model.mesh();
    let mut ex = Extractor::new(model);
    let mut compact = Vec::new();
    SHARES
        .iter()
        .map(|&share| {
            let lod = model.lod_for_ratio(share);
            let us = time_us(5, || {
                ex.set_lod_from_scratch(lod);
            });
            ex.write_compact(&mut compact);
            let level = model.collapses().mesh_at(&mesh, lod);
            let mut strip_triangles = Vec::new();
            mts::encoding::decode_restart_buffer(&compact, &mut strip_triangles);
            let vertices = model.positions().len();
            let list_triangles =
                peers::meshopt::optimize_vertex_cache(&level.triangles, level.vertex_count());
            let theirs = peers::meshopt::stripify(&level);
            let triangles = model.triangle_count(lod);
            Level {
                share,
                lod: lod as u64,
                triangles: triangles as u64,
                mts_indices: ex.indices_sent() as u64,
                list_indices: 3 * triangles as u64,
                meshopt_strip_indices: theirs.restart_index_count() as u64,
                mts_acmr: fifo_acmr(&strip_triangles, vertices, CACHE_SIZE),
                list_acmr: fifo_acmr(&list_triangles, level.vertex_count(), CACHE_SIZE),
                meshopt_strip_acmr: fifo_acmr(
                    &theirs.triangles(),
                    level.vertex_count(),
                    CACHE_SIZE,
                ),
                extract_us: us,
            }
        })
        .collect()
}

/// Hausdorff and RMS (relative to the diagonal) of the project's LoD and
/// of meshoptimizer's `simplify` at the same triangle count
/// ([`peers::quality::compare`], as `mts simplify` compares them).
fn measure_quality(mesh: &Mesh, model: &MtsModel) -> Vec<Quality> {
    let ours_mesh = model.mesh();
    QUALITY_SHARES
        .iter()
        .map(|&share| {
            let q = peers::quality::compare(
                mesh,
                model.collapses(),
                model.lod_for_ratio(share),
                SAMPLES,
                |lod| model.collapses().mesh_at(&ours_mesh, lod),
            );
            Quality {
                share,
                mts: Distance {
                    triangles: q.ours.triangle_count as u64,
                    hausdorff: q.ours.distance.hausdorff,
                    rms: q.ours.distance.rms,
                },
                meshopt: PeerDistance {
                    triangles: q.meshopt.triangle_count as u64,
                    hausdorff: q.meshopt.distance.hausdorff,
                    rms: q.meshopt.distance.rms,
                    ms: q.meshopt_ms,
                },
            }
        })
        .collect()
}

/// Peak resident memory of this process so far (Linux), in bytes.
fn peak_rss() -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kb: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb * 1024)
}

/// Build time, memory and extraction time of generated icospheres from
/// 10K to 4M triangles, with the exponent of a power law fitted to each.
///
/// # Errors
/// When the process's peak memory cannot be read (`/proc/self/status`).
fn measure_scale(progress: &dyn Fn(&str)) -> Result<Scale> {
    let mut rows = Vec::new();
    for size in SCALE_SIZES {
        let g: mts::mesh::generate::Generated = format!("icosphere:{size}")
            .parse()
            .expect("a valid generated name");
        progress(&format!("scale icosphere:{size}"));
        let mesh = g.build();
        let (model, _, t) = build_from_mesh(&mesh, &PipelineOptions::default(), &mut |_, _| {});
        let mut ex = Extractor::new(&model);
        let extract_us = time_us(5, || {
            ex.set_lod_from_scratch(0);
        });
        let (model_bytes, rss) = (model.stats().memory_bytes, peak_rss());
        drop(ex);
        let file = model.to_bytes();
        drop(model);
        let load_ms = time_us(3, || {
            let m = mts::MtsModel::from_bytes(&file, std::path::Path::new("scale.mts"))
                .expect("a file just written loads");
            std::hint::black_box(Extractor::new(&m).buffer().len());
        }) / 1e3;
        // Each stage alone (the pipeline runs stripify beside simplify),
        // against meshoptimizer, one run each.
        let ((_, stripify_ms), (_, meshopt_stripify_ms)) = interleaved_ms(
            1,
            || mts::stripify(&mesh, &StripifyOptions::default()),
            || peers::meshopt::stripify(&mesh),
        );
        let n = mesh.triangle_count();
        let ((_, simplify_ms), (_, meshopt_simplify_ms)) = interleaved_ms(
            1,
            || mts::simplify(&mesh, &SimplifyOptions::default()),
            || peers::meshopt::simplify(&mesh, n / 10),
        );
        rows.push(ScaleRow {
            triangles: mesh.triangle_count() as u64,
            stripify_ms,
            meshopt_stripify_ms,
            simplify_ms,
            meshopt_simplify_to_10_ms: meshopt_simplify_ms,
            build_ms: t.total.as_secs_f64() * 1e3,
            model_bytes: model_bytes as u64,
            file_bytes: file.len() as u64,
            load_ms,
            extract_lod0_us: extract_us,
            peak_rss_bytes: rss
                .context("cannot read the peak memory (VmHWM of /proc/self/status)")?,
        });
    }
    // NaN where no exponent fits: it is written as null, which `write`
    // refuses, naming the key.
    let fit = |y: fn(&ScaleRow) -> f64| {
        let points: Vec<(f64, f64)> = rows
            .iter()
            .map(|r| (r.triangles as f64, y(r)))
            .filter(|&(x, y)| x > 0.0 && y > 0.0)
            .map(|(x, y)| (x.ln(), y.ln()))
            .collect();
        growth_exponent(&points).unwrap_or(f64::NAN)
    };
    let exponent = ScaleExponent {
        stripify_ms: fit(|r| r.stripify_ms),
        meshopt_stripify_ms: fit(|r| r.meshopt_stripify_ms),
        simplify_ms: fit(|r| r.simplify_ms),
        meshopt_simplify_to_10_ms: fit(|r| r.meshopt_simplify_to_10_ms),
        build_ms: fit(|r| r.build_ms),
        model_bytes: fit(|r| r.model_bytes as f64),
        load_ms: fit(|r| r.load_ms),
        extract_lod0_us: fit(|r| r.extract_lod0_us),
    };
    Ok(Scale { rows, exponent })
}

/// Least-squares slope of `(ln x, ln y)` points: the exponent `k` of
/// `y ~ x^k`.
fn growth_exponent(points: &[(f64, f64)]) -> Option<f64> {
    if points.len() < 2 {
        return None;
    }
    let n = points.len() as f64;
    let (sx, sy) = points
        .iter()
        .fold((0.0, 0.0), |(a, b), &(x, y)| (a + x, b + y));
    let (mx, my) = (sx / n, sy / n);
    let (num, den) = points.iter().fold((0.0, 0.0), |(a, b), &(x, y)| {
        (a + (x - mx) * (y - my), b + (x - mx) * (x - mx))
    });
    (den > 0.0).then(|| num / den)
}

/// The Skip Strips and MTS figures the MTS paper prints for the bunny
/// (Tables 3 and 4, 550 MHz Pentium III): triangles, Skip Strips vertices,
/// MTS vertices. A printed reference, not a measurement.
const PAPER_TABLE_3: [(&str, &str, &str); 3] = [
    ("10.2K", "22K", "23K"),
    ("50.8K", "83K", "71K"),
    ("69.4K", "92K", "83K"),
];

/// The immediate-mode Figure 6 row of `method` at the share of `at`
/// (`None` when not measured).
pub fn figure6_row<'r>(
    rows: &'r [Figure6Row],
    at: &Figure6Row,
    method: &str,
) -> Option<&'r Figure6Row> {
    rows.iter()
        .find(|y| y.share == at.share && y.method == method && y.mode == "immediate")
}

/// The scale section's table and fitted exponents (the report's and the
/// README's).
pub fn scale_table(s: &mut String, scale: &Scale) {
    let _ = writeln!(s, "Stripify and simplify (whole sequence) each timed alone, beside meshoptimizer's `stripify` and `simplify` to 10%; build is the whole pipeline (stripify beside simplify, then the model).\n");
    let _ = writeln!(s, "| triangles | stripify ms (mts / meshopt) | simplify ms (mts whole / meshopt to 10%) | build ms | model bytes (per triangle) | .mts bytes | load ms (parse, validate, extractor ready) | peak RSS bytes (process so far) | LoD 0 extraction µs |");
    let _ = writeln!(s, "|---|---|---|---|---|---|---|---|---|");
    for r in &scale.rows {
        let _ = writeln!(
            s,
            "| {} | {:.0} / {:.0} | {:.0} / {:.0} | {:.0} | {} ({:.1}) | {} | {:.1} | {} | {:.0} |",
            r.triangles,
            r.stripify_ms,
            r.meshopt_stripify_ms,
            r.simplify_ms,
            r.meshopt_simplify_to_10_ms,
            r.build_ms,
            r.model_bytes,
            r.model_bytes as f64 / r.triangles.max(1) as f64,
            r.file_bytes,
            r.load_ms,
            r.peak_rss_bytes,
            r.extract_lod0_us,
        );
    }
    let e = &scale.exponent;
    let _ = writeln!(
        s,
        "\nFitted growth exponents (y ~ triangles^k): stripify {:.2} (meshoptimizer {:.2}), simplify {:.2} (meshoptimizer to 10% {:.2}), build {:.2}, model bytes {:.2}, load {:.2}, LoD 0 extraction {:.2}.",
        e.stripify_ms,
        e.meshopt_stripify_ms,
        e.simplify_ms,
        e.meshopt_simplify_to_10_ms,
        e.build_ms,
        e.model_bytes,
        e.load_ms,
        e.extract_lod0_us,
    );
}

/// The per-model strips table (the report's and the README's): the
/// project's strips against meshoptimizer's on each input mesh.
pub fn strips_table(s: &mut String, models: &[Model]) {
    let _ = writeln!(
        s, "The project's stripifier (adjacency included) against meshoptimizer's `optimize_vertex_cache_strip` + `stripify` on the input mesh, restart encoding; medians of interleaved runs. Each cell: mts / meshopt.\n");
    let _ = writeln!(
        s, "| model | triangles | strips | swaps | indices (restart) | indices per triangle | ACMR | ms |");
    let _ = writeln!(s, "|---|---|---|---|---|---|---|---|");
    for r in models {
        let (a, b) = (&r.stripify.mts, &r.stripify.meshopt);
        let _ = writeln!(
            s,
            "| {} | {} | {} / {} | {} / {} | {} / {} | {:.4} / {:.4} | {:.3} / {:.3} | {:.1} / {:.1} |",
            r.name,
            a.triangles,
            a.strips,
            b.strips,
            a.swaps,
            b.swaps,
            a.indices_restart,
            b.indices_restart,
            a.indices_per_triangle,
            b.indices_per_triangle,
            a.acmr,
            b.acmr,
            a.ms,
            b.ms,
        );
    }
}

/// Most a strip set's modelled vertex work may exceed the ordered list's
/// and still count as matching it (issue 24's figure).
pub const CACHE_AWARE_SLACK: f64 = 0.05;

/// Per model, issue 24's figure for the cache-aware strips: (indices below
/// meshoptimizer's strips, FIFO 16 within [`CACHE_AWARE_SLACK`] of the
/// ordered list, batch 96 within it).
pub fn cache_aware_verdict(r: &Model) -> (bool, bool, bool) {
    let st = &r.stripify;
    let c = &st.cache_aware;
    (
        c.indices_per_triangle < st.meshopt.indices_per_triangle,
        c.acmr <= st.list_acmr + CACHE_AWARE_SLACK,
        c.acmr_batch96 <= st.list_acmr_batch96 + CACHE_AWARE_SLACK,
    )
}

/// The report's table of the cache-aware strips against meshoptimizer's
/// strips and ordered list.
pub fn cache_aware_table(s: &mut String, models: &[Model]) {
    let _ = writeln!(s, "\n### Cache-aware strips (`mts strips --cache-aware`)\n");
    let _ = writeln!(s, "Rows laid around the last row's vertices (`strip/stripify/cache.rs`) against meshoptimizer's strips (indices) and meshoptimizer's cache-ordered triangle list (modelled vertex work: FIFO of 16 over the triangle order, batches of 96 indices over the buffer, restart values counted). The figure (issue 24): fewer indices per triangle than meshoptimizer's strips, and both models at most the list's + {CACHE_AWARE_SLACK}. Columns: cache-aware / meshoptimizer's strips / the default stripifier; cache-aware / ordered list / meshoptimizer's strips.\n");
    let _ = writeln!(s, "| model | indices per triangle | FIFO 16 | batch 96 | ms | indices below / FIFO 16 / batch 96 met |");
    let _ = writeln!(s, "|---|---|---|---|---|---|");
    let yes = |b: bool| if b { "yes" } else { "**no**" };
    for r in models {
        let st = &r.stripify;
        let (c, m, d) = (&st.cache_aware, &st.meshopt, &st.mts);
        let (i, f, b) = cache_aware_verdict(r);
        let _ = writeln!(
            s,
            "| {} | {:.3} / {:.3} / {:.3} | {:.3} / {:.3} / {:.3} | {:.3} / {:.3} / {:.3} | {:.1} | {} / {} / {} |",
            r.name,
            c.indices_per_triangle,
            m.indices_per_triangle,
            d.indices_per_triangle,
            c.acmr,
            st.list_acmr,
            m.acmr,
            c.acmr_batch96,
            st.list_acmr_batch96,
            m.acmr_batch96,
            c.ms,
            yes(i),
            yes(f),
            yes(b),
        );
    }
}

/// "CPU (N cores), OS" and the graphics adapter (or why there is none),
/// for the report's and the README's first lines.
pub fn machine_words(results: &Results) -> (String, String) {
    let m = &results.machine;
    (
        format!("{} ({} cores), {}", m.cpu, m.cores, m.os),
        m.adapter
            .as_deref()
            .or(m.adapter_note.as_deref())
            .unwrap_or("none")
            .to_string(),
    )
}

/// `report.md` from the results.
pub fn report(results: &Results) -> String {
    let mut s = String::new();
    let (machine, adapter) = machine_words(results);
    let models = &results.models;
    let _ = writeln!(s, "# mts bench report\n");
    let _ = writeln!(
        s,
        "Command: `{}`, {:.0} s. Machine: {machine}. Graphics adapter (Figure 6): {adapter}.\n",
        results.command, results.elapsed_s,
    );
    let _ = writeln!(s, "## Table 1: models and sizes (bytes)\n");
    let _ = writeln!(s, "The `.mts` file holds the model ready to walk (version 3); the recipe-only file (`mts build --recipe-only`) loads by building the graphs again. Memory is the model's arrays with its vertices and their properties.\n");
    let _ = writeln!(s, "| model | strips | triangles | vertices | LoDs | bands | raw (12/vertex + 12/triangle) | raw 16-bit (12 + 6) | .mts file | .mts / raw | recipe-only .mts / raw | MTS in memory | memory / raw | memory bytes / triangle | build ms (stripify ‖ simplify, model, total) |");
    let _ = writeln!(
        s,
        "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"
    );
    for r in models {
        let (b, t) = (&r.bytes, &r.build_ms);
        let _ = writeln!(
            s,
            "| {} | {} | {} | {} | {} | {} | {} | {} | {} | {:.2} | {:.2} | {} | {:.2} | {:.1} | {:.0} ‖ {:.0}, {:.0}, {:.0} |",
            r.name,
            r.strips,
            r.triangles,
            r.vertices,
            r.max_lod + 1,
            r.bands,
            b.raw,
            b.raw_u16,
            b.mts_file,
            b.mts_file as f64 / b.raw as f64,
            b.mts_recipe_file as f64 / b.raw as f64,
            b.mts_memory,
            b.mts_memory as f64 / b.raw as f64,
            b.mts_memory as f64 / r.triangles.max(1) as f64,
            t.stripify,
            t.simplify,
            t.model,
            t.total,
        );
    }
    let _ = writeln!(s, "\n## Strips against meshoptimizer\n");
    strips_table(&mut s, models);
    cache_aware_table(&mut s, models);
    let _ = writeln!(s, "\n### Table 1, every method: bytes and build time\n");
    let _ = writeln!(s, "File bytes against the raw mesh with 16-bit indices (12 per vertex + 6 per triangle, the cluster-tree paper's reference). MTS builds the whole pipeline; the baselines start from the mesh and MTS's contraction sequence (the cluster tree makes its own clustering). Multilevel has no file format of its own: its figure is the in-memory structure. Load: median of 5, from the file's bytes in memory to a source ready for its first LoD (MTS: parse, validate, extractor; progressive mesh: parse; cluster tree: decode the whole packet stream, its receiver's work); multilevel and discrete LoDs have no file reader.\n");
    let _ = writeln!(
        s,
        "| model | method | file bytes | file / raw 16-bit | memory bytes | memory bytes / triangle | load ms | build ms |"
    );
    let _ = writeln!(s, "|---|---|---|---|---|---|---|---|");
    for r in models {
        for m in &r.methods {
            let _ = match m {
                MethodRow::Measured(m) => writeln!(
                    s,
                    "| {} | {} | {} | {:.3} | {} | {:.1} | {} | {:.0} |",
                    r.name,
                    m.method,
                    m.file_bytes,
                    m.file_ratio_to_raw_u16,
                    m.memory_bytes,
                    m.memory_bytes as f64 / r.triangles.max(1) as f64,
                    m.load_ms
                        .map_or("no reader".to_string(), |ms| format!("{ms:.2}")),
                    m.build_ms,
                ),
                MethodRow::Skipped { method, skipped } => {
                    writeln!(
                        s,
                        "| {} | {method} | skipped: {skipped} | | | | | |",
                        r.name
                    )
                }
            };
        }
    }
    let _ = writeln!(s, "\n## Table 2: microseconds per LoD change\n");
    let _ = writeln!(s, "Sequences of `mts::model::sequence` (linear: coarsest to finest in equal steps; exponential: triangle counts in geometric steps; random: uniform, seed 1); medians of five passes each, with and without coherence interleaved, each from a fresh extractor (its construction not timed).\n");
    let _ = writeln!(s, "| model | linear coherent | linear without | × | exponential coherent | exponential without | × | random coherent | random without | × |");
    let _ = writeln!(s, "|---|---|---|---|---|---|---|---|---|---|");
    for r in models {
        let mut row = format!("| {} |", r.name);
        for seq in ["linear", "exponential", "random"] {
            let (c, w) = r.extraction.get(seq).map_or((f64::NAN, f64::NAN), |e| {
                (e.mts_coherent_us, e.mts_scratch_us)
            });
            let _ = write!(row, " {c:.1} | {w:.1} | {:.1} |", w / c);
        }
        let _ = writeln!(s, "{row}");
    }
    let _ = writeln!(
        s,
        "\n### Table 2, every method: microseconds per LoD change\n"
    );
    let _ = writeln!(s, "Each method through `LodSource::set_lod` (MTS: the coherent extractor; from scratch: every strip walked at each request, with the scratch/coherent ratio), the same sequences over its own LoD range, in one run. The cluster tree's LoDs are its own joins; discrete LoDs only switch buffers.\n");
    let _ = writeln!(s, "| model | method | linear | exponential | random |");
    let _ = writeln!(s, "|---|---|---|---|---|");
    for r in models {
        for m in &r.methods {
            if let MethodRow::Measured(m) = m {
                let u = |seq: &str| m.us_per_change.get(seq).copied().unwrap_or(f64::NAN);
                let _ = writeln!(
                    s,
                    "| {} | {} | {:.1} | {:.1} | {:.1} |",
                    r.name,
                    m.method,
                    u("linear"),
                    u("exponential"),
                    u("random"),
                );
                if let Some(scratch) = &m.us_per_change_scratch {
                    // The same requests from scratch, and what coherence
                    // saves (scratch / coherent).
                    let c = |seq: &str| {
                        let x = scratch.get(seq).copied().unwrap_or(f64::NAN);
                        format!("{x:.1} ({:.2}×)", x / u(seq))
                    };
                    let _ = writeln!(
                        s,
                        "| {} | mts from scratch | {} | {} | {} |",
                        r.name,
                        c("linear"),
                        c("exponential"),
                        c("random"),
                    );
                }
            }
        }
    }
    let _ = writeln!(
        s,
        "\n## Tables 3–4: indices sent per level (ACMR, 16-entry FIFO)\n"
    );
    let _ = writeln!(s, "MTS strips with restart values, the triangle list (`optimize_vertex_cache` order) and meshoptimizer's strips of that level's mesh (`optimize_vertex_cache_strip` + `stripify`), measured on the same LoD.\n");
    let _ = writeln!(s, "| model | share | triangles | MTS indices | list indices | meshopt strip indices | MTS / meshopt | ACMR MTS / list / meshopt strips | extract µs (from scratch) |");
    let _ = writeln!(s, "|---|---|---|---|---|---|---|---|---|");
    for r in models {
        for l in &r.levels {
            let _ = writeln!(
                s,
                "| {} | {:.0}% | {} | {} | {} | {} | {:.3} | {:.3} / {:.3} / {:.3} | {:.1} |",
                r.name,
                l.share * 100.0,
                l.triangles,
                l.mts_indices,
                l.list_indices,
                l.meshopt_strip_indices,
                l.mts_indices as f64 / l.meshopt_strip_indices as f64,
                l.mts_acmr,
                l.list_acmr,
                l.meshopt_strip_acmr,
                l.extract_us,
            );
        }
    }
    vertex_table(&mut s, results.vertex_work.as_ref());
    let _ = writeln!(s, "\nPrinted reference, not measured here: the MTS paper's Table 3 for the bunny (vertices sent): Skip Strips / MTS —");
    for (t, skip, ours) in PAPER_TABLE_3 {
        let _ = write!(s, " {t} triangles: {skip} / {ours};");
    }
    let _ = writeln!(
        s,
        "\n\n## Quality: simplification error against meshoptimizer\n"
    );
    let _ = writeln!(s, "Hausdorff and RMS distance to the input relative to its bounding-box diagonal ({SAMPLES} samples per side), meshoptimizer's `simplify` asked for the same triangle count (where it stops above it, the project's LoD is taken at its count).\n");
    let peer = match &results.fast_simplification {
        Some(FastSimplificationRun::Rows(rows)) => Some(rows),
        Some(FastSimplificationRun::Skipped { skipped }) => {
            let _ = writeln!(s, "fast-simplification not measured: {skipped}.\n");
            None
        }
        None => None,
    };
    let _ = writeln!(s, "Speed: the project's whole contraction sequence (every LoD, default options) against meshoptimizer's `simplify` to 10% and to 1%, medians of interleaved runs in milliseconds.\n");
    let _ = writeln!(s, "| model | triangles | contractions | mts whole sequence | meshopt to 10% | meshopt to 1% | stopped |");
    let _ = writeln!(s, "|---|---|---|---|---|---|---|");
    for r in models {
        let x = &r.simplify;
        let _ = writeln!(
            s,
            "| {} | {} | {} | {:.1} | {:.1} | {:.1} | {} |",
            r.name, r.triangles, x.max_lod, x.ms, x.meshopt_ms_to_10, x.meshopt_ms_to_1, x.stop,
        );
    }
    let _ = writeln!(s);
    let _ = writeln!(s, "| model | share | triangles (mts / meshopt) | Hausdorff mts | Hausdorff meshopt | ratio | RMS mts | RMS meshopt | fast-simplification triangles, Hausdorff, RMS |");
    let _ = writeln!(s, "|---|---|---|---|---|---|---|---|---|");
    for r in models {
        for q in &r.quality {
            let fast = peer
                .into_iter()
                .flatten()
                .find(|p| p.mesh == r.name && p.ratio == q.share)
                .map_or_else(
                    || "—".to_string(),
                    |p| format!("{}, {:.5}, {:.5}", p.triangles, p.hausdorff, p.rms),
                );
            let _ = writeln!(
                s,
                "| {} | {:.0}% | {} / {} | {:.5} | {:.5} | {:.2} | {:.5} | {:.5} | {fast} |",
                r.name,
                q.share * 100.0,
                q.mts.triangles,
                q.meshopt.triangles,
                q.mts.hausdorff,
                q.meshopt.hausdorff,
                q.mts.hausdorff / q.meshopt.hausdorff,
                q.mts.rms,
                q.meshopt.rms,
            );
        }
    }
    property_table(&mut s, &results.properties);
    if models.iter().any(|r| r.figure6.is_some()) {
        let _ = writeln!(
            s,
            "\n## Figure 6: frames per second against the share of triangles\n"
        );
        let _ = writeln!(s, "Immediate: a LoD change (extraction and upload) before every frame. Per second: one extraction (MTS from scratch; the list replayed and put in meshoptimizer's cache order) and upload per second, drawing in between. The list is meshoptimizer-ordered; MTS draws strips with primitive restart.\n");
        let _ = writeln!(s, "Each cell: immediate / one extraction per second. The baselines (through `LodSource`) upload their whole index buffer per change and are asked for their finest LoD within the MTS level's triangles.\n");
        let _ = writeln!(
            s,
            "| model | share | triangles | mts | list | pm | multilevel | cluster | discrete |"
        );
        let _ = writeln!(s, "|---|---|---|---|---|---|---|---|---|");
        for r in models {
            let rows = r.figure6.as_ref().map_or(&[][..], |f| &f.rows[..]);
            let mut shares: Vec<f64> = Vec::new();
            for x in rows {
                if !shares.contains(&x.share) {
                    shares.push(x.share);
                }
            }
            for share in shares {
                let cell = |method: &str| {
                    let fps = |mode: &str| {
                        rows.iter()
                            .find(|x| x.share == share && x.method == method && x.mode == mode)
                            .map_or(f64::NAN, |x| x.fps)
                    };
                    format!("{:.1} / {:.1}", fps("immediate"), fps("per_second"))
                };
                let triangles = rows
                    .iter()
                    .find(|x| x.share == share && x.method == "mts")
                    .map_or_else(|| "null".to_string(), |x| x.triangles.to_string());
                let _ = writeln!(
                    s,
                    "| {} | {:.0}% | {} | {} | {} | {} | {} | {} | {} |",
                    r.name,
                    share * 100.0,
                    triangles,
                    cell("mts"),
                    cell("list"),
                    cell("pm"),
                    cell("multilevel"),
                    cell("cluster"),
                    cell("discrete"),
                );
            }
        }
    }
    if models.iter().any(|r| r.figure6.is_some()) {
        let _ = writeln!(s, "\n### Figure 6, draw time per frame\n");
        let _ = writeln!(s, "The same runs: the median time of one frame drawn without a LoD change (submit and wait), MTS strips against the meshoptimizer-ordered list, and the median time of one MTS LoD change (extraction and dirty-range upload, one LoD step back and forth).\n");
        let _ = writeln!(s, "| model | share | triangles | indices mts / list | draw ms mts / list | Mtri/s mts / list | MTS LoD change µs |");
        let _ = writeln!(s, "|---|---|---|---|---|---|---|");
        for r in models {
            let rows = r.figure6.as_ref().map_or(&[][..], |f| &f.rows[..]);
            for x in rows
                .iter()
                .filter(|x| x.method == "mts" && x.mode == "immediate")
            {
                let list = figure6_row(rows, x, "list");
                let list_ms = list.map_or(f64::NAN, |l| l.draw_ms);
                let tri = x.triangles as f64;
                let _ = writeln!(
                    s,
                    "| {} | {:.0}% | {} | {} / {} | {:.2} / {:.2} | {:.2} / {:.2} | {:.0} |",
                    r.name,
                    x.share * 100.0,
                    x.triangles,
                    x.indices_sent,
                    list.map_or_else(|| "null".to_string(), |l| l.indices_sent.to_string()),
                    x.draw_ms,
                    list_ms,
                    tri / x.draw_ms / 1e3,
                    tri / list_ms / 1e3,
                    x.change_us.unwrap_or(f64::NAN),
                );
            }
        }
    }
    scene_table(&mut s, &results.scenes);
    if let Some(scale) = &results.scale {
        let _ = writeln!(s, "\n## Scale: generated icospheres\n");
        scale_table(&mut s, scale);
    }
    s
}

/// Writes `report.md` and `results.json` into `dir` (created if needed),
/// after checking that `results` reads back ([`Results::from_value`]): a
/// NaN the bench produced is written as `null`, which stops here with the
/// key named.
///
/// # Errors
/// When `results` holds a NaN, or a file cannot be written.
pub fn write(dir: &Path, results: &Results) -> Result<()> {
    Results::from_value(serde_json::to_value(results)?)?;
    std::fs::create_dir_all(dir).with_context(|| format!("cannot create {}", dir.display()))?;
    let json_path = dir.join("results.json");
    mts::output::write_file(
        &json_path,
        serde_json::to_string_pretty(results)?.as_bytes(),
    )?;
    let charts = super::charts::write_all(dir, results)?;
    let mut text = report(results);
    if !charts.is_empty() {
        let _ = writeln!(text, "\n## Charts\n");
        for c in &charts {
            if let Some(name) = c.file_name() {
                let name = name.to_string_lossy();
                let _ = writeln!(text, "![{name}]({name})\n");
            }
        }
    }
    let md = dir.join("report.md");
    mts::output::write_file(&md, text.as_bytes())?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn growth_exponent_recovers_a_power_law() {
        let points: Vec<(f64, f64)> = [1e4, 1e5, 1e6]
            .iter()
            .map(|&x: &f64| (x.ln(), (3.0 * x.powf(1.25)).ln()))
            .collect();
        let k = growth_exponent(&points).unwrap();
        assert!((k - 1.25).abs() < 1e-9, "{k}");
        assert_eq!(growth_exponent(&points[..1]), None);
    }

    /// The report written from the committed results.json is the committed
    /// report.md, byte for byte.
    #[test]
    fn the_committed_report_is_what_its_data_gives() {
        let dir = Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../../docs/report"));
        let results = crate::results::Results::load(&dir.join("results.json")).unwrap();
        let mut text = report(&results);
        let _ = writeln!(text, "\n## Charts\n");
        for name in [
            "indices",
            "figure6_immediate",
            "figure6_per_second",
            "scale",
        ] {
            let _ = writeln!(text, "![{name}.png]({name}.png)\n");
        }
        let committed = std::fs::read_to_string(dir.join("report.md")).unwrap();
        let first = text
            .lines()
            .zip(committed.lines())
            .position(|(a, b)| a != b);
        assert!(
            text == committed,
            "report.md differs from what results.json gives, first at line {:?}:\n{:?}\n{:?}",
            first.map(|i| i + 1),
            first.and_then(|i| text.lines().nth(i)),
            first.and_then(|i| committed.lines().nth(i)),
        );
    }
}
