//! `mts render`: one LoD of a model drawn headless into a PNG, by the MTS
//! strips or by the oracle triangle list, through `mts_render`; a glTF file
//! of several parts drawn as a scene of them ([`GltfScene`]); a
//! view-dependent hierarchy (a version-4 `.mts` file, or `--hierarchy`:
//! built from the mesh) drawn as its cut for the camera
//! ([`mts_render::HierarchyRenderer`]).

use crate::args::{LevelArgs, MeshSource};
use crate::commands::verify::peek_holds;
use crate::gltf_scene::GltfScene;
use crate::stdout::{outln, warnln};
use anyhow::{bail, Result};
use clap::builder::TypedValueParser;
use clap::{Args, ValueEnum};
use mts::hierarchy::{Hierarchy, HierarchyOptions, ViewDependent};
use mts::methods::Method;
use mts::model::format::Holds;
use mts::{Extractor, MtsModel};
use mts_render::headless::HeadlessTarget;
use mts_render::{Camera, Gpu, HierarchyRenderer, RendererConfig, StripMode, StripRenderer};
use serde_json::json;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// What draws the LoD: the MTS strips, the oracle list, or a baseline's
/// index buffer (`--method mts|list|pm|multilevel|cluster|discrete`).
#[derive(Clone, Copy, PartialEq, Eq)]
pub enum Draw {
    /// One of the LoD methods ([`Method::Mts`]: the strips the extractor
    /// emits at that LoD; a baseline: its finest LoD within the MTS LoD's
    /// triangles, numbered its own way).
    Method(Method),
    /// The oracle triangle list (the contraction sequence replayed).
    List,
}

impl Draw {
    /// The name the command line spells it with.
    fn name(self) -> &'static str {
        match self {
            Draw::Method(m) => m.name(),
            Draw::List => "list",
        }
    }

    /// The baseline behind this choice, if it is one.
    fn baseline(self) -> Option<Method> {
        match self {
            Draw::Method(Method::Mts) | Draw::List => None,
            Draw::Method(m) => Some(m),
        }
    }
}

/// `--method`: `list` or a method's name.
fn draw_parser() -> impl clap::builder::TypedValueParser<Value = Draw> {
    let mut names: Vec<&'static str> = Method::ALL.iter().map(|m| m.name()).collect();
    names.insert(1, "list");
    clap::builder::PossibleValuesParser::new(names).map(|name| {
        Method::ALL
            .iter()
            .find(|m| m.name() == name)
            .map_or(Draw::List, |&m| Draw::Method(m))
    })
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
    /// An .mts model, or an OBJ/PLY/glTF mesh (the model is built on the
    /// fly). A glTF file of several parts (mesh primitives) is drawn as a
    /// scene: each part with its own texture or material colour, once per
    /// node that holds it, each at the coarsest LoD within --pixel-error.
    /// A hierarchy's .mts file (`mts build --hierarchy`) is drawn as its
    /// cut for the camera within --pixel-error.
    #[command(flatten)]
    source: MeshSource,
    /// Build the view-dependent hierarchy of the mesh (or --generated)
    /// and draw its cut for the camera, every part within --pixel-error
    /// (groups simplified where they are far, full detail near).
    #[arg(long, conflicts_with_all = ["lod", "triangles", "ratio", "scene"])]
    hierarchy: bool,
    /// The LoD to draw (the full mesh when none is given).
    #[command(flatten)]
    level: LevelArgs,
    /// The PNG to write.
    #[arg(short, long)]
    output: PathBuf,
    /// Image size in pixels.
    #[arg(long, default_value = "1024x768")]
    size: Size,
    /// MTS strips, the oracle triangle list, or a baseline (its finest LoD
    /// within the MTS LoD's triangles).
    #[arg(long, value_parser = draw_parser(), default_value = "mts")]
    method: Draw,
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
          allow_negative_numbers = true, value_parser = crate::args::count_in::<1, { MAX_SCENE }>)]
    scene: Option<usize>,
    /// With --scene: more models (OBJ/PLY meshes), their instances taken
    /// in turn with the command's model.
    #[arg(long, value_name = "MESH", num_args = 1.., requires = "scene")]
    scene_with: Vec<PathBuf>,
    /// In a scene (--scene, or a glTF file of several parts) or a
    /// hierarchy: the screen-space error allowed, in pixels (0 draws every
    /// instance, or the whole hierarchy, at full detail) [default: 1].
    #[arg(long, allow_hyphen_values = true, value_parser = crate::args::pixel_error)]
    pixel_error: Option<f32>,
}

