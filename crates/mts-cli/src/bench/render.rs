//! `mts bench render`: frames and triangles per second of the MTS strips
//! against meshoptimizer-ordered triangle lists, headless, on the adapter
//! at hand; and the cost of one LoD change (extraction plus upload). A
//! hierarchy is benched along a flight instead
//! ([`super::render_hierarchy`]).

use super::scene::{scene_rows, SceneSpec, SCENE_COMPARED_FRAMES};
use super::vertex_work::measure_vertex_work;
use crate::args::MeshSource;
use crate::bench::results::{Scene, VertexWork};
use crate::commands::render::Size;
use crate::stdout::outln;
use anyhow::Result;
use clap::Args;
use mts::{peers, Extractor};
use mts_render::headless::HeadlessTarget;
use mts_render::{Camera, Gpu, RendererConfig, StripRenderer};
use serde::Serialize;
use std::time::Instant;

#[derive(Args)]
pub struct BenchRenderArgs {
    /// An .mts model, or an OBJ/PLY mesh (the model is built on the fly).
    #[command(flatten)]
    source: MeshSource,
    /// Frames timed per method and level (after two warm-up frames; 1 to
    /// 100,000).
    #[arg(long, default_value_t = 30, allow_negative_numbers = true,
          value_parser = crate::args::count_in::<1, 100_000>)]
    frames: usize,
    /// Image size in pixels.
    #[arg(long, default_value = "1024x768")]
    size: Size,
    /// Instances in the scene row, the models taken in turn (0 to skip
    /// it; at most 2^22).
    #[arg(long, default_value_t = 1000, allow_negative_numbers = true,
          value_parser = crate::args::count_in::<0, { 1 << 22 }>)]
    scene: usize,
    /// More models for the scene (OBJ/PLY meshes; the first is the
    /// command's model).
    #[arg(long, value_name = "MESH", num_args = 1..)]
    scene_with: Vec<std::path::PathBuf>,
    /// The scene's screen-space error allowed, in pixels.
    #[arg(long, default_value_t = mts_render::scene::DEFAULT_PIXEL_ERROR,
          allow_hyphen_values = true, value_parser = crate::args::pixel_error)]
    pixel_error: f32,
    /// Build the view-dependent hierarchy of the mesh (or --generated)
    /// and bench it along the flight of `mts bench view-dependent`
    /// (`--frames` cameras, `--pixel-error` px); a hierarchy's .mts file
    /// is benched so without it.
    #[arg(long)]
    hierarchy: bool,
    /// Print JSON instead of a table.
    #[arg(long)]
    json: bool,
}

/// The adapter a `--json` report names (its keys flattened into the
/// report's).
#[derive(Serialize)]
pub struct AdapterFields {
    adapter: String,
    backend: String,
    device_type: String,
    strip_mode: String,
}

impl AdapterFields {
    pub fn of(report: &mts_render::AdapterReport) -> AdapterFields {
        AdapterFields {
            adapter: report.name.clone(),
            backend: format!("{:?}", report.backend),
            device_type: format!("{:?}", report.device_type),
            strip_mode: report.strip_mode.to_string(),
        }
    }
}

/// What `--json` prints.
#[derive(Serialize)]
struct RenderReport {
    scene: Option<Scene>,
    vertex_work: VertexWork,
    input: String,
    #[serde(flatten)]
    adapter: AdapterFields,
    width: u32,
    height: u32,
    frames: usize,
    rows: Vec<RenderRow>,
}

/// One method at one level.
#[derive(Serialize)]
struct RenderRow {
    ratio: f64,
    lod: usize,
    triangles: usize,
    method: &'static str,
    indices_sent: usize,
    indices_drawn: usize,
    ms_per_frame: f64,
    fps: f64,
    triangles_per_second: f64,
    /// `None` for the list, which has no LoD step.
    lod_step_us: Option<f64>,
}

