//! `mts view`: a window on a model (orbit camera, LoD by wheel or by
//! screen-space error), on a scene of instances (`--scene`), on a glTF
//! file of several parts, or on a view-dependent hierarchy (a version-4
//! `.mts` file, or `--hierarchy`: built from the mesh); the window itself
//! is [`crate::viewer`].

use super::render::MAX_SCENE;
use crate::args::MeshSource;
use crate::gltf_scene::GltfScene;
use crate::stdout::outln;
use anyhow::Result;
use clap::Args;
use mts::MtsModel;
use std::path::PathBuf;

/// Arguments of `mts view`.
#[derive(Args)]
pub struct ViewArgs {
    /// An .mts model, or an OBJ/PLY/glTF mesh (the model is built on the
    /// fly). A glTF file of several parts (mesh primitives) is shown as a
    /// scene: each part with its own texture or material colour, once per
    /// node that holds it, each at the coarsest LoD within one pixel. A
    /// hierarchy's .mts file (`mts build --hierarchy`) is shown as its cut
    /// for the camera, updated every frame.
    #[command(flatten)]
    source: MeshSource,
    /// Build the view-dependent hierarchy of the mesh (or --generated)
    /// and show its cut, chosen again every frame for the camera within
    /// the pixel error (the wheel changes it) and culled to the view.
    #[arg(long, conflicts_with = "scene")]
    hierarchy: bool,
    /// Show N instances on a ground plane instead (1000 when N is left
    /// out); `F` flies through them.
    #[arg(long, value_name = "N", num_args = 0..=1, default_missing_value = "1000",
          allow_negative_numbers = true, value_parser = crate::args::count_in::<1, { MAX_SCENE }>)]
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
    /// Show an .mts model as if its file arrived at this many bytes a
    /// second (e.g. 500000): the coarsest chunk of a version-6 file
    /// (what `mts build` writes) first, refined as each later chunk and
    /// then the whole file arrive (`mts extract --bytes N` opens the same
    /// prefixes).
    #[arg(long, value_name = "BYTES_PER_S", value_parser = arrive_rate,
          conflicts_with_all = ["scene", "hierarchy"])]
    arrive: Option<f64>,
}

fn arrive_rate(s: &str) -> std::result::Result<f64, String> {
    match s.parse::<f64>() {
        Ok(r) if r.is_finite() && r >= 1.0 => Ok(r),
        _ => Err(format!("{s:?} is not a rate of at least 1 byte a second")),
    }
}

/// `view --arrive`: the model's file opened prefix by prefix, each
/// arriving after its bytes at `rate` bytes a second.
fn run_streamed(args: &ViewArgs, rate: f64) -> Result<()> {
    use crate::viewer::{run_streamed, Arrivals};
    let Some(path) = args.source.mesh.clone() else {
        anyhow::bail!("--arrive shows an .mts file as it arrives: give one");
    };
    let bytes = mts::mesh::io::read_file(&path)?;
    if !bytes.starts_with(mts::model::format::MAGIC) {
        anyhow::bail!(
            "{}: --arrive shows an .mts file (`mts build` writes one), not a mesh",
            path.display()
        );
    }
    let chunks = mts::model::chunk_index(&bytes, &path)?;
    let ends: Vec<usize> = chunks
        .iter()
        .map(|c| c.end)
        .chain(std::iter::once(bytes.len()))
        .collect();
    // The first chunk shows once its bytes have arrived.
    std::thread::sleep(std::time::Duration::from_secs_f64(ends[0] as f64 / rate));
    let first = MtsModel::from_prefix(&bytes[..ends[0]], &path)?;
    let full_triangles = first.full_triangles;
    let (send, receiver) = std::sync::mpsc::channel();
    let started = std::time::Instant::now();
    let file = path.clone();
    let file_bytes = bytes.len() as u64;
    std::thread::spawn(move || {
        for &end in &ends[1..] {
            let due = std::time::Duration::from_secs_f64(end as f64 / rate);
            std::thread::sleep(due.saturating_sub(started.elapsed()));
            if send
                .send(MtsModel::from_prefix(&bytes[..end], &file))
                .is_err()
            {
                return;
            }
        }
    });
    let name = path.display().to_string();
    let report = run_streamed(
        first,
        Arrivals {
            receiver,
            full_triangles,
            file_bytes,
        },
        args.checker,
        &format!("mts view: {name} (arriving)"),
        args.frames,
    )?;
    closing_line(&name, &report)
}

/// `mts view`: opens the viewer window.
pub fn run(args: &ViewArgs) -> Result<()> {
    use crate::viewer::{run, run_gltf, run_hierarchy, ViewerContent};
    if let Some(rate) = args.arrive {
        return run_streamed(args, rate);
    }
    if let Some((name, h)) = super::render::load_hierarchy(&args.source, args.hierarchy)? {
        if args.scene.is_some() {
            anyhow::bail!(
                "{name}: a hierarchy is shown alone; --scene lays out instances of one model"
            );
        }
        let title = format!("mts view: {name} (hierarchy)");
        let report = run_hierarchy(&h, args.checker, &title, args.frames)?;
        return outln!(
            "{name}: a hierarchy of {} triangles, {} groups: {} frames in {:.1} s on {}; last: {}",
            h.triangle_count(),
            h.groups().len(),
            report.frames,
            report.seconds,
            report.adapter,
            report.last_status
        );
    }
    if let (None, Some(path)) = (args.scene, &args.source.mesh) {
        if let Some(scene) = GltfScene::load_if_several(path, args.source.load_options())? {
            let title = format!("mts view: {} ({} parts)", scene.name, scene.part_count);
            let report = run_gltf(&scene, args.checker, &title, args.frames)?;
            return outln!(
                "{}: {} parts, {} instances: {} frames in {:.1} s on {}; last: {}",
                scene.name,
                scene.part_count,
                scene.instance_count(),
                report.frames,
                report.seconds,
                report.adapter,
                report.last_status
            );
        }
    }
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
    closing_line(&name, &report)
}

/// The line `view` prints when its window closes.
fn closing_line(name: &str, report: &crate::viewer::ViewerReport) -> Result<()> {
    outln!(
        "{name}: {} frames in {:.1} s on {}; last: {}",
        report.frames,
        report.seconds,
        report.adapter,
        report.last_status
    )?;
    Ok(())
}
