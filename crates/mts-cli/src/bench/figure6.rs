//! The MTS paper's Figure 6 on the adapter at hand: frames per second
//! against the share of triangles, for "extract then draw each frame"
//! (immediate) and "one extraction per second", per method.
//!
//! - **mts**: immediate = each frame the coherent extractor moves one LoD
//!   (back and forth around the level), the renderer uploads the dirty
//!   ranges, then draws; per second = one extraction from scratch and a
//!   full upload per second, drawing in between.
//! - **list**: the triangle list of the level in meshoptimizer's
//!   `optimize_vertex_cache` order. Immediate = each frame the list is
//!   replayed from the contraction sequence (pc-rep) and uploaded, as a
//!   program without a multiresolution structure would; per second = one
//!   replay, reorder and upload per second.
//!
//! - **pm, multilevel, cluster, discrete** (the baselines, through
//!   `LodSource`): immediate = each frame `set_lod` moves one LoD back and
//!   forth and the whole index buffer is uploaded; per second = one
//!   `set_lod` from the coarsest LoD and one upload per second. Each is
//!   asked for the finest of its own LoDs within the MTS level's triangle
//!   count.
//!
//! "Per second" frames are derived, not slept through: with extraction
//! cost `e` ms and drawing cost `d` ms, a second holds `1 + (1000 − e) / d`
//! frames.

use crate::bench::results::{Figure6, Figure6Row, Scene};
use anyhow::Result;
use mts::{peers, Extractor, MtsModel};
use mts_render::headless::HeadlessTarget;
use mts_render::{Camera, Gpu, RendererConfig, StripRenderer};
use std::time::Instant;

/// Image size of the frames.
const WIDTH: u32 = 800;
const HEIGHT: u32 = 600;

use super::results::IMAGE_TOLERANCE;

/// The renderer state shared by every model of a run.
pub struct Renderer {
    gpu: Gpu,
    target: HeadlessTarget,
    config: RendererConfig,
}

impl Renderer {
    /// A headless device (lavapipe without a GPU) and its frame target.
    pub fn new() -> Result<Renderer> {
        let gpu = Gpu::new_headless()?;
        let report = gpu.report();
        let config = RendererConfig::headless(report.strip_mode);
        let target = HeadlessTarget::new(&gpu.device, WIDTH, HEIGHT)?;
        Ok(Renderer {
            gpu,
            target,
            config,
        })
    }

    /// Adapter name, backend and strip mode, for the report.
    pub fn adapter(&self) -> String {
        self.gpu.report().to_string()
    }

    fn draw_ms(&self, renderer: &StripRenderer) -> Result<f64> {
        let t = Instant::now();
        self.target
            .render(&self.gpu.device, &self.gpu.queue, |pass| {
                renderer.draw(pass)
            })?;
        Ok(t.elapsed().as_secs_f64() * 1e3)
    }

    /// How each triangle list of `lods` (over `input`'s vertices) looks
    /// against `input` itself, both drawn with `input`'s properties (the
    /// checker where it has UVs: `mts render --checker`) from the camera
    /// that frames it: [`mts_render::Image::difference`] with tolerance
    /// [`IMAGE_TOLERANCE`].
    ///
    /// # Errors
    /// When the renderer cannot take the mesh or a frame cannot be read.
    pub fn image_differences(
        &self,
        input: &mts::Mesh,
        lods: &[&[[u32; 3]]],
    ) -> Result<Vec<mts_render::Difference>> {
        let (d, q) = (&self.gpu.device, &self.gpu.queue);
        let appearance = mts_render::Appearance { checker: true };
        let mut r = StripRenderer::with_properties(
            d,
            q,
            &self.config,
            &input.positions,
            &input.triangles,
            &input.properties,
            &appearance,
        )?;
        r.set_camera(
            q,
            &Camera::framing_points(&input.positions, self.target.aspect()),
        );
        r.upload_list(d, q, &input.triangles)?;
        let full = self.target.render_image(d, q, |pass| r.draw(pass))?;
        let mut out = Vec::with_capacity(lods.len());
        for triangles in lods {
            r.upload_list(d, q, triangles)?;
            let image = self.target.render_image(d, q, |pass| r.draw(pass))?;
            out.push(full.difference(&image, IMAGE_TOLERANCE));
        }
        Ok(out)
    }