/// The vertex-work rows as text.
fn print_vertex_work(w: &VertexWork) -> Result<()> {
    outln!("vertex work (adapter counts; modelled invocations per cache model):")?;
    if let Some(note) = &w.note {
        outln!("  {note}")?;
    }
    outln!(
        "{:>6} {:>14} {:>9} {:>9} {:>10} {:>8} {:>9} {:>8} {:>8} {:>8} {:>8}",
        "level",
        "method",
        "triangles",
        "indices",
        "VS inv",
        "VS/tri",
        "clipper",
        "fifo16",
        "batch96",
        "batch384",
        "lru32"
    )?;
    let opt = |x: Option<u64>| x.map_or("—".into(), |x| x.to_string());
    for r in &w.rows {
        outln!(
            "{:>5.0}% {:>14} {:>9} {:>9} {:>10} {:>8} {:>9} {:>8} {:>8} {:>8} {:>8}",
            100.0 * r.ratio,
            r.method,
            r.triangles,
            r.indices_sent,
            opt(r.vertex_invocations),
            r.invocations_per_triangle
                .map_or("—".into(), |x| format!("{x:.3}")),
            opt(r.clipper_invocations),
            r.modelled["fifo16"],
            r.modelled["batch96"],
            r.modelled["batch384"],
            r.modelled["lru32"],
        )?;
    }
    if let Some(best) = &w.best_model {
        outln!(
            "best-fitting model: {best}; clipper count differs from triangles in {} rows \
             ({} from the primitives assembled, degenerate windows included)",
            w.clipper_mismatches,
            w.rows
                .iter()
                .filter(|r| r
                    .clipper_invocations
                    .is_some_and(|c| c != r.primitives_assembled))
                .count()
        )?;
    }
    Ok(())
}

/// Median milliseconds of `frames` frames of `renderer` into `target`.
fn frame_ms(
    gpu: &Gpu,
    target: &HeadlessTarget,
    renderer: &StripRenderer,
    frames: usize,
) -> Result<f64> {
    let mut times = Vec::with_capacity(frames);
    for i in 0..frames + 2 {
        let t = Instant::now();
        target.render(&gpu.device, &gpu.queue, |pass| renderer.draw(pass))?;
        if i >= 2 {
            times.push(t.elapsed().as_secs_f64() * 1e3);
        }
    }
    times.sort_by(f64::total_cmp);
    Ok(times[times.len() / 2])
}

/// Median microseconds of one LoD step (extraction and dirty-range upload)
/// over 200 single steps back and forth around `lod`.
fn lod_change_us(
    gpu: &Gpu,
    renderer: &mut StripRenderer,
    ex: &mut Extractor<'_>,
    lod: usize,
) -> Result<f64> {
    let max = ex.model().max_lod();
    let (a, b) = if lod < max {
        (lod, lod + 1)
    } else {
        (lod - 1, lod)
    };
    let mut times = Vec::with_capacity(200);
    for i in 0..200 {
        let t = Instant::now();
        ex.set_lod(if i % 2 == 0 { b } else { a });
        renderer.update_strips(&gpu.device, &gpu.queue, ex)?;
        times.push(t.elapsed().as_secs_f64() * 1e6);
    }
    // Leave the extractor and the GPU buffer at `lod`.
    ex.set_lod(lod);
    renderer.update_strips(&gpu.device, &gpu.queue, ex)?;
    gpu.queue.submit([]);
    times.sort_by(f64::total_cmp);
    Ok(times[times.len() / 2])
}

