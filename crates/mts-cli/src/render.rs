//! `mts render`: one LoD of a model drawn headless into a PNG, by the MTS
//! strips or by the oracle triangle list, through `mts_render`.

use super::{LevelArgs, MeshSource};
use crate::stdout::{outln, warnln};
use anyhow::Result;
use clap::{Args, ValueEnum};
use mts::{Extractor, MtsModel};
use mts_render::headless::HeadlessTarget;
use mts_render::{Camera, Gpu, RendererConfig, StripMode, StripRenderer};
use serde_json::json;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// What draws the LoD.
#[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum Method {
    /// The MTS strips the extractor emits at that LoD.
    Mts,
    /// The oracle triangle list (the contraction sequence replayed).
    List,
    /// The progressive-mesh baseline.
    Pm,
    /// The progressive multilevel mesh baseline.
    Multilevel,
    /// The cluster-tree baseline (its own LoDs: asked for the triangles of
    /// the MTS LoD).
    Cluster,
    /// meshoptimizer simplify at fixed ratios.
    Discrete,
}

impl Method {
    /// The baseline behind this choice, if it is one.
    fn baseline(self) -> Option<super::Method> {
        match self {
            Method::Mts | Method::List => None,
            Method::Pm => Some(super::Method::Pm),
            Method::Multilevel => Some(super::Method::Multilevel),
            Method::Cluster => Some(super::Method::Cluster),
            Method::Discrete => Some(super::Method::Discrete),
        }
    }
}

/// How strips reach the GPU.
#[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum StripModeArg {
    /// Restart, or stitching on a backend that ignores restart (GL).
    Auto,
    /// Primitive restart.
    Restart,
    /// Degenerate stitching.
    Stitched,
}

/// An image size `WxH`.
#[derive(Clone, Copy)]
pub struct Size(pub u32, pub u32);

impl std::str::FromStr for Size {
    type Err = String;
    fn from_str(s: &str) -> std::result::Result<Size, String> {
        let (w, h) = s
            .split_once(['x', 'X'])
            .ok_or_else(|| format!("expected WxH, got {s:?}"))?;
        let parse = |v: &str| {
            v.trim()
                .parse::<u32>()
                .map_err(|e| format!("{v:?} in {s:?}: {e}"))
        };
        Ok(Size(parse(w)?, parse(h)?))
    }
}

#[derive(Args)]
pub struct RenderArgs {
    /// An .mts model, or an OBJ/PLY mesh (the model is built on the fly).
    #[command(flatten)]
    source: MeshSource,
    /// The LoD to draw (the full mesh when none is given).
    #[command(flatten)]
    level: LevelArgs,
    /// The PNG to write.
    #[arg(short, long)]
    output: PathBuf,
    /// Image size in pixels.
    #[arg(long, default_value = "1024x768")]
    size: Size,
    /// MTS strips or the oracle triangle list.
    #[arg(long, value_enum, default_value_t = Method::Mts)]
    method: Method,
    /// How strips are sent to the GPU.
    #[arg(long, value_enum, default_value_t = StripModeArg::Auto)]
    strip_mode: StripModeArg,
    /// Print JSON instead of text.
    #[arg(long)]
    json: bool,
    /// Texture the model with a checker (shows UV distortion) instead of
    /// its own texture; needs texture coordinates (`--properties`, or a
    /// model built with them).
    #[arg(long)]
    checker: bool,
    /// Draw N instances of the model on a ground plane instead (each at
    /// the coarsest LoD within --pixel-error, drawn from buffers shared
    /// by LoD bucket; 1000 when N is left out).
    #[arg(long, value_name = "N", num_args = 0..=1, default_missing_value = "1000",
          conflicts_with_all = ["lod", "triangles", "ratio", "method"],
          allow_negative_numbers = true, value_parser = crate::count_in::<1, { MAX_SCENE }>)]
    scene: Option<usize>,
    /// With --scene: more models (OBJ/PLY meshes), their instances taken
    /// in turn with the command's model.
    #[arg(long, value_name = "MESH", num_args = 1.., requires = "scene")]
    scene_with: Vec<PathBuf>,
    /// With --scene: the screen-space error allowed, in pixels (0 draws
    /// every instance at full detail).
    #[arg(long, default_value_t = mts_render::scene::DEFAULT_PIXEL_ERROR, requires = "scene",
          allow_hyphen_values = true, value_parser = crate::pixel_error)]
    pixel_error: f32,
}

