//! The renderer against the oracle: at every LoD tested, the image of the
//! MTS strips covers pixel for pixel what the contraction sequence's
//! triangle list covers, with back-face culling on (a flipped triangle
//! would leave a hole), and lit differs at most by rounding on a few
//! pixels (see `strips_equal_oracle` for why); the stitched and restart
//! paths, a dirty-range update and a fresh full upload, 16- and 32-bit
//! indices all give identical images.
//!
//! Needs a graphics adapter (Mesa's lavapipe is enough); without one every
//! test prints why it is skipped and passes.

#[path = "../../mts/tests/common/mod.rs"]
mod common;
// Each test binary uses some of the shared helpers.
#[allow(dead_code)]
mod support;

use mts::mesh::generate::Generated;
use mts::model::{build, BuildOptions};
use mts::{stripify, Error, Extractor, Mesh, MtsModel, SimplifyOptions, StripifyOptions};
use mts_render::headless::HeadlessTarget;
use mts_render::{
    Camera, FrameStats, Gpu, Image, InstanceId, InstancedScene, ModelId, RendererConfig, Shading,
    StripMode, StripRenderer,
};
use support::{difference, gpu_on, required_gpu};

const WIDTH: u32 = 320;
const HEIGHT: u32 = 240;

/// The headless GPU, or `None` with a message when there is no adapter or
/// the default one ignores primitive restart (GL: the GL test below covers
/// that path, every other test compares against restart).
fn gpu() -> Option<Gpu> {
    match Gpu::new_headless() {
        Ok(gpu) => {
            let report = gpu.report();
            eprintln!("adapter: {report}");
            if report.strip_mode != StripMode::Restart {
                assert!(
                    !required_gpu(),
                    "MTS_REQUIRE names gpu and the default adapter ignores primitive restart"
                );
                eprintln!("skipped: the default adapter ignores primitive restart");
                return None;
            }
            Some(gpu)
        }
        Err(Error::NoAdapter(why)) => {
            assert!(!required_gpu(), "MTS_REQUIRE names gpu: no adapter ({why})");
            eprintln!("skipped: no graphics adapter ({why}); install mesa-vulkan-drivers");
            None
        }
        Err(e) => panic!("GPU setup failed: {e}"),
    }
}

fn model_of(mesh: &Mesh) -> MtsModel {
    let strips = stripify(mesh, &StripifyOptions::default());
    let collapses = mts::simplify(mesh, &SimplifyOptions::default()).collapses;
    build(mesh, &strips, &collapses, &BuildOptions::default())
}

/// Draws with one renderer and reads back: the upload is done by `upload`.
struct Scene<'g> {
    gpu: &'g Gpu,
    target: HeadlessTarget,
    camera: Camera,
}