pub fn bench_render(args: &BenchRenderArgs) -> Result<()> {
    if let Some((name, h)) = crate::commands::render::load_hierarchy(&args.source, args.hierarchy)?
    {
        return super::render_hierarchy::bench_render_hierarchy(
            &super::render_hierarchy::HierarchyBench {
                name: &name,
                h: &h,
                cameras: args.frames,
                width: args.size.0,
                height: args.size.1,
                pixel_error: args.pixel_error,
                json: args.json,
            },
        );
    }
    let (name, model) = args.source.model()?;
    let mesh = model.mesh();
    let gpu = Gpu::new_headless()?;
    let report = gpu.report();
    let config = RendererConfig::headless(report.strip_mode);
    let (d, q) = (&gpu.device, &gpu.queue);
    let target = HeadlessTarget::new(d, args.size.0, args.size.1)?;
    let camera = Camera::framing_points(model.positions(), target.aspect());
    let mut strips = StripRenderer::for_model(d, q, &config, &model)?;
    let mut list = StripRenderer::for_model(d, q, &config, &model)?;
    strips.set_camera(q, &camera);
    list.set_camera(q, &camera);
    let mut ex = Extractor::new(&model);
    let mut rows = Vec::new();
    if !args.json {
        outln!("{name}: {} x {} pixels", args.size.0, args.size.1)?;
        outln!("adapter: {report}")?;
        outln!(
            "{:>6} {:>9} {:>7} {:>10} {:>9} {:>8} {:>10} {:>11}",
            "level",
            "triangles",
            "method",
            "indices",
            "ms/frame",
            "fps",
            "Mtri/s",
            "LoD step us"
        )?;
    }
    for ratio in [1.0, 0.5, 0.1] {
        let lod = model.lod_for_ratio(ratio);
        let triangles = model.triangle_count(lod);
        ex.set_lod(lod);
        strips.upload_strips(d, q, &ex)?;
        let step_us = lod_change_us(&gpu, &mut strips, &mut ex, lod)?;
        let oracle = model.collapses().triangles_at(&mesh, lod);
        let ordered = peers::meshopt::optimize_vertex_cache(&oracle, model.positions().len());
        list.upload_list(d, q, &ordered)?;
        for (method, renderer, indices, step) in [
            ("mts", &strips, ex.indices_sent(), Some(step_us)),
            ("meshopt", &list, 3 * ordered.len(), None),
        ] {
            let ms = frame_ms(&gpu, &target, renderer, args.frames)?;
            let fps = 1e3 / ms;
            let mtri = triangles as f64 * fps / 1e6;
            if !args.json {
                outln!(
                    "{:>5.0}% {triangles:>9} {method:>7} {indices:>10} {ms:>9.2} {fps:>8.1} {mtri:>10.2} {:>11}",
                    100.0 * ratio,
                    step.map_or(String::new(), |s| format!("{s:.0}"))
                )?;
            }
            rows.push(RenderRow {
                ratio,
                lod,
                triangles,
                method,
                indices_sent: indices,
                indices_drawn: renderer.indices_drawn(),
                ms_per_frame: ms,
                fps,
                triangles_per_second: triangles as f64 * fps,
                lod_step_us: step,
            });
        }
    }
    let vertex = measure_vertex_work(&gpu, &target, &config, &name, &model, &camera)?;
    if !args.json {
        print_vertex_work(&vertex)?;
    }
    let scene = if args.scene > 0 {
        let others = crate::demo_scene::load_models(&args.scene_with)?;
        let mut models = vec![(name.clone(), &model)];
        models.extend(others.iter().map(|(n, m)| (n.clone(), m)));
        Some(bench_scene(&gpu, &target, &config, &models, args)?)
    } else {
        None
    };
    if args.json {
        let out = RenderReport {
            scene,
            vertex_work: vertex,
            input: name,
            adapter: AdapterFields::of(&report),
            width: args.size.0,
            height: args.size.1,
            frames: args.frames,
            rows,
        };
        // Through a `Value`, whose keys are sorted: the order this output
        // has always had.
        outln!("{}", serde_json::to_value(out)?)?;
    }
    Ok(())
}

/// The scene rows of `mts bench render --scene N`: [`scene_row`] over the
/// command's model and `--scene-with` models; prints them unless `--json`.
fn bench_scene(
    gpu: &Gpu,
    target: &HeadlessTarget,
    config: &RendererConfig,
    models: &[(String, &mts::MtsModel)],
    args: &BenchRenderArgs,
) -> Result<Scene> {
    let spec = SceneSpec {
        instances: args.scene,
        pixel_errors: &[args.pixel_error],
        frames: args.frames,
        compared_frames: SCENE_COMPARED_FRAMES,
    };
    let row = scene_rows(gpu, target, config, models, &spec)?.remove(0);
    if !args.json {
        print_scene(&row)?;
    }
    Ok(row)
}

/// One scene row as text.
pub fn print_scene(r: &Scene) -> Result<()> {
    outln!(
        "scene: {} instances of {} models ({}), {}×{} pixels, {} frames along the path:",
        r.instances,
        r.models,
        r.model_names.join(", "),
        r.width,
        r.height,
        r.frames
    )?;
    outln!("{}", super::report::scene_table_head())?;
    outln!("{}", super::report::scene_table_row(r))
}
