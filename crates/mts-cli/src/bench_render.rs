//! `mts bench render`: frames and triangles per second of the MTS strips
//! against meshoptimizer-ordered triangle lists, headless, on the adapter
//! at hand; and the cost of one LoD change (extraction plus upload).

use super::render::Size;
use super::MeshSource;
use crate::results::{ModelFit, Scene, VertexRow, VertexWork};
use crate::stdout::outln;
use anyhow::Result;
use clap::Args;
use mts::{peers, Extractor, StripifyOptions};
use mts_render::headless::HeadlessTarget;
use mts_render::{Camera, Gpu, RendererConfig, StripRenderer};
use serde::Serialize;
use std::collections::BTreeMap;
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
    /// Instances in the scene row, the models taken in turn (0 to skip
    /// it; at most 2^22).
    #[arg(long, default_value_t = 1000, allow_negative_numbers = true,
          value_parser = crate::count_in::<0, { 1 << 22 }>)]
    scene: usize,
    /// More models for the scene (OBJ/PLY meshes; the first is the
    /// command's model).
    #[arg(long, value_name = "MESH", num_args = 1..)]
    scene_with: Vec<std::path::PathBuf>,
    /// The scene's screen-space error allowed, in pixels.
    #[arg(long, default_value_t = mts_render::scene::DEFAULT_PIXEL_ERROR,
          allow_hyphen_values = true, value_parser = crate::pixel_error)]
    pixel_error: f32,
    /// Print JSON instead of a table.
    #[arg(long)]
    json: bool,
}