pub fn render(args: &RenderArgs) -> Result<()> {
    let mut inputs: Vec<&Path> = args.scene_with.iter().map(PathBuf::as_path).collect();
    inputs.extend(args.source.mesh.as_deref());
    crate::check_output(&args.output, &inputs)?;
    let Size(width, height) = args.size;
    let t0 = Instant::now();
    let (name, model) = args.source.model()?;
    let ms_model = t0.elapsed().as_secs_f64() * 1e3;
    if let Some(count) = args.scene {
        return render_scene(args, &name, &model, count);
    }
    let lod = args.level.resolve_model(&model)?.unwrap_or(0);
    let gpu = Gpu::new_headless()?;
    let mut report = gpu.report();
    report.strip_mode = match args.strip_mode {
        StripModeArg::Auto => report.strip_mode,
        StripModeArg::Restart => StripMode::Restart,
        StripModeArg::Stitched => StripMode::Stitched,
    };
    let config = RendererConfig::headless(report.strip_mode);
    let (device, queue) = (&gpu.device, &gpu.queue);
    let target = HeadlessTarget::new(device, width, height)?;
    let t1 = Instant::now();
    let (renderer, indices_sent, upload) = match args.method.baseline() {
        // A baseline numbers its vertices its own way: a renderer over them,
        // and its finest LoD within the MTS LoD's triangles.
        Some(b) => {
            let mut source = super::make_source(b, &model, &model.mesh())?;
            let mut r = StripRenderer::for_source(device, queue, &config, source.as_mut())?;
            let own = mts::lod::lod_for_triangles(&*source, model.triangle_count(lod));
            source.set_lod(own);
            let upload = r.upload_source(device, queue, &*source)?;
            (r, source.indices().len(), upload)
        }
        None => {
            let appearance = mts_render::texture::Appearance {
                checker: args.checker,
            };
            let mut r = StripRenderer::for_model_with(device, queue, &config, &model, &appearance)?;
            for w in r.warnings() {
                warnln!("{w}");
            }
            if args.method == Method::Mts {
                let mut ex = Extractor::new(&model);
                ex.set_lod(lod);
                let upload = r.upload_strips(device, queue, &ex)?;
                (r, ex.indices_sent(), upload)
            } else {
                let triangles = model.collapses().triangles_at(&model.mesh(), lod);
                let upload = r.upload_list(device, queue, &triangles)?;
                (r, 3 * triangles.len(), upload)
            }
        }
    };
    let ms_extract = t1.elapsed().as_secs_f64() * 1e3;
    renderer.set_camera(
        queue,
        &Camera::framing_points(model.positions(), target.aspect()),
    );
    let t2 = Instant::now();
    let image = target.render_image(device, queue, |pass| renderer.draw(pass))?;
    let ms_render = t2.elapsed().as_secs_f64() * 1e3;
    image.save_png(&args.output)?;
    let triangles = model.triangle_count(lod);
    // The name the command line spells it with.
    let method = args
        .method
        .to_possible_value()
        .map_or_else(String::new, |v| v.get_name().to_string());
    if args.json {
        outln!(
            "{}",
            json!({
                "input": name,
                "adapter": report.name,
                "backend": format!("{:?}", report.backend),
                "device_type": format!("{:?}", report.device_type),
                "strip_mode": report.strip_mode.to_string(),
                "method": method,
                "lod": lod,
                "max_lod": model.max_lod(),
                "triangles": triangles,
                "indices_sent": indices_sent,
                "indices_drawn": renderer.indices_drawn(),
                "upload_bytes": upload.bytes,
                "index_format": format!("{:?}", renderer.index_format()),
                "foreground_pixels": image.foreground_pixels(),
                "ms_model": ms_model,
                "ms_extract_upload": ms_extract,
                "ms_render_readback": ms_render,
                "output": args.output.display().to_string(),
            })
        )?;
    } else {
        print_text(&name, &report, &args.output)?;
        outln!(
            "  LoD {lod} of {}: {triangles} triangles by {method}, {indices_sent} indices sent \
             ({:.2} per triangle), {} drawn as {:?}",
            model.max_lod(),
            indices_sent as f64 / triangles.max(1) as f64,
            renderer.indices_drawn(),
            renderer.index_format()
        )?;
        outln!(
            "  time      model {ms_model:.1} ms, extract+upload {ms_extract:.2} ms, \
             render+readback {ms_render:.1} ms; {} foreground pixels of {}",
            image.foreground_pixels(),
            width as usize * height as usize
        )?;
    }
    Ok(())
}

