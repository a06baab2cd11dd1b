//! The instanced scene measured along its camera path: frame times,
//! triangles, LoD changes and the images against full detail (`mts bench
//! render --scene`, the report's scene table): pixels that differ, and the
//! image-error ratio against a supersampled reference
//! ([`mts_render::image_error`]).

use crate::bench::results::Scene;
use anyhow::Result;
use mts::Extractor;
use mts_render::headless::HeadlessTarget;
use mts_render::image_error::{ImageError, ReferenceTarget};
use mts_render::{Gpu, RendererConfig};
use std::time::Instant;

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
/// [`crate::bench::results::IMAGE_TOLERANCE`], and whose coverage differs;
/// and the image-error ratio ([`ImageError::ratio`], pooled over those
/// frames): against the full-detail frame drawn 4 × 4 times denser and
/// box-filtered, the LoD frame's RMSE over the full-detail frame's.
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
    // Per compared frame: full detail at one sample per pixel, and the
    // reference it is measured against with the LoD frames.
    let mut full_frames = Vec::with_capacity(spec.compared_frames);
    if spec.compared_frames > 0 {
        let mut full = DemoScene::new(d, q, config, &refs, spec.instances, &Default::default())?;
        let supersampled = ReferenceTarget::new(d, width, height)?;
        for k in 0..spec.compared_frames {
            let camera = full.path_camera(compared_at(k, spec.compared_frames), aspect);
            full.update(d, q, &camera, h, 0.0)?;
            let image = target.render_image(d, q, |pass| full.scene.draw(pass))?;
            let reference = supersampled.render(&camera, |tile_camera, tile| {
                full.update(d, q, tile_camera, h, 0.0)?;
                tile.render_image(d, q, |pass| full.scene.draw(pass))
            })?;
            full_frames.push((image, reference));
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
        let mut error = ImageError::default();
        for (k, (full, reference)) in full_frames.iter().enumerate() {
            let camera = scene.path_camera(compared_at(k, spec.compared_frames), aspect);
            scene.update(d, q, &camera, h, pixel_error)?;
            let lod = target.render_image(d, q, |pass| scene.scene.draw(pass))?;
            error.add(reference, full, &lod)?;
            let diff = full.difference(&lod, crate::bench::results::IMAGE_TOLERANCE);
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
            image_error_ratio: error.ratio(),
        });
    }
    Ok(rows)
}