    /// Figure 6 rows of `model` (built from `input`) at `shares`, `frames`
    /// timed frames each.
    pub fn measure(
        &self,
        model: &MtsModel,
        input: &mts::Mesh,
        shares: &[f64],
        frames: usize,
    ) -> Result<Figure6> {
        let (d, q) = (&self.gpu.device, &self.gpu.queue);
        let camera = Camera::framing_points(model.positions(), self.target.aspect());
        let mut strips = StripRenderer::for_model(d, q, &self.config, model)?;
        let mut list = StripRenderer::for_model(d, q, &self.config, model)?;
        strips.set_camera(q, &camera);
        list.set_camera(q, &camera);
        let mesh = model.mesh();
        let vertices = model.positions().len();
        let mut ex = Extractor::new(model);
        let mut rows = Vec::new();
        let median = |mut v: Vec<f64>| {
            v.sort_by(f64::total_cmp);
            v[v.len() / 2]
        };
        for &share in shares {
            let lod = model.lod_for_ratio(share);
            let other = if lod < model.max_lod() {
                lod + 1
            } else {
                lod - 1
            };
            let triangles = model.triangle_count(lod);
            // mts, immediate.
            ex.set_lod(lod);
            strips.upload_strips(d, q, &ex)?;
            let mut immediate = Vec::with_capacity(frames);
            let mut change = Vec::with_capacity(frames);
            for i in 0..frames + 2 {
                let t = Instant::now();
                ex.set_lod(if i % 2 == 0 { other } else { lod });
                strips.update_strips(d, q, &ex)?;
                let changed = t.elapsed().as_secs_f64() * 1e6;
                self.target.render(d, q, |pass| strips.draw(pass))?;
                if i >= 2 {
                    immediate.push(t.elapsed().as_secs_f64() * 1e3);
                    change.push(changed);
                }
            }
            let change_us = median(change);
            // mts, one extraction per second: every strip walked again
            // and the buffer uploaded whole.
            let t = Instant::now();
            ex.set_lod_from_scratch(lod);
            strips.upload_strips(d, q, &ex)?;
            let extract_ms = t.elapsed().as_secs_f64() * 1e3;
            let draw: Vec<f64> = (0..frames)
                .map(|_| self.draw_ms(&strips))
                .collect::<Result<_>>()?;
            let mts_draw = median(draw);
            // list, immediate: replay + upload + draw each frame.
            let mut list_immediate = Vec::with_capacity(frames);
            for i in 0..frames + 1 {
                let t = Instant::now();
                let tris = model.collapses().triangles_at(&mesh, lod);
                list.upload_list(d, q, &tris)?;
                self.target.render(d, q, |pass| list.draw(pass))?;
                if i >= 1 {
                    list_immediate.push(t.elapsed().as_secs_f64() * 1e3);
                }
            }
            // list, one replay + reorder + upload per second.
            let t = Instant::now();
            let tris = model.collapses().triangles_at(&mesh, lod);
            let ordered = peers::meshopt::optimize_vertex_cache(&tris, vertices);
            list.upload_list(d, q, &ordered)?;
            let list_extract_ms = t.elapsed().as_secs_f64() * 1e3;
            let draw: Vec<f64> = (0..frames)
                .map(|_| self.draw_ms(&list))
                .collect::<Result<_>>()?;
            let list_draw = median(draw);
            let per_second = |e: f64, d: f64| 1.0 + (1000.0 - e).max(0.0) / d;
            let mts_indices = ex.indices_sent();
            for (method, mode, fps, indices, draw_ms, change_us) in [
                (
                    "mts",
                    "immediate",
                    1e3 / median(immediate),
                    mts_indices,
                    mts_draw,
                    Some(change_us),
                ),
                (
                    "mts",
                    "per_second",
                    per_second(extract_ms, mts_draw),
                    mts_indices,
                    mts_draw,
                    None,
                ),
                (
                    "list",
                    "immediate",
                    1e3 / median(list_immediate),
                    3 * triangles,
                    list_draw,
                    None,
                ),
                (
                    "list",
                    "per_second",
                    per_second(list_extract_ms, list_draw),
                    3 * triangles,
                    list_draw,
                    None,
                ),
            ] {
                rows.push(Figure6Row {
                    method: method.into(),
                    mode: mode.into(),
                    share,
                    lod: lod as u64,
                    triangles: triangles as u64,
                    indices_sent: indices as u64,
                    draw_ms,
                    fps,
                    change_us,
                });
            }
        }
        for method in [
            mts::methods::Method::Pm,
            mts::methods::Method::Multilevel,
            mts::methods::Method::Cluster,
            mts::methods::Method::Discrete,
        ] {
            self.measure_source(method, model, input, shares, frames, &camera, &mut rows)?;
        }
        Ok(Figure6 {
            width: WIDTH,
            height: HEIGHT,
            frames: frames as u64,
            rows,
        })
    }

