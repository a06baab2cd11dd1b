//! The measuring of `mts bench`: every table's figures into the typed
//! [`super::results::Results`].

//! `mts bench`: the MTS paper's tables measured on this machine, written as
//! `report.md` and `results.json` (schema in `docs/bench-schema.md`).
//!
//! Every figure of a row is measured in the same run as the figures it is
//! compared with. Timings are medians of a few repetitions; the machine
//! section names the CPU they come from.

use crate::bench::results::{
    BuildMs, Bytes, Distance, Extraction, FastSimplification, FastSimplificationRun, Level,
    Machine, Model, PeerDistance, PropertyRow, PropertySide, Quality, Results, Scale,
    ScaleExponent, ScaleRow, Scene, Simplify, StripRow, Stripify, ViewDependentRun,
};
use anyhow::{Context, Result};
use mts::model::{build_from_mesh, requests, PipelineOptions};
use mts::peers;
use mts::strip::acmr::{fifo_acmr, CACHE_SIZE};
use mts::strip::stats::StripStats;
use mts::{Extractor, Mesh, MtsModel, SimplifyOptions, StripifyOptions};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::time::Instant;

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
pub const SAMPLES: usize = 100_000;

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

/// The view-dependent section (`mts bench view-dependent` per input): the
/// generated terrain at each of [`VIEW_DEPENDENT_THRESHOLDS`], then the
/// scans of [`VIEW_DEPENDENT_SCANS`] measured by this run (the largest
/// shared ones) at 1 pixel, [`VIEW_DEPENDENT_FRAMES`] frames in a viewport
/// of [`VIEW_DEPENDENT_SIZE`]; with `--quick` a smaller terrain at 1 pixel,
/// fewer frames, a smaller viewport.
pub const VIEW_DEPENDENT_TERRAIN: &str = "terrain:4M";

pub const VIEW_DEPENDENT_THRESHOLDS: [f32; 3] = [0.5, 1.0, 2.0];

pub const VIEW_DEPENDENT_SCANS: [&str; 2] = ["lucy.ply", "armadillo.obj"];

const VIEW_DEPENDENT_SCAN_THRESHOLDS: [f32; 1] = [1.0];

/// Frames of each full-run flight. 120, not the command's 300: at 4M
/// triangles the cluster tree draws about 1.9M a frame, and its quality
/// figures cost seconds a frame; at 300 frames the full bench would take
/// about an hour longer.
pub const VIEW_DEPENDENT_FRAMES: usize = 120;

pub const VIEW_DEPENDENT_SIZE: (u32, u32) = (640, 360);

pub const QUICK_VIEW_DEPENDENT_TERRAIN: &str = "terrain:100k";

pub const QUICK_VIEW_DEPENDENT_THRESHOLDS: [f32; 1] = [1.0];

pub const QUICK_VIEW_DEPENDENT_FRAMES: usize = 120;

pub const QUICK_VIEW_DEPENDENT_SIZE: (u32, u32) = (320, 180);

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
    let view_dependent =
        measure_view_dependent(&inputs, options.quick, renderer.is_ok(), progress)?;
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
        schema: super::results::SCHEMA_VERSION,
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
        view_dependent,
    })
}

