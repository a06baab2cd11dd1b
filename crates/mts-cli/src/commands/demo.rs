//! `mts demo`: the first thing a new user runs. On the built-in mesh (or a
//! file) it builds the model, sweeps the LoDs with and without the
//! coherence cache, renders a strip of thumbnails at several LoDs
//! (headless), and prints the side-by-side summary: indices sent by MTS
//! strips, a triangle list and meshoptimizer's strips of each level.

use crate::stdout::outln;
use anyhow::Result;
use mts::model::{build_from_mesh, requests, PipelineOptions};
use mts::Extractor;
use std::path::PathBuf;
use std::time::Instant;

#[derive(clap::Args)]
pub struct DemoArgs {
    #[command(flatten)]
    pub source: crate::args::MeshSource,
    /// Where the strip of thumbnails (PNG) goes.
    #[arg(long, default_value = "demo-thumbnails.png")]
    pub thumbnails: PathBuf,
}

/// `mts demo`: the demo on the command's mesh.
pub fn run(args: &DemoArgs) -> Result<()> {
    let (name, mesh, _) = args.source.load_for_scene()?;
    demo(&name, &mesh, &args.thumbnails)
}

/// Shares of the triangles shown as thumbnails, left to right.
const THUMBNAIL_SHARES: [f64; 5] = [1.0, 0.25, 0.05, 0.01, 0.002];
/// Side of one thumbnail in pixels.
const THUMBNAIL: u32 = 256;

/// Runs the demo on `mesh` (named `name`), prints its summary and writes
/// the thumbnails to `thumbnails` (when the renderer is built in).
pub fn demo(name: &str, mesh: &mts::Mesh, thumbnails: &std::path::Path) -> Result<()> {
    outln!(
        "{name}: {} triangles, {} vertices",
        mesh.triangle_count(),
        mesh.vertex_count()
    )?;
    let (model, stop, t) = build_from_mesh(mesh, &PipelineOptions::default(), &mut |_, _| {});
    let ms = |d: std::time::Duration| d.as_secs_f64() * 1e3;
    outln!(
        "built the MTS model in {:.0} ms (strips {:.0} ms beside the contraction sequence {:.0} ms, graphs {:.0} ms): {} LoDs down to {} triangles, {} bands, {} strips at LoD 0",
        ms(t.total),
        ms(t.stripify),
        ms(t.simplify),
        ms(t.model),
        model.max_lod() + 1,
        stop.triangles,
        model.band_count(),
        model.base_strips().run_count(),
    )?;
    let file_bytes = model
        .to_streamed_bytes(
            mts::model::compress::DEFAULT_LEVEL,
            &mts::model::DEFAULT_PREFIX_SHARES,
        )
        .len();
    outln!(
        ".mts file {file_bytes} bytes = {:.2} x the raw mesh (12 bytes per vertex + 12 per triangle), as `mts build` writes it",
        file_bytes as f64 / model.raw_bytes() as f64
    )?;
    // A sweep from the coarsest LoD to the full mesh, one LoD at a time
    // over a window, as a viewer zooming in would ask for them.
    let lods = requests::linear(model.max_lod(), model.max_lod() + 1);
    let mut ex = Extractor::new(&model);
    let t0 = Instant::now();
    let mut walked = 0;
    for &l in &lods {
        walked += ex.set_lod(l).strips_walked;
    }
    let coherent = t0.elapsed().as_secs_f64() * 1e6 / lods.len() as f64;
    let sample: Vec<usize> = lods.iter().step_by(50).copied().collect();
    let t0 = Instant::now();
    for &l in &sample {
        ex.set_lod_from_scratch(l);
    }
    let scratch = t0.elapsed().as_secs_f64() * 1e6 / sample.len().max(1) as f64;
    outln!(
        "swept all {} LoDs coarsest to finest: {coherent:.1} us per LoD with the coherence cache ({:.1} strips walked per step), {scratch:.1} us from scratch ({:.0}x)",
        lods.len(),
        walked as f64 / lods.len() as f64,
        scratch / coherent
    )?;
    let levels = crate::bench::measure::measure_levels(&model);
    outln!()?;
    outln!(
        "{:>6} {:>9} {:>12} {:>12} {:>14} {:>10} {:>12}",
        "share",
        "triangles",
        "MTS strips",
        "tri. list",
        "meshopt strips",
        "MTS/list",
        "extract us"
    )?;
    for l in &levels {
        outln!(
            "{:>5.0}% {:>9} {:>12} {:>12} {:>14} {:>10.3} {:>12.1}",
            l.share * 100.0,
            l.triangles,
            l.mts_indices,
            l.list_indices,
            l.meshopt_strip_indices,
            l.mts_indices as f64 / l.list_indices as f64,
            l.extract_us,
        )?;
    }
    match render_thumbnails(&model, thumbnails) {
        Ok(line) => outln!("\n{line}")?,
        Err(e) => outln!("\nthumbnails skipped: {e:#}")?,
    }
    outln!("\n(indices sent to the GPU per level: MTS strips with restart values, the triangle list, meshoptimizer's strips of that level's mesh; `mts bench` measures the full tables)")?;
    Ok(())
}

/// Draws the model's strips at [`THUMBNAIL_SHARES`] side by side into one
/// PNG (headless; Mesa's lavapipe without a GPU) and says what it drew.
fn render_thumbnails(model: &mts::MtsModel, path: &std::path::Path) -> Result<String> {
    use mts_render::headless::{HeadlessTarget, Image};
    use mts_render::{Camera, Gpu, RendererConfig, StripRenderer};
    let gpu = Gpu::new_headless()?;
    let report = gpu.report();
    let config = RendererConfig::headless(report.strip_mode);
    let (device, queue) = (&gpu.device, &gpu.queue);
    let mut renderer = StripRenderer::for_model(device, queue, &config, model)?;
    let target = HeadlessTarget::new(device, THUMBNAIL, THUMBNAIL)?;
    renderer.set_camera(queue, &Camera::framing_points(model.positions(), 1.0));
    let n = THUMBNAIL_SHARES.len() as u32;
    let mut strip = Image {
        width: THUMBNAIL * n,
        height: THUMBNAIL,
        rgba: vec![0; (4 * THUMBNAIL * THUMBNAIL * n) as usize],
    };
    let mut ex = Extractor::new(model);
    let mut labels = Vec::new();
    // Coarse to fine would upload less; the order of the picture is fine to
    // coarse, and every change uploads only its dirty ranges anyway.
    for (i, &share) in THUMBNAIL_SHARES.iter().enumerate() {
        let lod = model.lod_for_ratio(share);
        ex.set_lod(lod);
        renderer.upload_strips(device, queue, &ex)?;
        let image = target.render_image(device, queue, |pass| renderer.draw(pass))?;
        let row = 4 * THUMBNAIL as usize;
        for y in 0..THUMBNAIL as usize {
            let from = y * row;
            let to = y * row * n as usize + i * row;
            strip.rgba[to..to + row].copy_from_slice(&image.rgba[from..from + row]);
        }
        labels.push(format!("{} triangles", model.triangle_count(lod)));
    }
    strip.save_png(path)?;
    Ok(format!(
        "thumbnails ({}) on {}: {}",
        labels.join(", "),
        report.name,
        path.display()
    ))
}