    /// The adapter's vertex work on `model` (see `mts bench render`),
    /// framed as Figure 6 frames it.
    ///
    /// # Errors
    /// As [`super::vertex_work::measure_vertex_work`].
    pub fn measure_vertex_work(
        &self,
        name: &str,
        model: &MtsModel,
    ) -> Result<crate::bench::results::VertexWork> {
        let camera = Camera::framing_points(model.positions(), self.target.aspect());
        super::vertex_work::measure_vertex_work(
            &self.gpu,
            &self.target,
            &self.config,
            name,
            model,
            &camera,
        )
    }

    /// Scene rows (see `mts bench render --scene`) of `models`.
    ///
    /// # Errors
    /// As [`super::scene::scene_rows`].
    pub fn measure_scene(
        &self,
        models: &[(String, &MtsModel)],
        spec: &super::scene::SceneSpec<'_>,
    ) -> Result<Vec<Scene>> {
        super::scene::scene_rows(&self.gpu, &self.target, &self.config, models, spec)
    }

    /// Figure 6 rows of one baseline (see the module documentation).
    #[allow(clippy::too_many_arguments)]
    fn measure_source(
        &self,
        method: mts::methods::Method,
        model: &MtsModel,
        input: &mts::Mesh,
        shares: &[f64],
        frames: usize,
        camera: &Camera,
        rows: &mut Vec<Figure6Row>,
    ) -> Result<()> {
        let (d, q) = (&self.gpu.device, &self.gpu.queue);
        let mut source = method.source(model, input)?;
        let mut renderer = StripRenderer::for_source(d, q, &self.config, source.as_mut())?;
        renderer.set_camera(q, camera);
        let median = |mut v: Vec<f64>| {
            v.sort_by(f64::total_cmp);
            v[v.len() / 2]
        };
        let max_lod = source.max_lod();
        for &share in shares {
            let budget = model.triangle_count(model.lod_for_ratio(share));
            let lod = mts::lod::lod_for_triangles(&*source, budget);
            let other = if lod < max_lod {
                lod + 1
            } else {
                lod.saturating_sub(1)
            };
            let mut immediate = Vec::with_capacity(frames);
            for i in 0..frames + 2 {
                let t = Instant::now();
                source.set_lod(if i % 2 == 0 { other } else { lod });
                renderer.upload_source(d, q, &*source)?;
                self.target.render(d, q, |pass| renderer.draw(pass))?;
                if i >= 2 {
                    immediate.push(t.elapsed().as_secs_f64() * 1e3);
                }
            }
            source.set_lod(max_lod);
            let t = Instant::now();
            source.set_lod(lod);
            renderer.upload_source(d, q, &*source)?;
            let extract_ms = t.elapsed().as_secs_f64() * 1e3;
            let draw: Vec<f64> = (0..frames)
                .map(|_| self.draw_ms(&renderer))
                .collect::<Result<_>>()?;
            let draw_ms = median(draw);
            let per_second = 1.0 + (1000.0 - extract_ms).max(0.0) / draw_ms;
            let triangles = source.triangle_count(lod);
            for (mode, fps) in [
                ("immediate", 1e3 / median(immediate.clone())),
                ("per_second", per_second),
            ] {
                rows.push(Figure6Row {
                    method: source.name().into(),
                    mode: mode.into(),
                    share,
                    lod: lod as u64,
                    triangles: triangles as u64,
                    indices_sent: source.indices().len() as u64,
                    draw_ms,
                    fps,
                    change_us: None,
                });
            }
        }
        Ok(())
    }
}