impl<'g> Scene<'g> {
    fn new(gpu: &'g Gpu, model: &MtsModel) -> Scene<'g> {
        let target = HeadlessTarget::new(&gpu.device, WIDTH, HEIGHT).unwrap();
        let camera = Camera::framing_points(model.positions(), target.aspect());
        Scene {
            gpu,
            target,
            camera,
        }
    }

    fn renderer(&self, model: &MtsModel, mode: StripMode) -> StripRenderer {
        let config = RendererConfig::headless(mode);
        StripRenderer::for_model(&self.gpu.device, &self.gpu.queue, &config, model).unwrap()
    }

    fn image(&self, renderer: &StripRenderer) -> Image {
        renderer.set_camera(&self.gpu.queue, &self.camera);
        self.target
            .render_image(&self.gpu.device, &self.gpu.queue, |pass| {
                renderer.draw(pass)
            })
            .unwrap()
    }
}

/// The strips at each LoD of `ratios` against the oracle list, and the
/// stitched path against the restart path.
///
/// Unlit (coverage only), strips and oracle must agree pixel for pixel:
/// the same triangles with the same winding cover the same pixels, and a
/// flipped triangle would be culled and leave a hole. Lit, they may differ
/// by one step of one channel on a handful of pixels, and only there:
/// lavapipe (llvmpipe) sets up each attribute's plane equation from the
/// triangle's first vertex and reorders the vertices of clockwise-submitted
/// triangles (a strip's odd triangles) before setup, so the same triangle
/// sent as `(a, b, c)` in a list and `(b, a, c)` in a strip can get a
/// normal that differs in its last float bit, which after 8-bit rounding
/// flips a channel by one on rare pixels. Measured: 0 to 3 pixels of about
/// 12,000 at 320 × 240; decoding the strips into a list in either vertex
/// order of the odd triangles reproduces it, so it is the interpolation
/// order, not the triangles. The stitched and restart paths send the same
/// vertex orders and must agree exactly, lit or not.
fn strips_equal_oracle(gpu: &Gpu, name: &str, mesh: &Mesh, ratios: &[f64], min_foreground: usize) {
    let model = model_of(mesh);
    let mut scene = Scene::new(gpu, &model);
    let (d, q) = (&gpu.device, &gpu.queue);
    let mut restart = scene.renderer(&model, StripMode::Restart);
    let mut stitched = scene.renderer(&model, StripMode::Stitched);
    let mut list = scene.renderer(&model, StripMode::Restart);
    let mut ex = Extractor::new(&model);
    for &ratio in ratios {
        let lod = model.lod_for_ratio(ratio);
        ex.set_lod(lod);
        restart.upload_strips(d, q, &ex).unwrap();
        stitched.upload_strips(d, q, &ex).unwrap();
        let oracle = model.collapses().triangles_at(mesh, lod);
        assert_eq!(oracle.len(), model.triangle_count(lod));
        list.upload_list(d, q, &oracle).unwrap();
        assert!(
            2 * ex.indices_sent() <= 3 * oracle.len(),
            "{name} LoD {lod}: strips send {} indices, more than half the list's {}",
            ex.indices_sent(),
            3 * oracle.len()
        );
        scene.camera.shading = Shading::Unlit;
        let (a, b, c) = (
            scene.image(&restart),
            scene.image(&list),
            scene.image(&stitched),
        );
        let fg = a.foreground_pixels();
        assert!(
            fg >= min_foreground,
            "{name} LoD {lod}: only {fg} foreground pixels (expected at least {min_foreground})"
        );
        assert_eq!(
            difference(&a, &b),
            (0, 0),
            "{name} LoD {lod}: strips and oracle list cover different pixels"
        );
        assert_eq!(
            difference(&a, &c),
            (0, 0),
            "{name} LoD {lod}: stitched, unlit"
        );
        // The comparison can fail: with every other triangle flipped, the
        // flipped front ones are culled and leave holes (flipping all of
        // them would show the inside, whose outline is the same; the lit
        // comparison below catches that).
        let flipped: Vec<[u32; 3]> = oracle
            .iter()
            .enumerate()
            .map(|(i, t)| if i % 2 == 0 { [t[0], t[2], t[1]] } else { *t })
            .collect();
        list.upload_list(d, q, &flipped).unwrap();
        let holes = difference(&a, &scene.image(&list)).0;
        assert!(
            holes >= fg / 10,
            "{name} LoD {lod}: flipped triangles change only {holes} pixels"
        );
        list.upload_list(d, q, &oracle).unwrap();
        scene.camera.shading = Shading::Lit;
        let (a, b, c) = (
            scene.image(&restart),
            scene.image(&list),
            scene.image(&stitched),
        );
        let (lit_differ, lit_step) = difference(&a, &b);
        eprintln!(
            "{name} LoD {lod} ({} triangles): {fg} foreground pixels; strips send {} indices, \
             the list {}; lit, {lit_differ} pixels differ by at most {lit_step}",
            oracle.len(),
            ex.indices_sent(),
            3 * oracle.len()
        );
        assert!(
            lit_step <= 1 && lit_differ <= fg / 1000,
            "{name} LoD {lod}: lit strips and list differ on {lit_differ} pixels by up to {lit_step}"
        );
        assert_eq!(
            difference(&a, &c),
            (0, 0),
            "{name} LoD {lod}: stitched, lit"
        );
    }
}

#[test]
fn torus_strips_equal_oracle_list() {
    let Some(gpu) = gpu() else { return };
    let mesh: Mesh = "torus:20k".parse::<Generated>().unwrap().build();
    // The torus fills about a sixth of the frame at every LoD.
    strips_equal_oracle(&gpu, "torus:20k", &mesh, &[1.0, 0.25, 0.05, 0.01], 8_000);
}

#[test]
fn icosphere_strips_equal_oracle_list() {
    let Some(gpu) = gpu() else { return };
    let mesh: Mesh = "icosphere:20k".parse::<Generated>().unwrap().build();
    strips_equal_oracle(&gpu, "icosphere:20k", &mesh, &[1.0, 0.5, 0.25, 0.05], 8_000);
}

#[test]
fn bunny_strips_equal_oracle_list() {
    let Some(gpu) = gpu() else { return };
    let Some(mesh) = common::model("bunny.ply") else {
        return;
    };
    strips_equal_oracle(&gpu, "bunny", &mesh, &[1.0, 0.25, 0.05], 8_000);
}

#[test]
fn dirty_range_updates_equal_full_uploads() {
    let Some(gpu) = gpu() else { return };
    let mesh: Mesh = "torus:20k".parse::<Generated>().unwrap().build();
    let model = model_of(&mesh);
    assert!(model.band_count() > 1, "the walk crosses bands");
    let mut scene = Scene::new(&gpu, &model);
    let (d, q) = (&gpu.device, &gpu.queue);
    let config = RendererConfig::headless(StripMode::Restart);
    let triangles = model.base_strips().triangles();
    // 16-bit indices (the torus's own vertices; odd range starts widen the
    // writes) and 32-bit ones (the same vertices padded past 65,535).
    let mut padded = model.positions().to_vec();
    padded.resize(70_000, glam::Vec3::ZERO);
    for (positions, format) in [
        (model.positions(), wgpu::IndexFormat::Uint16),
        (&padded[..], wgpu::IndexFormat::Uint32),
    ] {
        let mut updated = StripRenderer::new(d, q, &config, positions, &triangles).unwrap();
        let mut fresh = StripRenderer::new(d, q, &config, positions, &triangles).unwrap();
        assert_eq!(updated.index_format(), format);
        let mut ex = Extractor::new(&model);
        ex.set_lod(0);
        let first = updated.update_strips(d, q, &ex).unwrap();
        let mut partial_seen = false;
        // Down and back up, through several bands, small and large steps.
        for ratio in [0.9, 0.85, 0.5, 0.49, 0.2, 0.05, 0.3, 0.95, 0.94] {
            ex.set_lod(model.lod_for_ratio(ratio));
            let up = updated.update_strips(d, q, &ex).unwrap();
            assert_eq!(up.writes, ex.dirty_ranges().len());
            partial_seen |= up.bytes < first.bytes;
            fresh.upload_strips(d, q, &ex).unwrap();
            for shading in [Shading::Lit, Shading::Unlit] {
                scene.camera.shading = shading;
                let (a, b) = (scene.image(&updated), scene.image(&fresh));
                assert!(a.foreground_pixels() >= 8_000);
                assert_eq!(
                    difference(&a, &b),
                    (0, 0),
                    "{format:?}, ratio {ratio}, {shading:?}: dirty-range update and full upload differ"
                );
            }
        }
        assert!(partial_seen, "some update sent less than the whole buffer");
    }
}

#[test]
fn baselines_through_upload_source_cover_what_the_oracle_covers() {
    use mts::methods::Method;
    let Some(gpu) = gpu() else { return };
    let mesh: Mesh = "torus:8k".parse::<Generated>().unwrap().build();
    let model = model_of(&mesh);
    let mut scene = Scene::new(&gpu, &model);
    scene.camera.shading = Shading::Unlit;
    let (d, q) = (&gpu.device, &gpu.queue);
    let mut oracle = scene.renderer(&model, StripMode::Restart);
    let config = RendererConfig::headless(StripMode::Restart);
    let sources = [Method::Pm, Method::Multilevel].map(|m| m.source(&model, &mesh).unwrap());
    for mut source in sources {
        // The baseline's own vertex numbering: its own renderer.
        let mut renderer = StripRenderer::new(d, q, &config, source.positions(), &[]).unwrap();
        for ratio in [1.0, 0.3, 0.05] {
            let lod = model.lod_for_ratio(ratio);
            source.set_lod(lod);
            renderer.upload_source(d, q, &*source).unwrap();
            let triangles = model.collapses().triangles_at(&mesh, lod);
            oracle.upload_list(d, q, &triangles).unwrap();
            let (a, b) = (scene.image(&renderer), scene.image(&oracle));
            assert!(
                a.foreground_pixels() >= 3_000,
                "{}: empty image",
                source.name()
            );
            assert_eq!(
                difference(&a, &b),
                (0, 0),
                "{} at {ratio}: coverage differs from the oracle",
                source.name()
            );
        }
    }
}

#[test]
fn a_geomorph_runs_from_the_coarse_shape_to_the_fine_one() {
    use mts::baselines::MultilevelMesh;
    use mts::LodSource;
    let Some(gpu) = gpu() else { return };
    let mesh: Mesh = "icosphere:8k".parse::<Generated>().unwrap().build();
    let model = model_of(&mesh);
    let mut scene = Scene::new(&gpu, &model);
    scene.camera.shading = Shading::Unlit;
    let (d, q) = (&gpu.device, &gpu.queue);
    let config = RendererConfig::headless(StripMode::Restart);
    let mut ml = MultilevelMesh::new(&mesh, model.collapses()).unwrap();
    let (fine, coarse) = (model.lod_for_ratio(0.5), model.lod_for_ratio(0.02));
    let mut renderer = StripRenderer::new(d, q, &config, ml.positions(), &[]).unwrap();
    let mut coarse_renderer = StripRenderer::new(d, q, &config, ml.positions(), &[]).unwrap();
    ml.set_lod(coarse);
    coarse_renderer.upload_source(d, q, &ml).unwrap();
    let coarse_image = scene.image(&coarse_renderer);
    ml.set_lod(fine);
    renderer.upload_source(d, q, &ml).unwrap();
    let fine_image = scene.image(&renderer);
    assert!(
        fine_image.differing_pixels(&coarse_image) > 50,
        "the two LoDs must differ"
    );
    let mut morph = Vec::new();
    // t = 0: the fine triangles on the coarse representatives' positions
    // cover exactly what the coarse LoD covers.
    ml.geomorph(fine, coarse, 0.0, &mut morph).unwrap();
    renderer.update_positions(q, &morph).unwrap();
    assert_eq!(difference(&scene.image(&renderer), &coarse_image), (0, 0));
    // Half way it is neither; t = 1 is the fine LoD again.
    ml.geomorph(fine, coarse, 0.5, &mut morph).unwrap();
    renderer.update_positions(q, &morph).unwrap();
    let half = scene.image(&renderer);
    assert!(half.differing_pixels(&coarse_image) > 0 && half.differing_pixels(&fine_image) > 0);
    ml.geomorph(fine, coarse, 1.0, &mut morph).unwrap();
    renderer.update_positions(q, &morph).unwrap();
    assert_eq!(difference(&scene.image(&renderer), &fine_image), (0, 0));
    assert!(renderer
        .update_positions(q, &vec![glam::Vec3::ZERO; ml.positions().len() + 1])
        .is_err());
}

#[test]
fn u32_indices_draw_what_u16_indices_draw() {
    let Some(gpu) = gpu() else { return };
    // Above 65,535 vertices the renderer switches to 32-bit indices: the
    // same LoD drawn both ways (the sphere's vertices, and the same
    // vertices padded past the u16 range).
    let mesh: Mesh = "icosphere:20k".parse::<Generated>().unwrap().build();
    let model = model_of(&mesh);
    let scene = Scene::new(&gpu, &model);
    let (d, q) = (&gpu.device, &gpu.queue);
    let config = RendererConfig::headless(StripMode::Restart);
    let triangles = model.base_strips().triangles();
    let mut padded = model.positions().to_vec();
    padded.resize(70_000, glam::Vec3::ZERO);
    let mut small = StripRenderer::new(d, q, &config, model.positions(), &triangles).unwrap();
    let mut large = StripRenderer::new(d, q, &config, &padded, &triangles).unwrap();
    assert_eq!(small.index_format(), wgpu::IndexFormat::Uint16);
    assert_eq!(large.index_format(), wgpu::IndexFormat::Uint32);
    let mut ex = Extractor::new(&model);
    ex.set_lod(model.lod_for_ratio(0.3));
    small.upload_strips(d, q, &ex).unwrap();
    large.upload_strips(d, q, &ex).unwrap();
    let (a, b) = (scene.image(&small), scene.image(&large));
    assert!(a.foreground_pixels() >= 8_000);
    assert_eq!(difference(&a, &b), (0, 0));
}

#[test]
fn gl_backend_stitches_and_covers_what_the_oracle_covers() {
    // wgpu's GL backend ignores primitive restart: the renderer must pick
    // stitching by itself there and still draw the oracle's triangles.
    let gpu = match Gpu::new_headless_on(wgpu::Backends::GL) {
        Ok(gpu) => gpu,
        Err(Error::NoAdapter(why)) => {
            assert!(
                !required_gpu(),
                "MTS_REQUIRE names gpu: no GL adapter ({why})"
            );
            eprintln!("skipped: no GL adapter ({why})");
            return;
        }
        Err(e) => panic!("GL setup failed: {e}"),
    };
    let report = gpu.report();
    eprintln!("adapter: {report}");
    assert_eq!(report.strip_mode, StripMode::Stitched);
    let mesh: Mesh = "torus:20k".parse::<Generated>().unwrap().build();
    let model = model_of(&mesh);
    let mut scene = Scene::new(&gpu, &model);
    scene.camera.shading = Shading::Unlit;
    let (d, q) = (&gpu.device, &gpu.queue);
    let mut strips = scene.renderer(&model, report.strip_mode);
    let mut list = scene.renderer(&model, report.strip_mode);
    let mut ex = Extractor::new(&model);
    for ratio in [1.0, 0.25, 0.05] {
        let lod = model.lod_for_ratio(ratio);
        ex.set_lod(lod);
        strips.update_strips(d, q, &ex).unwrap();
        list.upload_list(d, q, &model.collapses().triangles_at(&mesh, lod))
            .unwrap();
        let (a, b) = (scene.image(&strips), scene.image(&list));
        assert!(a.foreground_pixels() >= 8_000);
        assert_eq!(difference(&a, &b), (0, 0), "GL, LoD {lod}");
    }
}

/// Draws `scene` into `target` after updating it for `camera`.
fn scene_image(
    gpu: &Gpu,
    target: &HeadlessTarget,
    scene: &mut InstancedScene<'_>,
    camera: &Camera,
) -> (Image, FrameStats) {
    let stats = scene
        .update(&gpu.device, &gpu.queue, camera, HEIGHT as f32, 1.0)
        .unwrap();
    let image = target
        .render_image(&gpu.device, &gpu.queue, |pass| scene.draw(pass))
        .unwrap();
    (image, stats)
}

/// `count` instances of `model` on a square grid in the plane y = 0, each
/// turned about +y, spaced five model radii apart (the host's own layout).
fn grid_of<'m>(
    scene: &mut InstancedScene<'m>,
    model: ModelId,
    radius: f32,
    count: usize,
) -> Vec<InstanceId> {
    (0..count)
        .map(|i| {
            scene
                .add_instance(model, grid_transform(i, count, radius))
                .unwrap()
        })
        .collect()
}