fn print_text(name: &str, report: &mts_render::AdapterReport, output: &Path) -> Result<()> {
    outln!("{name} -> {}", output.display())?;
    outln!("  adapter   {report}")
}

/// Frames timed after the first (which extracts every visible instance).
const SCENE_FRAMES: usize = 5;

fn render_scene(args: &RenderArgs, name: &str, model: &MtsModel, count: usize) -> Result<()> {
    use crate::demo_scene::DemoScene;
    let Size(width, height) = args.size;
    let gpu = Gpu::new_headless()?;
    let report = gpu.report();
    let config = RendererConfig::headless(report.strip_mode);
    let (device, queue) = (&gpu.device, &gpu.queue);
    let target = HeadlessTarget::new(device, width, height)?;
    let appearance = mts_render::Appearance {
        checker: args.checker,
    };
    let others = crate::demo_scene::load_models(&args.scene_with)?;
    let mut models = vec![model];
    models.extend(others.iter().map(|(_, m)| m));
    let mut scene = DemoScene::new(device, queue, &config, &models, count, &appearance)?;
    let camera = scene.overview_camera(target.aspect());
    let pixel_error = args.pixel_error;
    let t = Instant::now();
    let first = scene.update(device, queue, &camera, height as f32, pixel_error)?;
    let ms_first_update = t.elapsed().as_secs_f64() * 1e3;
    let mut times = Vec::new();
    let mut stats = first;
    for _ in 0..SCENE_FRAMES {
        let t = Instant::now();
        stats = scene.update(device, queue, &camera, height as f32, pixel_error)?;
        target.render(device, queue, |pass| scene.draw(pass))?;
        times.push(t.elapsed().as_secs_f64() * 1e3);
    }
    times.sort_by(f64::total_cmp);
    let ms_frame = times[times.len() / 2];
    let image = target.render_image(device, queue, |pass| scene.draw(pass))?;
    image.save_png(&args.output)?;
    let memory = scene.scene.memory();
    if args.json {
        outln!(
            "{}",
            json!({
                "input": name,
                "adapter": report.name,
                "backend": format!("{:?}", report.backend),
                "strip_mode": report.strip_mode.to_string(),
                "device_type": format!("{:?}", report.device_type),
                "instances": count,
                "visible": stats.visible,
                "triangles": stats.triangles,
                "pixel_threshold": pixel_error,
                "triangles_full_detail": stats.triangles_full_detail,
                "indices_drawn": stats.indices_drawn,
                "draws": stats.draws,
                "buffers": memory.buffers,
                "first_update_extractions": first.extractions,
                "first_update_upload_bytes": first.upload_bytes,
                "ms_first_update": ms_first_update,
                "ms_frame": ms_frame,
                "fps": 1e3 / ms_frame,
                "cpu_bytes_per_instance": memory.cpu_bytes_per_instance(),
                "cpu_shared_bytes": memory.cpu_shared_bytes,
                "gpu_bytes": memory.gpu_bytes(),
                "gpu_vertex_bytes": memory.gpu_vertex_bytes,
                "output": args.output.display().to_string(),
            })
        )?;
    } else {
        print_text(name, &report, &args.output)?;
        outln!(
            "  scene     {count} instances, {} visible after culling: {} triangles ({:.1}% of full \
             detail) at {pixel_error} px, {} indices drawn in {} instanced draws",
            stats.visible,
            stats.triangles,
            100.0 * stats.triangles as f64 / stats.triangles_full_detail.max(1) as f64,
            stats.indices_drawn,
            stats.draws
        )?;
        outln!(
            "  time      first update {ms_first_update:.1} ms ({} buckets extracted, {} bytes \
             uploaded); frame {ms_frame:.1} ms ({:.1} fps, median of {SCENE_FRAMES})",
            first.extractions,
            first.upload_bytes,
            1e3 / ms_frame
        )?;
        outln!(
            "  memory    {} B CPU per instance, {:.1} KB CPU shared; GPU {:.1} KB in {} bucket \
             buffers and transforms, {:.1} KB vertices",
            memory.cpu_bytes_per_instance(),
            memory.cpu_shared_bytes as f64 / 1e3,
            memory.gpu_bytes() as f64 / 1e3,
            memory.buffers,
            memory.gpu_vertex_bytes as f64 / 1e3
        )?;
    }
    Ok(())
}

