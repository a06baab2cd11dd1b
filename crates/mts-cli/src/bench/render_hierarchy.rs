//! `mts bench render` of a view-dependent hierarchy (a version-4 `.mts`
//! file, or `--hierarchy`): along the flight of `mts bench view-dependent`,
//! the hierarchy's arena drawn as strips against the same cut's triangles
//! as a meshoptimizer-ordered list, frame time side by side, and the cost
//! of one camera step (selection, walks and the dirty ranges' upload).

use super::render::AdapterFields;
use super::view_dependent::camera_at;
use crate::stdout::outln;
use anyhow::{Context, Result};
use mts::hierarchy::{Hierarchy, ViewDependent};
use mts::peers;
use mts_render::headless::HeadlessTarget;
use mts_render::{Gpu, HierarchyRenderer, RendererConfig};
use serde::Serialize;
use std::time::Instant;

/// Frames drawn and timed per camera of the flight (after one warm-up).
const FRAMES_PER_CAMERA: usize = 2;

/// What `--json` prints for a hierarchy.
#[derive(Serialize)]
struct HierarchyRenderReport {
    hierarchy: bool,
    input: String,
    #[serde(flatten)]
    adapter: AdapterFields,
    width: u32,
    height: u32,
    /// Cameras along the flight.
    cameras: usize,
    pixel_error: f32,
    triangles_full_detail: usize,
    rows: Vec<HierarchyRenderRow>,
}

/// One method over the flight: medians over its cameras.
#[derive(Serialize)]
struct HierarchyRenderRow {
    method: &'static str,
    triangles_median: usize,
    indices_sent_median: usize,
    indices_drawn_median: usize,
    ms_per_frame: f64,
    fps: f64,
    triangles_per_second: f64,
    /// Selection, walks and upload of one camera step, microseconds
    /// (`None` for the list, rebuilt from scratch).
    step_us_median: Option<f64>,
    gpu_bytes: usize,
}

/// What the command's arguments say of a hierarchy's bench.
pub struct HierarchyBench<'a> {
    pub name: &'a str,
    pub h: &'a Hierarchy,
    pub cameras: usize,
    pub width: u32,
    pub height: u32,
    pub pixel_error: f32,
    pub json: bool,
}

fn median<T: Copy + PartialOrd>(mut v: Vec<T>) -> T {
    v.sort_by(|a, b| a.partial_cmp(b).unwrap_or(std::cmp::Ordering::Equal));
    v[v.len() / 2]
}

/// Times `draw` [`FRAMES_PER_CAMERA`] times after one warm-up; the
/// milliseconds of each.
fn time_frames(
    gpu: &Gpu,
    target: &HeadlessTarget,
    draw: &dyn Fn(&mut wgpu::RenderPass<'_>),
    out: &mut Vec<f64>,
) -> Result<()> {
    for i in 0..=FRAMES_PER_CAMERA {
        let t = Instant::now();
        target.render(&gpu.device, &gpu.queue, draw)?;
        if i > 0 {
            out.push(t.elapsed().as_secs_f64() * 1e3);
        }
    }
    Ok(())
}

/// Runs the bench and prints it (a table, or JSON).
pub fn bench_render_hierarchy(b: &HierarchyBench<'_>) -> Result<()> {
    let h = b.h;
    let gpu = Gpu::new_headless()?;
    let report = gpu.report();
    let config = RendererConfig::headless(report.strip_mode);
    let (d, q) = (&gpu.device, &gpu.queue);
    let target = HeadlessTarget::new(d, b.width, b.height)?;
    let mut strips = HierarchyRenderer::new(d, q, &config, h)?;
    let mut list = HierarchyRenderer::new(d, q, &config, h)?;
    let mut view = ViewDependent::new(h);
    let (lo, hi) = mts::mesh::bounds_of(h.positions()).context("the hierarchy has no vertices")?;
    let aspect = b.width as f32 / b.height as f32;
    let (mut strip_ms, mut list_ms, mut step_us) = (Vec::new(), Vec::new(), Vec::new());
    let (mut triangles, mut sent, mut drawn, mut list_drawn) =
        (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    for i in 0..b.cameras {
        let t = if b.cameras > 1 {
            i as f32 / (b.cameras - 1) as f32
        } else {
            0.5
        };
        let (camera, _) = camera_at(lo, hi, t, aspect);
        let t0 = Instant::now();
        let frame = strips.update(
            d,
            q,
            &mut view,
            &camera,
            b.height as f32,
            b.pixel_error,
            true,
        )?;
        gpu.queue.submit([]);
        if i > 0 {
            // The first camera fills the arena from nothing.
            step_us.push(t0.elapsed().as_secs_f64() * 1e6);
        }
        triangles.push(frame.triangles);
        sent.push(frame.indices_sent);
        drawn.push(frame.indices_drawn);
        time_frames(&gpu, &target, &|pass| strips.draw(pass), &mut strip_ms)?;
        let cut = view.triangles();
        let ordered = peers::meshopt::optimize_vertex_cache(&cut, h.vertex_count());
        list.strip_renderer_mut().upload_list(d, q, &ordered)?;
        list.set_camera(q, &camera);
        list_drawn.push(list.strip_renderer().indices_drawn());
        time_frames(
            &gpu,
            &target,
            &|pass| list.strip_renderer().draw(pass),
            &mut list_ms,
        )?;
    }
    let tri = median(triangles);
    let row = |method, ms: f64, sent, drawn, step, gpu_bytes| HierarchyRenderRow {
        method,
        triangles_median: tri,
        indices_sent_median: sent,
        indices_drawn_median: drawn,
        ms_per_frame: ms,
        fps: 1e3 / ms,
        triangles_per_second: tri as f64 * 1e3 / ms,
        step_us_median: step,
        gpu_bytes,
    };
    let rows = vec![
        row(
            "mts_hierarchy",
            median(strip_ms),
            median(sent),
            median(drawn),
            (!step_us.is_empty()).then(|| median(step_us)),
            strips.gpu_bytes(),
        ),
        row(
            "meshopt",
            median(list_ms),
            3 * tri,
            median(list_drawn),
            None,
            list.strip_renderer().gpu_bytes(),
        ),
    ];
    if b.json {
        let out = HierarchyRenderReport {
            hierarchy: true,
            input: b.name.to_string(),
            adapter: AdapterFields::of(&report),
            width: b.width,
            height: b.height,
            cameras: b.cameras,
            pixel_error: b.pixel_error,
            triangles_full_detail: h.triangle_count(),
            rows,
        };
        return outln!("{}", serde_json::to_value(out)?);
    }
    outln!(
        "{}: a hierarchy of {} triangles, {} x {} pixels, {} cameras along the flight at {} px",
        b.name,
        h.triangle_count(),
        b.width,
        b.height,
        b.cameras,
        b.pixel_error
    )?;
    outln!("adapter: {report}")?;
    outln!(
        "{:>13} {:>9} {:>10} {:>10} {:>9} {:>8} {:>10} {:>11}",
        "method",
        "triangles",
        "indices",
        "drawn",
        "ms/frame",
        "fps",
        "Mtri/s",
        "step us"
    )?;
    for r in &rows {
        outln!(
            "{:>13} {:>9} {:>10} {:>10} {:>9.2} {:>8.1} {:>10.2} {:>11}",
            r.method,
            r.triangles_median,
            r.indices_sent_median,
            r.indices_drawn_median,
            r.ms_per_frame,
            r.fps,
            r.triangles_per_second / 1e6,
            r.step_us_median
                .map_or(String::new(), |s| format!("{s:.0}"))
        )?;
    }
    Ok(())
}
