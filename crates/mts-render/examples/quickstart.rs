//! The README's library example, the main path in one function: a mesh,
//! its MTS model, one level of detail extracted, drawn headless into a
//! PNG. Everything after this header is the README's `rust` block, byte
//! for byte (`tests/readme.rs` fails when they differ).
//!
//! Run with `cargo run --release -p mts-render --example quickstart`
//! (without a GPU, Mesa's lavapipe draws it).

use mts::mesh::generate::Generated;
use mts::model::{try_build_from_mesh, PipelineOptions};
use mts_render::{Camera, Gpu, HeadlessTarget, RendererConfig, StripRenderer};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mesh = "torus:20k".parse::<Generated>()?.build(); // or mts::mesh::io::load(path, opts)?.0
    let (model, _, _) = try_build_from_mesh(&mesh, &PipelineOptions::default(), &mut |_, _| {})?;
    let mut extractor = mts::Extractor::new(&model);
    let lod = extractor.set_ratio(0.1).lod; // the finest LoD with at most 10% of the triangles
    let gpu = Gpu::new_headless()?;
    let target = HeadlessTarget::new(&gpu.device, 640, 480)?;
    let config = RendererConfig::headless(gpu.report().strip_mode);
    let mut renderer = StripRenderer::for_model(&gpu.device, &gpu.queue, &config, &model)?;
    renderer.upload_strips(&gpu.device, &gpu.queue, &extractor)?; // then update_strips per change
    let camera = Camera::framing_points(model.positions(), target.aspect());
    renderer.set_camera(&gpu.queue, &camera);
    let image = target.render_image(&gpu.device, &gpu.queue, |pass| renderer.draw(pass))?;
    image.save_png(&std::env::temp_dir().join("mts-quickstart.png"))?;
    println!("LoD {lod}: {} pixels drawn", image.foreground_pixels());
    Ok(())
}