/// The transform of instance `i` of `count` in [`grid_of`].
fn grid_transform(i: usize, count: usize, radius: f32) -> glam::Mat4 {
    let side = (count as f64).sqrt().ceil() as usize;
    let at = glam::Vec3::new((i % side) as f32, 0.0, (i / side) as f32) * 5.0 * radius;
    glam::Mat4::from_translation(at) * glam::Mat4::from_rotation_y(i as f32 * 0.7)
}

/// A camera above the corner `lo` of a field looking across it to `hi`.
fn across(lo: glam::Vec3, hi: glam::Vec3, aspect: f32) -> Camera {
    let size = (hi - lo).length();
    let eye = lo + glam::Vec3::new(0.08 * size, 0.05 * size, 0.08 * size);
    Camera::looking(eye, lo + (hi - lo) * 0.5, aspect, 0.01 * size, 2.0 * size)
}

#[test]
fn scene_culls_and_updates_like_a_fresh_scene() {
    let Some(gpu) = gpu() else { return };
    let mesh: Mesh = "torus:2k".parse::<Generated>().unwrap().build();
    let model = model_of(&mesh);
    let (d, q) = (&gpu.device, &gpu.queue);
    let config = RendererConfig::headless(StripMode::Restart);
    let target = HeadlessTarget::new(d, WIDTH, HEIGHT).unwrap();
    let mut scene = InstancedScene::new(&config);
    let id = scene.add_model(d, q, &model).unwrap();
    let radius = mesh.diagonal() * 0.5;
    let ids = grid_of(&mut scene, id, radius, 100);
    let centres: Vec<glam::Vec3> = ids.iter().map(|&i| scene.bounds_of(i).unwrap().0).collect();

    // From high above the middle, everything is in view (small: 100 tori
    // across 320 x 240 pixels).
    let (lo, hi) = centres.iter().fold(
        (
            glam::Vec3::splat(f32::INFINITY),
            glam::Vec3::splat(f32::NEG_INFINITY),
        ),
        |(lo, hi), &c| (lo.min(c), hi.max(c)),
    );
    let all = Camera::framing(lo - radius, hi + radius, target.aspect());
    let (image, stats) = scene_image(&gpu, &target, &mut scene, &all);
    assert_eq!(stats.visible, 100);
    let fg = image.foreground_pixels();
    eprintln!("scene from above: {fg} instance pixels");
    assert!(fg >= 500, "{fg}");

    // Looking away from the field, nothing is.
    let mid = (lo + hi) * 0.5;
    let away = Camera::looking(
        mid - glam::Vec3::X * 2.0 * (hi.x - lo.x + 10.0 * radius),
        mid - glam::Vec3::X * 10.0 * (hi.x - lo.x + 10.0 * radius),
        target.aspect(),
        0.1,
        1e4,
    );
    assert_eq!(
        scene
            .update(d, q, &away, HEIGHT as f32, 1.0)
            .unwrap()
            .visible,
        0
    );

    // Across the field from a corner: every instance whose centre projects
    // inside the view is drawn, none behind the camera is, nearer ones get
    // finer LoDs.
    let across = across(lo, hi, target.aspect());
    let (image, stats) = scene_image(&gpu, &target, &mut scene, &across);
    let visible = scene.visible().to_vec();
    eprintln!(
        "scene: {} of 100 instances visible, {} triangles, {} indices sent",
        stats.visible, stats.triangles, stats.indices_drawn
    );
    assert!(
        0 < stats.visible && stats.visible < 100,
        "{}",
        stats.visible
    );
    let mut by_depth = Vec::new();
    for (i, &c) in centres.iter().enumerate() {
        let clip = across.view_proj * c.extend(1.0);
        let inside = clip.w > 0.0
            && clip.x.abs() < clip.w
            && clip.y.abs() < clip.w
            && (0.0..clip.w).contains(&clip.z);
        let drawn = visible.contains(&ids[i]);
        assert!(!inside || drawn, "instance {i} is in view but culled");
        assert!(
            clip.w > -radius || !drawn,
            "instance {i} is behind but drawn"
        );
        if drawn {
            by_depth.push((clip.w, scene.lod_of(ids[i]).unwrap()));
        }
    }
    by_depth.sort_by(|a, b| a.0.total_cmp(&b.0));
    assert!(
        by_depth[0].1 < by_depth[by_depth.len() - 1].1,
        "{by_depth:?}"
    );

    // The incremental path (after two other views) draws what a fresh
    // scene draws for the same view.
    let mut fresh = InstancedScene::new(&config);
    let fresh_id = fresh.add_model(d, q, &model).unwrap();
    grid_of(&mut fresh, fresh_id, radius, 100);
    let (expected, fresh_stats) = scene_image(&gpu, &target, &mut fresh, &across);
    assert_eq!(
        fresh_stats,
        FrameStats {
            lod_changes: fresh_stats.lod_changes,
            upload_bytes: fresh_stats.upload_bytes,
            extractions: fresh_stats.extractions,
            evictions: fresh_stats.evictions,
            bvh: fresh_stats.bvh,
            ..stats
        }
    );
    let fg = image.foreground_pixels();
    eprintln!("scene across: {fg} pixels differ from the top-left corner");
    assert!(fg >= 5_000, "{fg}");
    assert_eq!(difference(&image, &expected), (0, 0));
}