/// What `--json` prints.
#[derive(Serialize)]
struct RenderReport {
    scene: Option<Scene>,
    vertex_work: VertexWork,
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

/// Shares of the vertex-work rows (the 100/50/10/1%).
const VERTEX_SHARES: [f64; 4] = [1.0, 0.5, 0.1, 0.01];

/// Measures [`VertexWork`] of `model` on `gpu`: MTS strips (restart or
/// stitched, as the backend draws; and stitched: `mts_stitched`), the MTS strips of the same model built
/// with cache-aware bands (`mts_cache_aware`), meshoptimizer's strips, the
/// cache-aware stripifier on the level's triangles (`cache_aware_strips`,
/// and stitched into one run: `cache_aware_stitched`),
/// the meshoptimizer-ordered list and the unordered list (the oracle's
/// order) at each of [`VERTEX_SHARES`], and the baselines' lists (`pm_list`,
/// `multilevel_list`, `cluster_list`, `discrete_list`; discrete where
/// meshoptimizer takes the mesh) at their finest LoD within the same
/// triangles.
pub fn measure_vertex_work(
    gpu: &Gpu,
    target: &HeadlessTarget,
    config: &RendererConfig,
    model_name: &str,
    model: &mts::MtsModel,
    camera: &Camera,
) -> Result<VertexWork> {
    use mts::strip::encode::stitch_restart_buffer;
    use mts::strip::vertex_work::{Topology, REPORTED_MODELS};
    use mts_render::{DrawQueries, StripMode};
    let (d, q) = (&gpu.device, &gpu.queue);
    let queries = DrawQueries::new(d, q);
    let mesh = model.mesh();
    let mut renderer = StripRenderer::for_model(d, q, config, model)?;
    renderer.set_camera(q, camera);
    let mut ex = Extractor::new(model);
    // The same sequence and band slack, every band stripified cache-aware.
    let aware = StripifyOptions {
        cache_aware: true,
        ..StripifyOptions::default()
    };
    let aware_model = mts::model::build(
        &mesh,
        &mts::stripify(&mesh, &aware),
        model.collapses(),
        &mts::model::BuildOptions {
            band_slack: model.build_options().band_slack,
            stripify: aware,
        },
    );
    let mut aware_ex = Extractor::new(&aware_model);
    let mut rows = Vec::new();
    for ratio in VERTEX_SHARES {
        let lod = model.lod_for_ratio(ratio);
        ex.set_lod(lod);
        let oracle = model.collapses().triangles_at(&mesh, lod);
        let n = model.positions().len();
        let ordered = peers::meshopt::optimize_vertex_cache(&oracle, n);
        let level = mts::Mesh {
            positions: model.positions().to_vec(),
            triangles: oracle.clone(),
            properties: Default::default(),
        };
        let theirs = peers::meshopt::stripify(&level).to_restart_u32();
        let aware_strips = mts::stripify(&level, &aware).to_restart_u32();
        // The same runs joined by degenerate triangles instead of restart
        // values: a driver that empties its vertex cache at each restart
        // keeps it across the joins.
        let mut aware_stitched = Vec::new();
        stitch_restart_buffer(&aware_strips, &mut aware_stitched);
        let ours = ex.buffer()[ex.active_range()].to_vec();
        let mut ours_stitched = Vec::new();
        stitch_restart_buffer(&ours, &mut ours_stitched);
        aware_ex.set_lod(lod);
        let ours_aware = aware_ex.buffer()[aware_ex.active_range()].to_vec();
        let flat = |t: &[[u32; 3]]| t.iter().flatten().copied().collect::<Vec<u32>>();
        for (method, buffer, topology) in [
            ("mts_strips", ours, Topology::StripRestart),
            ("mts_stitched", ours_stitched, Topology::StripRestart),
            ("mts_cache_aware", ours_aware, Topology::StripRestart),
            ("meshopt_strips", theirs, Topology::StripRestart),
            ("cache_aware_strips", aware_strips, Topology::StripRestart),
            (
                "cache_aware_stitched",
                aware_stitched,
                Topology::StripRestart,
            ),
            ("meshopt_list", flat(&ordered), Topology::List),
            ("list", flat(&oracle), Topology::List),
        ] {
            // What the GPU reads: the restart buffer, or its stitching.
            let drawn = if topology == Topology::List {
                renderer.upload_list(d, q, bytemuck_triangles(&buffer))?;
                buffer
            } else {
                renderer.upload_strip_indices(d, q, &buffer)?;
                match config.strip_mode {
                    StripMode::Restart => buffer,
                    StripMode::Stitched => {
                        let mut out = Vec::new();
                        stitch_restart_buffer(&buffer, &mut out);
                        out
                    }
                }
            };
            let triangles = model.triangle_count(lod);
            rows.push(vertex_row(
                &queries, d, q, target, &renderer, method, ratio, lod, triangles, &drawn, topology,
            )?);
        }
    }
    // The baselines' lists (their own vertex numbering), each at its
    // finest LoD within the MTS level's triangles.
    for method in [
        super::Method::Pm,
        super::Method::Multilevel,
        super::Method::Cluster,
        super::Method::Discrete,
    ] {
        if method == super::Method::Discrete && peers::meshopt::refusal(&mesh).is_some() {
            continue;
        }
        let mut source = super::make_source(method, model, &mesh)?;
        let mut renderer = StripRenderer::for_source(d, q, config, source.as_mut())?;
        renderer.set_camera(q, camera);
        for ratio in VERTEX_SHARES {
            let budget = model.triangle_count(model.lod_for_ratio(ratio));
            let lod = source.set_lod(mts::lod::lod_for_triangles(&*source, budget));
            renderer.upload_source(d, q, &*source)?;
            let topology = match source.topology() {
                mts::Topology::TriangleList => Topology::List,
                mts::Topology::StripRestart => Topology::StripRestart,
            };
            let name = format!("{}_list", source.name());
            let triangles = source.triangle_count(lod);
            let drawn = source.indices().to_vec();
            rows.push(vertex_row(
                &queries, d, q, target, &renderer, &name, ratio, lod, triangles, &drawn, topology,
            )?);
        }
    }
    // Share by share, finest first; methods in the order measured.
    rows.sort_by(|a, b| b.ratio.total_cmp(&a.ratio));
    let mut model_fit = BTreeMap::new();
    for (name, _) in REPORTED_MODELS {
        let logs: Option<Vec<f64>> = rows
            .iter()
            .map(|r| r.measured_over_modelled[name].map(f64::ln))
            .collect();
        let fit = logs.filter(|l| !l.is_empty()).map(|l| ModelFit {
            ratio_geomean: (l.iter().sum::<f64>() / l.len() as f64).exp(),
            mean_abs_log_ratio: l.iter().map(|x| x.abs()).sum::<f64>() / l.len() as f64,
        });
        model_fit.insert(name.to_string(), fit);
    }
    let best_model = model_fit
        .iter()
        .filter_map(|(n, f)| f.map(|f| (n.clone(), f.mean_abs_log_ratio)))
        .min_by(|a, b| a.1.total_cmp(&b.1))
        .map(|(n, _)| n);
    let mut missing = Vec::new();
    if !queries.has_statistics() {
        missing.push("pipeline statistics");
    }
    if !queries.has_timestamps() {
        missing.push("timestamps");
    }
    Ok(VertexWork {
        model: model_name.to_string(),
        pipeline_statistics: queries.has_statistics(),
        timestamps: queries.has_timestamps(),
        note: (!missing.is_empty())
            .then(|| format!("the adapter does not offer {}", missing.join(" or "))),
        clipper_mismatches: rows
            .iter()
            .filter(|r| r.clipper_matches_triangles == Some(false))
            .count() as u64,
        rows,
        model_fit,
        best_model,
    })
}

/// One vertex-work row: `renderer` drawn five times under the queries
/// (it holds `drawn`, `triangles` triangles of `method` at `lod`), beside
/// each cache model's invocations for `drawn`.
#[allow(clippy::too_many_arguments)]
fn vertex_row(
    queries: &mts_render::DrawQueries,
    d: &wgpu::Device,
    q: &wgpu::Queue,
    target: &HeadlessTarget,
    renderer: &StripRenderer,
    method: &str,
    ratio: f64,
    lod: usize,
    triangles: usize,
    drawn: &[u32],
    topology: mts::strip::vertex_work::Topology,
) -> Result<VertexRow> {
    use mts::strip::vertex_work::{vertex_work, REPORTED_MODELS};
    let mut times = Vec::new();
    let mut counts = None;
    for _ in 0..5 {
        let m = queries.measure(d, q, target, |pass| renderer.draw(pass))?;
        counts = m.counts;
        times.extend(m.gpu_ms);
    }
    times.sort_by(f64::total_cmp);
    let mut modelled = BTreeMap::new();
    let mut ratios = BTreeMap::new();
    for (name, cache) in REPORTED_MODELS {
        let w = vertex_work(drawn, topology, cache);
        modelled.insert(name.to_string(), w.invocations);
        ratios.insert(
            name.to_string(),
            counts.map(|c| c.vertex_invocations as f64 / w.invocations.max(1) as f64),
        );
    }
    Ok(VertexRow {
        ratio,
        lod: lod as u64,
        triangles: triangles as u64,
        method: method.to_string(),
        indices_sent: drawn.len() as u64,
        vertex_invocations: counts.map(|c| c.vertex_invocations),
        invocations_per_triangle: counts
            .map(|c| c.vertex_invocations as f64 / triangles.max(1) as f64),
        clipper_invocations: counts.map(|c| c.clipper_invocations),
        primitives_assembled: assembled(drawn, topology) as u64,
        clipper_matches_triangles: counts.map(|c| c.clipper_invocations == triangles as u64),
        fragment_invocations: counts.map(|c| c.fragment_invocations),
        gpu_ms: times.get(times.len() / 2).copied(),
        modelled,
        measured_over_modelled: ratios,
    })
}

/// Windows of three indices `buffer` assembles to (no restart inside).
fn assembled(buffer: &[u32], topology: mts::strip::vertex_work::Topology) -> usize {
    use mts::strip::encode::RESTART_U32;
    if topology == mts::strip::vertex_work::Topology::List {
        return buffer.len() / 3;
    }
    buffer
        .windows(3)
        .filter(|w| !w.contains(&RESTART_U32))
        .count()
}

/// A flat list as triangles (its length is a multiple of 3).
fn bytemuck_triangles(flat: &[u32]) -> &[[u32; 3]] {
    bytemuck::cast_slice(flat)
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
    outln!("{}", super::bench::scene_table_head())?;
    outln!("{}", super::bench::scene_table_row(r))
}

/// Frames of the path compared with full detail by `mts bench render`.
pub const SCENE_COMPARED_FRAMES: usize = 3;

/// What the scene rows measure.
pub struct SceneSpec<'t> {
    /// Instances (the models taken in turn).
    pub instances: usize,
    /// The screen-space errors allowed, in pixels: a row each.
    pub pixel_errors: &'t [f32],
    /// Frames along the camera path (timed).
    pub frames: usize,
    /// Frames of the path drawn also at full detail and compared (0 for
    /// none: full detail costs the full triangle count per instance).
    pub compared_frames: usize,
}