/// The view-dependent runs (see [`VIEW_DEPENDENT_TERRAIN`]): each input
/// flown with the hierarchy's default settings, the images compared with
/// full detail when `images` (an adapter was found).
///
/// # Errors
/// As [`super::view_dependent::measure`].
fn measure_view_dependent(
    inputs: &[(String, Mesh)],
    quick: bool,
    images: bool,
    progress: &dyn Fn(&str),
) -> Result<Vec<ViewDependentRun>> {
    let (terrain, thresholds, frames, (width, height)): (&str, &[f32], _, _) = if quick {
        (
            QUICK_VIEW_DEPENDENT_TERRAIN,
            &QUICK_VIEW_DEPENDENT_THRESHOLDS,
            QUICK_VIEW_DEPENDENT_FRAMES,
            QUICK_VIEW_DEPENDENT_SIZE,
        )
    } else {
        (
            VIEW_DEPENDENT_TERRAIN,
            &VIEW_DEPENDENT_THRESHOLDS,
            VIEW_DEPENDENT_FRAMES,
            VIEW_DEPENDENT_SIZE,
        )
    };
    let fly = |mesh: &Mesh, name: &str, pixel_errors: &[f32]| {
        let spec = super::view_dependent::FlightSpec {
            mesh,
            name,
            pixel_errors,
            frames,
            width,
            height,
            images,
            options: Default::default(),
        };
        // Told each build; the flights follow the last.
        let say = |what: &str| {
            progress(&format!(
                "view-dependent {name} at {pixel_errors:?} px: building {what}, then the flights"
            ));
            Ok(())
        };
        super::view_dependent::measure(&spec, &say)
    };
    let g: mts::mesh::generate::Generated = terrain.parse().expect("a valid generated name");
    let mut runs = vec![fly(&g.build(), &format!("generated {g}"), thresholds)?];
    // The scans this run measured (a file missing or refused is not).
    for scan in VIEW_DEPENDENT_SCANS.iter().filter(|_| !quick) {
        if let Some((name, mesh)) = inputs.iter().find(|(n, _)| n == scan) {
            runs.push(fly(mesh, name, &VIEW_DEPENDENT_SCAN_THRESHOLDS)?);
        }
    }
    Ok(runs)
}

/// The generated mesh with properties every run measures (UV seams,
/// normals, colours).
pub const PROPERTY_MESH: &str = "torus:20k";

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
    use mts::peers::meshopt::{simplify_with_attributes_to_lod, MESHOPT_WEIGHTS};
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
            let (theirs, lod) =
                simplify_with_attributes_to_lod(mesh, &c, c.lod_for_ratio(share), MESHOPT_WEIGHTS);
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
/// As [`super::scene::scene_rows`].
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
        let spec = super::scene::SceneSpec {
            instances,
            pixel_errors: thresholds,
            frames,
            compared_frames: super::scene::SCENE_COMPARED_FRAMES,
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
    let coded = model.to_streamed_bytes(
        mts::model::compress::DEFAULT_LEVEL,
        &mts::model::DEFAULT_PREFIX_SHARES,
    );
    let file_bytes = coded.len();
    let chunks = mts::model::chunk_index(&coded, std::path::Path::new("bench.mts"))?;
    let prefix_bytes =
        |share: f64| mts::model::bytes_for_lod(&chunks, file_bytes, model.lod_for_ratio(share));
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
            prefix_bytes_10: prefix_bytes(0.1) as u64,
            prefix_bytes_50: prefix_bytes(0.5) as u64,
            mts_file_uncompressed: model.to_bytes().len() as u64,
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
        methods: super::methods::measure_methods(&model, mesh, ms(t.total), requests, &coded)?,
        figure6: match renderer {
            Ok(r) => Some(r.measure(&model, mesh, shares, frames)?),
            Err(_) => {
                let _ = (shares, frames);
                None
            }
        },
        renewal: super::renewal::measure(&model, mesh),
    };
    Ok((row, model))
}

/// Table 2: microseconds per LoD change over each sequence, with the
/// coherence cache and from scratch: medians of five passes each, the two
/// interleaved (a drift of the machine's speed hits both alike), each
/// pass from a fresh extractor whose construction is not timed.
fn measure_sequences(model: &MtsModel, requests: usize) -> BTreeMap<String, Extraction> {
    let mut out = BTreeMap::new();
    for (seq, lods) in requests::table2(model.triangle_counts(), requests) {
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
        let coded = model.to_streamed_bytes(
            mts::model::compress::DEFAULT_LEVEL,
            &mts::model::DEFAULT_PREFIX_SHARES,
        );
        drop(model);
        let load = |bytes: &[u8]| {
            time_us(3, || {
                let m = mts::MtsModel::from_bytes(bytes, std::path::Path::new("scale.mts"))
                    .expect("a file just written loads");
                std::hint::black_box(Extractor::new(&m).buffer().len());
            }) / 1e3
        };
        let (load_ms, coded_load_ms) = (load(&file), load(&coded));
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
            coded_file_bytes: coded.len() as u64,
            coded_load_ms,
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
}