/// The host drives the scene: two models, instances added, moved and
/// removed between frames (buffers growing on the way); after each change
/// the image is the one a scene built afresh in the final state draws.
#[test]
fn host_moves_adds_and_removes_instances_of_two_models() {
    let Some(gpu) = gpu() else { return };
    let (d, q) = (&gpu.device, &gpu.queue);
    let config = RendererConfig::headless(StripMode::Restart);
    let target = HeadlessTarget::new(d, WIDTH, HEIGHT).unwrap();
    let torus: Mesh = "torus:2k".parse::<Generated>().unwrap().build();
    let sphere: Mesh = "icosphere:1k".parse::<Generated>().unwrap().build();
    let (a, b) = (model_of(&torus), model_of(&sphere));
    let at = |x: f32, z: f32| glam::Mat4::from_translation(glam::Vec3::new(x, 0.0, z) * 3.0);
    let camera = Camera::looking(
        glam::Vec3::new(6.0, 12.0, 20.0),
        glam::Vec3::new(6.0, 0.0, 6.0),
        target.aspect(),
        0.1,
        100.0,
    );
    // The state every step ends in, as (model, transform) lists.
    let mut scene = InstancedScene::new(&config);
    let (ma, mb) = (
        scene.add_model(d, q, &a).unwrap(),
        scene.add_model(d, q, &b).unwrap(),
    );
    let first = scene.add_instance(ma, at(0.0, 0.0)).unwrap();
    scene_image(&gpu, &target, &mut scene, &camera);
    let mut ids = vec![first];
    for i in 1..12 {
        let m = if i % 2 == 0 { ma } else { mb };
        ids.push(
            scene
                .add_instance(m, at((i % 4) as f32, (i / 4) as f32))
                .unwrap(),
        );
    }
    scene_image(&gpu, &target, &mut scene, &camera);
    scene.set_transform(ids[3], at(1.5, 1.5)).unwrap();
    assert!(scene.remove_instance(ids[5]));
    assert!(!scene.remove_instance(ids[5]), "removed twice");
    assert!(scene.set_transform(ids[5], at(0.0, 0.0)).is_err());
    let (image, stats) = scene_image(&gpu, &target, &mut scene, &camera);
    assert_eq!(scene.instance_count(), 11);
    assert!(!scene.visible().contains(&ids[5]));

    let mut fresh = InstancedScene::new(&config);
    let (fa, fb) = (
        fresh.add_model(d, q, &a).unwrap(),
        fresh.add_model(d, q, &b).unwrap(),
    );
    for (i, &id) in ids.iter().enumerate() {
        if i == 5 {
            continue;
        }
        let m = if id.model() == ma { fa } else { fb };
        let t = if i == 3 {
            at(1.5, 1.5)
        } else {
            at((i % 4) as f32, (i / 4) as f32)
        };
        fresh.add_instance(m, t).unwrap();
    }
    let (expected, fresh_stats) = scene_image(&gpu, &target, &mut fresh, &camera);
    assert_eq!(stats.visible, fresh_stats.visible);
    assert_eq!(stats.triangles, fresh_stats.triangles);
    assert!(
        image.foreground_pixels() >= 3_000,
        "{}",
        image.foreground_pixels()
    );
    assert_eq!(difference(&image, &expected), (0, 0));
}