/// The path's frames compared with full detail: `k + 0.5` of `n` along.
fn compared_at(k: usize, n: usize) -> f32 {
    (k as f32 + 0.5) / n as f32
}

/// `spec.instances` instances of `models` (the demo layout) seen along the
/// fly-through path, a row per pixel error, each on a scene built afresh:
/// one untimed frame at the path's start, then `spec.frames` frames along
/// it, each an update (cull, LoD choice, extractions, uploads) and a draw,
/// timed apart; memory at its peak; and on `spec.compared_frames` frames
/// spread along the path the image of the instances (no ground) against
/// the same frame at full detail (drawn once for all rows): the share of
/// the pixels either covers whose colour differs at all, by more than
/// [`crate::figure6::IMAGE_TOLERANCE`], and whose coverage differs.
///
/// # Errors
/// As the scene's construction, update and drawing.
pub fn scene_rows(
    gpu: &Gpu,
    target: &HeadlessTarget,
    config: &RendererConfig,
    models: &[(String, &mts::MtsModel)],
    spec: &SceneSpec<'_>,
) -> Result<Vec<Scene>> {
    use crate::demo_scene::DemoScene;
    let (d, q) = (&gpu.device, &gpu.queue);
    let refs: Vec<&mts::MtsModel> = models.iter().map(|(_, m)| *m).collect();
    let (width, height) = target.size();
    let (aspect, h) = (target.aspect(), height as f32);
    let mut references = Vec::with_capacity(spec.compared_frames);
    {
        let mut full = DemoScene::new(d, q, config, &refs, spec.instances, &Default::default())?;
        for k in 0..spec.compared_frames {
            let camera = full.path_camera(compared_at(k, spec.compared_frames), aspect);
            full.update(d, q, &camera, h, 0.0)?;
            references.push(target.render_image(d, q, |pass| full.scene.draw(pass))?);
        }
    }
    let full_detail_strip_bytes = models
        .iter()
        .map(|(_, m)| {
            let mut ex = Extractor::new(m);
            ex.set_lod(0);
            let bytes = if m.positions().len() <= usize::from(u16::MAX) {
                2
            } else {
                4
            };
            bytes * ex.indices_sent() as u64
        })
        .sum();
    let frames = spec.frames.max(1);
    let at = |i: usize| i as f32 / (frames.max(2) - 1) as f32;
    let mut rows = Vec::with_capacity(spec.pixel_errors.len());
    for &pixel_error in spec.pixel_errors {
        let mut scene = DemoScene::new(d, q, config, &refs, spec.instances, &Default::default())?;
        scene.update(d, q, &scene.path_camera(0.0, aspect), h, pixel_error)?;
        target.render(d, q, |pass| scene.draw(pass))?;
        let (mut update, mut frame) = (Vec::with_capacity(frames), Vec::with_capacity(frames));
        let mut sums = [0f64; 6];
        let (mut buffers, mut gpu_bytes, mut extractions_max) = (0, 0, 0);
        for i in 0..frames {
            let camera = scene.path_camera(at(i), aspect);
            let t = Instant::now();
            let stats = scene.update(d, q, &camera, h, pixel_error)?;
            update.push(t.elapsed().as_secs_f64() * 1e3);
            target.render(d, q, |pass| scene.draw(pass))?;
            frame.push(t.elapsed().as_secs_f64() * 1e3);
            let memory = scene.scene.memory();
            buffers = buffers.max(memory.buffers);
            gpu_bytes = gpu_bytes.max(memory.gpu_bytes());
            extractions_max = extractions_max.max(stats.extractions);
            for (sum, x) in sums.iter_mut().zip([
                stats.visible,
                stats.triangles,
                stats.triangles_full_detail,
                stats.indices_drawn,
                stats.draws,
                stats.extractions,
            ]) {
                *sum += x as f64;
            }
        }
        let memory = scene.scene.memory();
        let mean = |x: f64| x / frames as f64;
        let percentile = |mut v: Vec<f64>, p: f64| {
            v.sort_by(f64::total_cmp);
            v[((v.len() - 1) as f64 * p).round() as usize]
        };
        let mut pixels = [0f64; 4];
        for (k, full) in references.iter().enumerate() {
            let camera = scene.path_camera(compared_at(k, spec.compared_frames), aspect);
            scene.update(d, q, &camera, h, pixel_error)?;
            let lod = target.render_image(d, q, |pass| scene.scene.draw(pass))?;
            let diff = full.difference(&lod, crate::figure6::IMAGE_TOLERANCE);
            pixels[0] += diff.pixels as f64;
            pixels[1] += diff.changed_share * diff.pixels as f64;
            pixels[2] += diff.share * diff.pixels as f64;
            pixels[3] += diff.coverage_changed as f64;
        }
        let share = |x: f64| (pixels[0] > 0.0).then(|| x / pixels[0]);
        rows.push(Scene {
            models: models.len() as u64,
            model_names: models.iter().map(|(n, _)| n.clone()).collect(),
            instances: spec.instances as u64,
            width,
            height,
            pixel_threshold: f64::from(pixel_error),
            frames: frames as u64,
            visible: mean(sums[0]),
            triangles_drawn: mean(sums[1]),
            triangles_full_detail: mean(sums[2]),
            indices_drawn: mean(sums[3]),
            draws: mean(sums[4]),
            extractions_per_frame: mean(sums[5]),
            extractions_max: extractions_max as u64,
            cpu_bytes_per_instance: memory.cpu_bytes_per_instance() as u64,
            cpu_shared_bytes: memory.cpu_shared_bytes as u64,
            gpu_bytes: gpu_bytes as u64,
            gpu_vertex_bytes: memory.gpu_vertex_bytes as u64,
            full_detail_strip_bytes,
            buffers: buffers as u64,
            update_ms_median: percentile(update.clone(), 0.5),
            update_ms_p99: percentile(update, 0.99),
            frame_ms_median: percentile(frame, 0.5),
            compared_frames: spec.compared_frames as u64,
            differing_pixel_share: share(pixels[1]),
            visibly_differing_pixel_share: share(pixels[2]),
            coverage_differing_pixel_share: share(pixels[3]),
        });
    }
    Ok(rows)
}