/// Most instances `--scene` lays out (`render`, `view`): about 220 bytes of
/// CPU and GPU memory each, so at most a few hundred MB.
const MAX_SCENE: u64 = 1 << 20;

/// Arguments of `mts view`.
#[derive(Args)]
pub struct ViewArgs {
    /// An .mts model, or an OBJ/PLY mesh (the model is built on the fly).
    #[command(flatten)]
    source: MeshSource,
    /// Show N instances on a ground plane instead (1000 when N is left
    /// out); `F` flies through them.
    #[arg(long, value_name = "N", num_args = 0..=1, default_missing_value = "1000",
          allow_negative_numbers = true, value_parser = crate::count_in::<1, { MAX_SCENE }>)]
    scene: Option<usize>,
    /// With --scene: more models (OBJ/PLY meshes), their instances taken
    /// in turn with the command's model.
    #[arg(long, value_name = "MESH", num_args = 1.., requires = "scene")]
    scene_with: Vec<PathBuf>,
    /// Quit after this many frames (scripted runs).
    #[arg(long)]
    frames: Option<u64>,
    /// Texture the model with a checker (shows UV distortion) instead of
    /// its own texture; needs texture coordinates (`--properties`, or a
    /// model built with them).
    #[arg(long)]
    checker: bool,
}

/// `mts view`: opens the viewer window.
pub fn view(args: &ViewArgs) -> Result<()> {
    use crate::viewer::{run, ViewerContent};
    let (name, model) = args.source.model()?;
    let content = match args.scene {
        Some(count) => ViewerContent::Scene {
            count,
            checker: args.checker,
        },
        None => ViewerContent::Model {
            checker: args.checker,
        },
    };
    let others = crate::demo_scene::load_models(&args.scene_with)?;
    let others: Vec<&MtsModel> = others.iter().map(|(_, m)| m).collect();
    let report = run(
        &model,
        &others,
        content,
        &format!("mts view: {name}"),
        args.frames,
    )?;
    outln!(
        "{name}: {} frames in {:.1} s on {}; last: {}",
        report.frames,
        report.seconds,
        report.adapter,
        report.last_status
    )?;
    Ok(())
}