/// Issue 19: the instanced scene refused backends without primitive
/// restart. On GL it now stitches each instance's runs and covers the same
/// pixels as the restart path on Vulkan.
#[test]
fn instanced_scene_on_gl_covers_what_vulkan_covers() {
    let (Some(gl), Some(vk)) = (
        gpu_on(wgpu::Backends::GL, "GL"),
        gpu_on(wgpu::Backends::VULKAN, "Vulkan"),
    ) else {
        return;
    };
    assert_eq!(gl.report().strip_mode, StripMode::Stitched);
    assert_eq!(vk.report().strip_mode, StripMode::Restart);
    let mesh: Mesh = "torus:2k".parse::<Generated>().unwrap().build();
    let model = model_of(&mesh);
    let mut images = Vec::new();
    for gpu in [&gl, &vk] {
        let config = RendererConfig::headless(gpu.report().strip_mode);
        let (d, q) = (&gpu.device, &gpu.queue);
        let target = HeadlessTarget::new(d, WIDTH, HEIGHT).unwrap();
        let mut scene = InstancedScene::new(&config);
        let id = scene.add_model(d, q, &model).unwrap();
        let radius = mesh.diagonal() * 0.5;
        let ids = grid_of(&mut scene, id, radius, 50);
        let far = scene.bounds_of(ids[49]).unwrap().0;
        let camera = across(glam::Vec3::ZERO, far, target.aspect());
        let stats = scene.update(d, q, &camera, HEIGHT as f32, 1.0).unwrap();
        assert!(
            stats.visible > 10 && stats.lod_changes == stats.visible,
            "{stats:?}"
        );
        images.push((
            stats,
            target.render_image(d, q, |pass| scene.draw(pass)).unwrap(),
        ));
    }
    let ((gl_stats, gl_image), (vk_stats, vk_image)) = (&images[0], &images[1]);
    assert_eq!(gl_stats.visible, vk_stats.visible);
    assert_eq!(gl_stats.triangles, vk_stats.triangles);
    let covered = vk_image.foreground_pixels();
    assert!(covered > 5_000, "{covered}");
    // Two rasterisers (llvmpipe through GL and through Vulkan) may differ
    // on a few edge pixels, never on coverage.
    let differing = gl_image.differing_pixels(vk_image);
    assert!(
        differing * 200 <= covered,
        "{differing} of {covered} pixels differ"
    );
}