impl RenderArgs {
    /// The pixel threshold of a scene's LoD choice.
    fn pixel_threshold(&self) -> f32 {
        self.pixel_error
            .unwrap_or(mts_render::scene::DEFAULT_PIXEL_ERROR)
    }
}

pub fn run(args: &RenderArgs) -> Result<()> {
    let mut inputs: Vec<&Path> = args.scene_with.iter().map(PathBuf::as_path).collect();
    inputs.extend(args.source.mesh.as_deref());
    crate::args::check_output(&args.output, &inputs)?;
    let Size(width, height) = args.size;
    let t0 = Instant::now();
    if let Some((name, h)) = load_hierarchy(&args.source, args.hierarchy)? {
        let ms_model = t0.elapsed().as_secs_f64() * 1e3;
        return render_hierarchy(args, &name, &h, ms_model);
    }
    if let (None, Some(path)) = (args.scene, &args.source.mesh) {
        if let Some(scene) = GltfScene::load_if_several(path, args.source.load_options())? {
            return render_gltf(args, &scene);
        }
    }
    if args.scene.is_none() && args.pixel_error.is_some() {
        bail!(
            "--pixel-error chooses the LoDs of a scene (--scene, or a glTF file of several \
             parts) or of a hierarchy (--hierarchy); one model is drawn at --lod, --triangles \
             or --ratio"
        );
    }
    let (name, model) = args.source.model()?;
    let ms_model = t0.elapsed().as_secs_f64() * 1e3;
    if let Some(count) = args.scene {
        return render_scene(args, &name, &model, count);
    }
    let lod = args.level.resolve_model(&model)?.unwrap_or(0);
    let (gpu, report, config, target) = headless(args, width, height)?;
    let (device, queue) = (&gpu.device, &gpu.queue);
    let t1 = Instant::now();
    let (renderer, indices_sent, upload) = match args.method.baseline() {
        // A baseline numbers its vertices its own way: a renderer over them,
        // and its finest LoD within the MTS LoD's triangles.
        Some(b) => {
            let mut source = b.source(&model, &model.mesh())?;
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
            if args.method == Draw::Method(Method::Mts) {
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
    let method = args.method.name();
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

/// The hierarchy a command draws: a version-4 `.mts` file (recognised by
/// its header, with or without `build`), or with `build` the hierarchy of
/// the mesh or `--generated` built now with the default options; `None`
/// otherwise.
pub(crate) fn load_hierarchy(
    source: &MeshSource,
    build: bool,
) -> Result<Option<(String, Hierarchy)>> {
    if let Some(path) = &source.mesh {
        match peek_holds(path) {
            Some(Holds::Hierarchy) => {
                let h = Hierarchy::load(path)?;
                return Ok(Some((path.display().to_string(), h)));
            }
            Some(Holds::Model) if build => bail!(
                "{}: an MTS model's file; --hierarchy builds the hierarchy of a mesh (`mts build \
                 --hierarchy` writes one to a file)",
                path.display()
            ),
            _ => {}
        }
    }
    if !build {
        return Ok(None);
    }
    let (name, mesh, _) = source.load()?;
    if mesh.triangle_count() >= HIERARCHY_NOTE_TRIANGLES {
        warnln!(
            "{name}: building the hierarchy of {} triangles first (`mts build --hierarchy` \
             writes it to a file once)",
            mesh.triangle_count()
        );
    }
    let h = mts::hierarchy::build(&mesh, &HierarchyOptions::default())?;
    Ok(Some((name, h)))
}

/// Inputs of this many triangles or more get a note that `--hierarchy`
/// builds the hierarchy first.
const HIERARCHY_NOTE_TRIANGLES: usize = 500_000;

/// `mts render` of a hierarchy: its cut for the default camera (as a
/// model's, framing the input's bounds) within `--pixel-error`, culled to
/// the view, drawn by the strips of its arena (`--method mts`) or by the
/// cut's triangles as a list from scratch (`--method list`, the oracle).
fn render_hierarchy(args: &RenderArgs, name: &str, h: &Hierarchy, ms_model: f64) -> Result<()> {
    if args.level.lod.is_some() || args.level.triangles.is_some() || args.level.ratio.is_some() {
        bail!(
            "{name}: a hierarchy draws every part at the coarsest LoD within --pixel-error; \
             --lod, --triangles and --ratio choose one model's"
        );
    }
    if args.scene.is_some() {
        bail!("{name}: a hierarchy is drawn alone; --scene lays out instances of one model");
    }
    let list = match args.method {
        Draw::Method(Method::Mts) => false,
        Draw::List => true,
        Draw::Method(m) => bail!(
            "{name}: a hierarchy is drawn by its strips (--method mts) or its cut's triangle \
             list (--method list), not by {}",
            m.name()
        ),
    };
    let Size(width, height) = args.size;
    let (gpu, report, config, target) = headless(args, width, height)?;
    let (device, queue) = (&gpu.device, &gpu.queue);
    let appearance = mts_render::Appearance {
        checker: args.checker,
    };
    let mut renderer = HierarchyRenderer::with_appearance(device, queue, &config, h, &appearance)?;
    for w in renderer.warnings() {
        warnln!("{w}");
    }
    let camera = Camera::framing_points(h.positions(), target.aspect());
    let pixel_error = args.pixel_threshold();
    let mut view = ViewDependent::new(h);
    let t = Instant::now();
    let frame = renderer.update(
        device,
        queue,
        &mut view,
        &camera,
        height as f32,
        pixel_error,
        true,
    )?;
    let (triangles, indices_sent, upload) = if list {
        let triangles = view.cut().triangles(h);
        let upload = renderer
            .strip_renderer_mut()
            .upload_list(device, queue, &triangles)?;
        (triangles.len(), 3 * triangles.len(), upload)
    } else {
        (frame.triangles, frame.indices_sent, frame.upload)
    };
    let ms_update = t.elapsed().as_secs_f64() * 1e3;
    let t = Instant::now();
    let image = target.render_image(device, queue, |pass| {
        if list {
            renderer.strip_renderer().draw(pass);
        } else {
            renderer.draw(pass);
        }
    })?;
    let ms_render = t.elapsed().as_secs_f64() * 1e3;
    image.save_png(&args.output)?;
    let indices_drawn = if list {
        renderer.strip_renderer().indices_drawn()
    } else {
        frame.indices_drawn
    };
    let method = args.method.name();
    let full = h.triangle_count();
    if args.json {
        return outln!(
            "{}",
            json!({
                "input": name,
                "hierarchy": true,
                "adapter": report.name,
                "backend": format!("{:?}", report.backend),
                "device_type": format!("{:?}", report.device_type),
                "strip_mode": report.strip_mode.to_string(),
                "method": method,
                "pixel_threshold": pixel_error,
                "levels": h.level_count(),
                "groups": h.groups().len(),
                "clusters": h.clusters().len(),
                "groups_drawn": frame.update.groups_drawn,
                "clusters_drawn": frame.update.clusters_drawn,
                "triangles": triangles,
                "triangles_full_detail": full,
                "indices_sent": indices_sent,
                "indices_drawn": indices_drawn,
                "upload_bytes": upload.bytes,
                "gpu_bytes": renderer.gpu_bytes(),
                "cpu_bytes": frame.cpu_bytes,
                "index_format": format!("{:?}", renderer.index_format()),
                "foreground_pixels": image.foreground_pixels(),
                "ms_model": ms_model,
                "ms_update_upload": ms_update,
                "ms_render_readback": ms_render,
                "output": args.output.display().to_string(),
            })
        );
    }
    print_text(name, &report, &args.output)?;
    outln!(
        "  hierarchy {} levels, {} groups, {} clusters; the cut within {pixel_error} px: {} \
         groups and {} clusters drawn (culled to the view)",
        h.level_count(),
        h.groups().len(),
        h.clusters().len(),
        frame.update.groups_drawn,
        frame.update.clusters_drawn
    )?;
    outln!(
        "  drawn     {triangles} triangles of {full} ({:.1}%) by {method}, {indices_sent} indices \
         sent ({:.2} per triangle), {indices_drawn} drawn as {:?}; GPU {:.1} KB",
        100.0 * triangles as f64 / full.max(1) as f64,
        indices_sent as f64 / triangles.max(1) as f64,
        renderer.index_format(),
        renderer.gpu_bytes() as f64 / 1e3
    )?;
    outln!(
        "  time      hierarchy (load or build) {ms_model:.1} ms, update+upload {ms_update:.2} ms, render+readback \
         {ms_render:.1} ms; {} foreground pixels of {}",
        image.foreground_pixels(),
        width as usize * height as usize
    )
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
    let pixel_error = args.pixel_threshold();
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

/// Part lines the text report prints before it says how many more there
/// are (the JSON lists every part).
const PART_LINES: usize = 20;

/// `mts render` of a glTF file of several parts: every part a model of the
/// instanced scene, one instance per node, LoDs by `--pixel-error`, the
/// camera framing every instance.
fn render_gltf(args: &RenderArgs, scene: &GltfScene) -> Result<()> {
    if args.level.lod.is_some() || args.level.triangles.is_some() || args.level.ratio.is_some() {
        bail!(
            "{}: a scene of {} parts draws each instance at the coarsest LoD within \
             --pixel-error; --lod, --triangles and --ratio choose one model's (`mts build` \
             merges the parts into one)",
            scene.name,
            scene.part_count
        );
    }
    if args.method != Draw::Method(Method::Mts) {
        bail!(
            "{}: a scene of {} parts is drawn by the MTS strips only; --method chooses how one \
             model is drawn (`mts build` merges the parts into one)",
            scene.name,
            scene.part_count
        );
    }
    let Size(width, height) = args.size;
    let (gpu, report, config, target) = headless(args, width, height)?;
    let (device, queue) = (&gpu.device, &gpu.queue);
    let appearance = mts_render::Appearance {
        checker: args.checker,
    };
    let (mut instanced, instances) = scene.scene(device, queue, &config, &appearance)?;
    let camera = scene.camera(target.aspect());
    let pixel_error = args.pixel_threshold();
    let t = Instant::now();
    let stats = instanced.update(device, queue, &camera, height as f32, pixel_error)?;
    let ms_update = t.elapsed().as_secs_f64() * 1e3;
    let t = Instant::now();
    let image = target.render_image(device, queue, |pass| instanced.draw(pass))?;
    let ms_render = t.elapsed().as_secs_f64() * 1e3;
    image.save_png(&args.output)?;
    let parts: Vec<_> = scene
        .models
        .iter()
        .zip(&instances)
        .map(|(m, ids)| {
            let lods: Vec<Option<usize>> = ids.iter().map(|&i| instanced.lod_of(i)).collect();
            let texture = ids.first().and_then(|i| instanced.texture_size(i.model()));
            (m, lods, texture)
        })
        .collect();
    let instance_count = scene.instance_count();
    if args.json {
        let parts: Vec<_> = parts
            .iter()
            .map(|(m, lods, texture)| {
                json!({
                    "mesh": m.mesh,
                    "primitive": m.primitive,
                    "name": m.name,
                    "mirrored": m.mirrored,
                    "triangles": m.model.triangle_count(0),
                    "max_lod": m.model.max_lod(),
                    "instances": lods.len(),
                    "lods": lods,
                    "texture": texture.map(|(w, h)| [w, h]),
                })
            })
            .collect();
        outln!(
            "{}",
            json!({
                "input": scene.name,
                "adapter": report.name,
                "backend": format!("{:?}", report.backend),
                "device_type": format!("{:?}", report.device_type),
                "strip_mode": report.strip_mode.to_string(),
                "part_count": scene.part_count,
                "parts": parts,
                "instances": instance_count,
                "visible": stats.visible,
                "triangles": stats.triangles,
                "triangles_full_detail": stats.triangles_full_detail,
                "pixel_threshold": pixel_error,
                "indices_drawn": stats.indices_drawn,
                "draws": stats.draws,
                "camera": {
                    "view_proj": camera.view_proj.to_cols_array(),
                    "light_dir": camera.light_dir.to_array(),
                },
                "foreground_pixels": image.foreground_pixels(),
                "ms_update": ms_update,
                "ms_render_readback": ms_render,
                "output": args.output.display().to_string(),
            })
        )?;
        return Ok(());
    }
    print_text(&scene.name, &report, &args.output)?;
    outln!(
        "  scene     {} parts, {instance_count} instances ({} visible): {} triangles of {} at full \
         detail within {pixel_error} px, {} indices drawn in {} instanced draws",
        scene.part_count,
        stats.visible,
        stats.triangles,
        stats.triangles_full_detail,
        stats.indices_drawn,
        stats.draws
    )?;
    for (m, lods, texture) in parts.iter().take(PART_LINES) {
        let mut drawn: Vec<usize> = lods.iter().flatten().copied().collect();
        drawn.sort_unstable();
        drawn.dedup();
        let drawn: Vec<String> = drawn.iter().map(usize::to_string).collect();
        outln!(
            "  part      {}: {} triangles, {} instance{} ({} drawn, at LoD {}), {}",
            m.label(),
            m.model.triangle_count(0),
            lods.len(),
            if lods.len() == 1 { "" } else { "s" },
            lods.iter().flatten().count(),
            if drawn.is_empty() {
                "-".into()
            } else {
                drawn.join(", ")
            },
            texture.map_or_else(|| "untextured".into(), |(w, h)| format!("textured {w}x{h}"))
        )?;
    }
    if parts.len() > PART_LINES {
        outln!(
            "  part      ... {} more (--json lists them all)",
            parts.len() - PART_LINES
        )?;
    }
    outln!(
        "  time      update+extract {ms_update:.2} ms, render+readback {ms_render:.1} ms; {} \
         foreground pixels of {}",
        image.foreground_pixels(),
        width as usize * height as usize
    )
}

/// Most instances `--scene` lays out (`render`, `view`): about 220 bytes of
/// CPU and GPU memory each, so at most a few hundred MB.
pub const MAX_SCENE: u64 = 1 << 20;

/// The headless adapter, its report with the strip mode `--strip-mode`
/// asks for, the renderer configuration of that mode and a `width` ×
/// `height` target.
fn headless(
    args: &RenderArgs,
    width: u32,
    height: u32,
) -> Result<(
    Gpu,
    mts_render::AdapterReport,
    RendererConfig,
    HeadlessTarget,
)> {
    let gpu = Gpu::new_headless()?;
    let mut report = gpu.report();
    report.strip_mode = match args.strip_mode {
        StripModeArg::Auto => report.strip_mode,
        StripModeArg::Restart => StripMode::Restart,
        StripModeArg::Stitched => StripMode::Stitched,
    };
    let config = RendererConfig::headless(report.strip_mode);
    let target = HeadlessTarget::new(&gpu.device, width, height)?;
    Ok((gpu, report, config, target))
}
