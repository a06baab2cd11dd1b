//! `mts bench render`: frames and triangles per second of the MTS strips
//! against meshoptimizer-ordered triangle lists, headless, on the adapter
//! at hand; and the cost of one LoD change (extraction plus upload).

use super::render::Size;
use super::MeshSource;
use crate::results::Scene;
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
          value_parser = crate::count_in::<1, 100_000>)]
    frames: usize,
    /// Image size in pixels.
    #[arg(long, default_value = "1024x768")]
    size: Size,
    /// Instances of the model in the scene row (0 to skip it; at most
    /// 2^20).
    #[arg(long, default_value_t = 1000, allow_negative_numbers = true,
          value_parser = crate::count_in::<0, { 1 << 20 }>)]
    scene: usize,
    /// Print JSON instead of a table.
    #[arg(long)]
    json: bool,
}

/// The scene row skips (with a note) where the scene itself would refuse:
/// past this many bytes of per-instance coherence caches.
use mts_render::scene::MAX_CACHE_BYTES as SCENE_MEMORY_CAP;

/// What `--json` prints.
#[derive(Serialize)]
struct RenderReport {
    scene: Option<Scene>,
    input: String,
    adapter: String,
    backend: String,
    device_type: String,
    strip_mode: String,
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
        println!("{name}: {} x {} pixels", args.size.0, args.size.1);
        println!("adapter: {report}");
        println!(
            "{:>6} {:>9} {:>7} {:>10} {:>9} {:>8} {:>10} {:>11}",
            "level", "triangles", "method", "indices", "ms/frame", "fps", "Mtri/s", "LoD step us"
        );
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
                println!(
                    "{:>5.0}% {triangles:>9} {method:>7} {indices:>10} {ms:>9.2} {fps:>8.1} {mtri:>10.2} {:>11}",
                    100.0 * ratio,
                    step.map_or(String::new(), |s| format!("{s:.0}"))
                );
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
    let scene = if args.scene > 0 {
        bench_scene(&gpu, &target, &config, &name, &model, args)?
    } else {
        None
    };
    if args.json {
        let out = RenderReport {
            scene,
            input: name,
            adapter: report.name,
            backend: format!("{:?}", report.backend),
            device_type: format!("{:?}", report.device_type),
            strip_mode: report.strip_mode.to_string(),
            width: args.size.0,
            height: args.size.1,
            frames: args.frames,
            rows,
        };
        // Through a `Value`, whose keys are sorted: the order this output
        // has always had.
        println!("{}", serde_json::to_value(out)?);
    }
    Ok(())
}

/// Median frame (update and draw) of `args.scene` instances seen by the
/// scene's overview camera; prints a row unless `--json`. `None` (with a
/// note on stderr) when the instances' coherence caches would exceed
/// [`SCENE_MEMORY_CAP`].
fn bench_scene(
    gpu: &Gpu,
    target: &HeadlessTarget,
    config: &RendererConfig,
    name: &str,
    model: &mts::MtsModel,
    args: &BenchRenderArgs,
) -> Result<Option<Scene>> {
    let row = scene_row(gpu, target, config, name, model, args.scene, args.frames)?;
    if let (Some(r), false) = (&row, args.json) {
        let ms = r.ms_per_frame;
        println!(
            "scene: {} instances, {} visible, {} triangles, {} indices sent; \
             first update {:.1} ms; frame {ms:.2} ms = {:.1} fps, {:.2} Mtri/s",
            args.scene,
            r.visible,
            r.triangles,
            r.indices_sent,
            r.ms_first_update,
            1e3 / ms,
            r.triangles_per_second / 1e6,
        );
    }
    Ok(row)
}

/// Median frame (every instance's LoD update and the draw) of `instances`
/// copies of `model` (called `name`) seen by the scene's overview camera,
/// `frames` timed frames after two warm-up ones. `None` (with a note on
/// stderr) when the instances' coherence caches would exceed
/// [`SCENE_MEMORY_CAP`].
pub fn scene_row(
    gpu: &Gpu,
    target: &HeadlessTarget,
    config: &RendererConfig,
    name: &str,
    model: &mts::MtsModel,
    instances: usize,
    frames: usize,
) -> Result<Option<Scene>> {
    use crate::demo_scene::DemoScene;
    let per_instance = 4 * Extractor::new(model).buffer().len();
    if per_instance.saturating_mul(instances) > SCENE_MEMORY_CAP {
        eprintln!(
            "scene skipped: {instances} instances would hold {:.1} GB of coherence caches \
             ({per_instance} bytes each); pass a smaller --scene",
            (per_instance * instances) as f64 / 1e9,
        );
        return Ok(None);
    }
    let mut scene = DemoScene::new(&gpu.device, &gpu.queue, config, model, instances)?;
    let camera = scene.overview_camera(target.aspect());
    let (width, height) = target.size();
    let t = Instant::now();
    let first = scene.update(&gpu.device, &gpu.queue, &camera, height as f32)?;
    let first_ms = t.elapsed().as_secs_f64() * 1e3;
    let mut times = Vec::with_capacity(frames);
    let mut stats = first;
    for i in 0..frames.max(1) + 2 {
        let t = Instant::now();
        stats = scene.update(&gpu.device, &gpu.queue, &camera, height as f32)?;
        target.render(&gpu.device, &gpu.queue, |pass| scene.draw(pass))?;
        if i >= 2 {
            times.push(t.elapsed().as_secs_f64() * 1e3);
        }
    }
    times.sort_by(f64::total_cmp);
    let ms = times[times.len() / 2];
    Ok(Some(Scene {
        model: name.to_string(),
        instances: instances as u64,
        width,
        height,
        visible: stats.visible as u64,
        triangles: stats.triangles as u64,
        indices_sent: stats.indices_sent as u64,
        cpu_bytes_per_instance: per_instance as u64,
        ms_first_update: first_ms,
        ms_per_frame: ms,
        fps: 1e3 / ms,
        triangles_per_second: stats.triangles as f64 * 1e3 / ms,
    }))
}