/// Issue 19: an image whose readback buffer passes the device's
/// `max_buffer_size` is an error, not a wgpu validation panic.
#[test]
fn readback_beyond_the_device_limit_is_an_error() {
    let Some(gpu) = gpu() else { return };
    let max = gpu.device.limits().max_buffer_size;
    let side = gpu.device.limits().max_texture_dimension_2d;
    // Rows of `side` pixels (4 bytes each), enough of them to pass `max`.
    let rows = (max / (4 * u64::from(side)) + 1).min(u64::from(side)) as u32;
    if 4 * u64::from(side) * u64::from(rows) <= max {
        eprintln!("skipped: this device's buffers hold any image ({max} bytes)");
        return;
    }
    match HeadlessTarget::new(&gpu.device, side, rows) {
        Err(Error::InvalidArgument(m)) => assert!(m.contains("max_buffer_size"), "{m}"),
        other => panic!("expected an InvalidArgument, got {:?}", other.map(|_| ())),
    }
}

/// Issue 22: instances share their LoD bucket's buffer, each drawing the
/// coarsest bucket at least as fine as the LoD its projected error allows;
/// moving instances refits the BVH and draws what a fresh scene draws;
/// buckets nobody uses are freed after `KEEP_UPDATES` updates; 0 pixels is
/// full detail.
#[test]
fn instances_share_buckets_chosen_by_screen_space_error() {
    use mts_render::scene::{BvhUpdate, KEEP_UPDATES};
    let Some(gpu) = gpu() else { return };
    let (d, q) = (&gpu.device, &gpu.queue);
    let config = RendererConfig::headless(StripMode::Restart);
    let target = HeadlessTarget::new(d, WIDTH, HEIGHT).unwrap();
    let mesh: Mesh = "torus:4k".parse::<Generated>().unwrap().build();
    let model = model_of(&mesh);
    let mut scene = InstancedScene::new(&config);
    let id = scene.add_model(d, q, &model).unwrap();
    let radius = mesh.diagonal() * 0.5;
    let ids = grid_of(&mut scene, id, radius, 400);
    let far = scene.bounds_of(ids[399]).unwrap().0;
    let camera = across(glam::Vec3::ZERO, far, target.aspect());
    let (_, stats) = scene_image(&gpu, &target, &mut scene, &camera);
    assert_eq!(stats.bvh, BvhUpdate::Rebuilt);
    assert!(stats.visible > 50, "{stats:?}");
    // Fewer buffers than visible instances: they are shared.
    let memory = scene.memory();
    assert_eq!(memory.buffers, stats.draws);
    assert!(memory.buffers * 4 < stats.visible, "{memory:?} {stats:?}");
    assert!(memory.cpu_bytes_per_instance() <= 256, "{memory:?}");
    // Each visible instance: its wanted LoD's error projects within one
    // pixel (the next coarser one's does not), and its bucket is at least
    // as fine, within 10% more triangles than the next coarser bucket
    // would have.
    let collapses = model.collapses();
    let row_y = camera.view_proj.row(1).truncate().length();
    let px_at_1 = row_y * 0.5 * HEIGHT as f32;
    let mut lods = std::collections::BTreeSet::new();
    for &i in scene.visible() {
        let (centre, r) = scene.bounds_of(i).unwrap();
        let depth = camera.view_proj.row(3).dot(centre.extend(1.0));
        let ppu = px_at_1 / (depth - r).max(1e-9);
        let wanted = scene.wanted_lod_of(i).unwrap();
        let pixels = |lod: usize| collapses.error(lod) * mesh.diagonal() * ppu;
        assert!(pixels(wanted) <= 1.0 + 1e-4, "{wanted}: {}", pixels(wanted));
        if wanted < model.max_lod() {
            assert!(
                pixels(wanted + 1) > 1.0 - 1e-4,
                "{wanted} is not the coarsest"
            );
        }
        let drawn = scene.lod_of(i).unwrap();
        assert!(drawn <= wanted, "bucket LoD {drawn} coarser than {wanted}");
        lods.insert(drawn);
    }
    assert!(
        lods.len() > 2,
        "nearer and farther instances differ: {lods:?}"
    );

    // Moving every instance a little: refitted, and drawn as a fresh scene
    // in the same state draws.
    let lift = glam::Mat4::from_translation(glam::Vec3::new(0.0, 0.3 * radius, 0.0));
    let mut fresh = InstancedScene::new(&config);
    let fresh_id = fresh.add_model(d, q, &model).unwrap();
    let fresh_ids = grid_of(&mut fresh, fresh_id, radius, 400);
    for (i, (&a, &b)) in ids.iter().zip(&fresh_ids).enumerate() {
        let moved = lift * grid_transform(i, 400, radius);
        scene.set_transform(a, moved).unwrap();
        fresh.set_transform(b, moved).unwrap();
    }
    let (image, stats) = scene_image(&gpu, &target, &mut scene, &camera);
    assert_eq!(stats.bvh, BvhUpdate::Refitted);
    let (expected, _) = scene_image(&gpu, &target, &mut fresh, &camera);
    assert_eq!(difference(&image, &expected), (0, 0));
    assert!(image.foreground_pixels() > 2_000);

    // 0 pixels: every visible instance at full detail, one bucket.
    let stats = scene.update(d, q, &camera, HEIGHT as f32, 0.0).unwrap();
    assert_eq!(stats.triangles, stats.triangles_full_detail);
    assert_eq!(stats.draws, 1);
    assert!(scene.visible().iter().all(|&i| scene.lod_of(i) == Some(0)));

    // Looking away: nothing drawn; the buckets go after KEEP_UPDATES.
    let away = Camera::looking(
        glam::Vec3::new(0.0, 0.0, -10.0 * radius),
        glam::Vec3::new(0.0, 0.0, -100.0 * radius),
        target.aspect(),
        0.1,
        10.0 * radius,
    );
    let mut evicted = 0;
    for k in 0..=KEEP_UPDATES {
        let stats = scene.update(d, q, &away, HEIGHT as f32, 1.0).unwrap();
        assert_eq!(stats.visible, 0);
        evicted += stats.evictions;
        if k < KEEP_UPDATES {
            assert!(scene.memory().buffers > 0, "freed too early ({k})");
        }
    }
    assert_eq!(scene.memory().buffers, 0);
    assert!(evicted > 2, "{evicted}");
}
