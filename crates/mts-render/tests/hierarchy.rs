//! `HierarchyRenderer` against the oracle: along a flight over a terrain
//! (near, far, low, back near, so the arena grows, shrinks and grows
//! again), the incrementally updated index buffer read back equals the
//! `ViewDependent` arena index for index, and the image equals the same
//! cut drawn from scratch as a triangle list (`Cut::triangles`) through
//! `StripRenderer::upload_list`: pixel for pixel unlit, lit within the
//! rounding that `tests/render.rs` explains (strips and lists hand the
//! rasteriser a triangle's vertices in another order); the stitched path
//! equals the restart path exactly, on Vulkan and on GL (which ignores
//! primitive restart); culling changes no pixel. In an `InstancedScene`,
//! hierarchy instances beside a model follow the camera in their model
//! space (each cut the one its own `ViewDependent` selects there), draw
//! what a scene built afresh draws after the host moves one, and an
//! instance at the identity draws what `HierarchyRenderer` draws.
//!
//! Needs a graphics adapter (Mesa's lavapipe is enough); without one every
//! test prints why it is skipped and passes, and fails when `MTS_REQUIRE`
//! names `gpu`.

// Each test binary uses some of the shared helpers.
#[allow(dead_code)]
mod support;

use glam::{Mat4, Quat, Vec3};
use mts::hierarchy::{self, Frustum, Hierarchy, HierarchyOptions, ViewDependent};
use mts::mesh::generate::Generated;
use mts_render::headless::HeadlessTarget;
use mts_render::hierarchy::instance_view;
use mts_render::{
    Camera, FrameStats, Gpu, HierarchyFrame, HierarchyInstanceId, HierarchyRenderer, Image,
    InstancedScene, RendererConfig, Shading, StripMode,
};
use support::{default_gpu, difference, gpu_on};

const WIDTH: u32 = 320;
const HEIGHT: u32 = 240;

fn terrain() -> Hierarchy {
    let mesh = "terrain:20k".parse::<Generated>().unwrap().build();
    let h = hierarchy::build(&mesh, &HierarchyOptions::default()).unwrap();
    assert!(h.level_count() >= 3, "{} levels", h.level_count());
    h
}

/// The flight: over a corner, far above, low across, back near the corner
/// and away (the terrain spans -1..1 in x and z, heights 0..0.3).
fn cameras(aspect: f32) -> Vec<Camera> {
    [
        (Vec3::new(-1.3, 0.5, -1.3), Vec3::new(0.0, 0.1, 0.0)),
        (Vec3::new(0.0, 4.0, 3.0), Vec3::ZERO),
        (Vec3::new(-0.8, 0.3, -0.2), Vec3::new(0.5, 0.05, 0.3)),
        (Vec3::new(-0.5, 0.32, -0.1), Vec3::new(0.7, 0.05, 0.4)),
        (Vec3::new(0.95, 0.4, 0.95), Vec3::new(0.4, 0.1, 0.4)),
        (Vec3::new(0.0, 4.0, 3.0), Vec3::ZERO),
        (Vec3::new(-1.1, 0.45, -1.2), Vec3::new(0.0, 0.1, 0.0)),
    ]
    .into_iter()
    .map(|(eye, target)| Camera::looking(eye, target, aspect, 0.005, 12.0))
    .collect()
}

/// The first `count` indices of `buffer` (restarts as `u32::MAX`).
fn read_indices(
    gpu: &Gpu,
    buffer: &wgpu::Buffer,
    format: wgpu::IndexFormat,
    count: usize,
) -> Vec<u32> {
    let (device, queue) = (&gpu.device, &gpu.queue);
    let staging = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("test readback"),
        size: buffer.size(),
        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor::default());
    encoder.copy_buffer_to_buffer(buffer, 0, &staging, 0, buffer.size());
    queue.submit([encoder.finish()]);
    staging
        .slice(..)
        .map_async(wgpu::MapMode::Read, |r| r.unwrap());
    device.poll(wgpu::PollType::wait_indefinitely()).unwrap();
    let bytes = staging.slice(..).get_mapped_range().unwrap().to_vec();
    match format {
        wgpu::IndexFormat::Uint16 => bytes
            .chunks_exact(2)
            .take(count)
            .map(|b| match u16::from_le_bytes([b[0], b[1]]) {
                u16::MAX => u32::MAX,
                v => u32::from(v),
            })
            .collect(),
        wgpu::IndexFormat::Uint32 => bytes
            .chunks_exact(4)
            .take(count)
            .map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
            .collect(),
    }
}

/// One renderer's flight: each frame's stats, and per camera the lit and
/// unlit images.
struct Flight {
    frames: Vec<HierarchyFrame>,
    images: Vec<(Image, Image)>,
}

/// Flies `renderer` (and its `ViewDependent`) along the cameras at
/// `pixel_threshold`; per frame checks the index buffer against the arena
/// (restart path) and the image against the cut drawn as a list from
/// scratch (through `oracle`'s own strip renderer: the same vertices).
fn fly(gpu: &Gpu, h: &Hierarchy, mode: StripMode, pixel_threshold: f32, cull: bool) -> Flight {
    let (d, q) = (&gpu.device, &gpu.queue);
    let target = HeadlessTarget::new(d, WIDTH, HEIGHT).unwrap();
    let config = RendererConfig::headless(mode);
    let mut renderer = HierarchyRenderer::new(d, q, &config, h).unwrap();
    let mut oracle = HierarchyRenderer::new(d, q, &config, h).unwrap();
    assert_eq!(renderer.strip_mode(), mode);
    let mut view = ViewDependent::new(h);
    let mut flight = Flight {
        frames: Vec::new(),
        images: Vec::new(),
    };
    for (i, camera) in cameras(target.aspect()).iter().enumerate() {
        let context = format!("{mode:?}, {pixel_threshold} px, cull {cull}, camera {i}");
        let frame = renderer
            .update(
                d,
                q,
                &mut view,
                camera,
                HEIGHT as f32,
                pixel_threshold,
                cull,
            )
            .unwrap();
        assert_eq!(frame.triangles, view.triangle_count(), "{context}");
        assert_eq!(frame.indices_sent, view.indices_sent(), "{context}");
        assert!(frame.gpu_bytes >= 2 * frame.indices_drawn, "{context}");
        if mode == StripMode::Restart {
            assert_eq!(frame.indices_drawn, view.buffer().len(), "{context}");
            let gpu_indices = read_indices(
                gpu,
                renderer.index_buffer().unwrap(),
                renderer.index_format(),
                view.buffer().len(),
            );
            assert!(
                gpu_indices == view.buffer(),
                "{context}: the index buffer is not the arena"
            );
        }
        // The cut from scratch, every selected group and cluster (culled
        // ones lie outside the view and add no pixel).
        let cut = view.cut().clone();
        let list = cut.triangles(h);
        if !cull {
            assert_eq!(list.len(), frame.triangles, "{context}");
        }
        let strips = oracle.strip_renderer_mut();
        strips.upload_list(d, q, &list).unwrap();
        let mut images = Vec::new();
        for shading in [Shading::Lit, Shading::Unlit] {
            let camera = Camera { shading, ..*camera };
            renderer.set_camera(q, &camera);
            oracle.set_camera(q, &camera);
            let a = target
                .render_image(d, q, |pass| renderer.draw(pass))
                .unwrap();
            let b = target
                .render_image(d, q, |pass| oracle.strip_renderer().draw(pass))
                .unwrap();
            let fg = a.foreground_pixels();
            assert!(fg >= 5_000, "{context}: {fg} foreground pixels");
            let (differ, step) = difference(&a, &b);
            match shading {
                Shading::Unlit => assert_eq!(
                    (differ, step),
                    (0, 0),
                    "{context}: the arena and the cut's list cover different pixels"
                ),
                Shading::Lit => assert!(
                    step <= 1 && differ <= fg / 1000,
                    "{context}: lit, {differ} pixels differ by up to {step}"
                ),
            }
            images.push(a);
        }
        let unlit = images.pop().unwrap();
        let lit = images.pop().unwrap();
        eprintln!(
            "{context}: {} triangles, {} indices sent, {} drawn, {} bytes in {} writes, {} \
             foreground pixels",
            frame.triangles,
            frame.indices_sent,
            frame.indices_drawn,
            frame.upload.bytes,
            frame.upload.writes,
            unlit.foreground_pixels()
        );
        flight.frames.push(frame);
        flight.images.push((lit, unlit));
    }
    flight
}

/// The default adapter when it honours primitive restart (the GL test
/// covers the other case), or `None` with a message.
fn restart_gpu() -> Option<Gpu> {
    let gpu = default_gpu()?;
    if gpu.report().strip_mode != StripMode::Restart {
        assert!(
            !support::required_gpu(),
            "MTS_REQUIRE names gpu and the default adapter ignores primitive restart"
        );
        eprintln!("skipped: the default adapter ignores primitive restart");
        return None;
    }
    Some(gpu)
}

#[test]
fn incremental_updates_draw_the_cut_and_stitching_draws_the_same() {
    let Some(gpu) = restart_gpu() else { return };
    let h = terrain();
    for px in [1.0, 4.0] {
        let restart = fly(&gpu, &h, StripMode::Restart, px, true);
        // Some update wrote less than the whole arena, and the flight
        // changed the drawn set (far cameras draw less).
        let partial = restart
            .frames
            .iter()
            .skip(1)
            .any(|f| f.upload.bytes < 2 * f.indices_drawn);
        assert!(partial, "{px} px: every update wrote the whole arena");
        let counts: Vec<usize> = restart.frames.iter().map(|f| f.triangles).collect();
        assert!(counts[1] < counts[0] && counts[2] > counts[1], "{counts:?}");
        // The stitched path sends the same triangles with the same vertex
        // orders: the same pixels, lit or not.
        let stitched = fly(&gpu, &h, StripMode::Stitched, px, true);
        for (i, (a, b)) in restart.images.iter().zip(&stitched.images).enumerate() {
            assert_eq!(difference(&a.0, &b.0), (0, 0), "{px} px, camera {i}, lit");
            assert_eq!(difference(&a.1, &b.1), (0, 0), "{px} px, camera {i}, unlit");
        }
    }
}

#[test]
fn culling_changes_no_pixel_and_draws_less() {
    // On the default adapter's strip mode (stitched under WGPU_BACKEND=gl).
    let Some(gpu) = default_gpu() else { return };
    let mode = gpu.report().strip_mode;
    let h = terrain();
    let culled = fly(&gpu, &h, mode, 1.0, true);
    let whole = fly(&gpu, &h, mode, 1.0, false);
    let mut fewer = 0;
    for (i, (a, b)) in culled.images.iter().zip(&whole.images).enumerate() {
        assert_eq!(difference(&a.0, &b.0), (0, 0), "camera {i}, lit");
        assert_eq!(difference(&a.1, &b.1), (0, 0), "camera {i}, unlit");
        let (c, w) = (culled.frames[i].triangles, whole.frames[i].triangles);
        assert!(c <= w, "camera {i}: {c} culled, {w} not");
        fewer += usize::from(c < w);
    }
    assert!(fewer >= 2, "the low cameras see part of the terrain");
}

#[test]
fn gl_backend_stitches_the_arena_and_draws_the_cut() {
    let Some(gpu) = gpu_on(wgpu::Backends::GL, "GL") else {
        return;
    };
    let report = gpu.report();
    eprintln!("adapter: {report}");
    assert_eq!(report.strip_mode, StripMode::Stitched);
    let h = terrain();
    fly(&gpu, &h, report.strip_mode, 1.0, true);
}

#[test]
fn a_view_of_another_hierarchy_is_refused() {
    let Some(gpu) = default_gpu() else { return };
    let (d, q) = (&gpu.device, &gpu.queue);
    let h = terrain();
    let small = "grid:2k".parse::<Generated>().unwrap().build();
    let other = hierarchy::build(&small, &HierarchyOptions::default()).unwrap();
    let config = RendererConfig::headless(gpu.report().strip_mode);
    let mut renderer = HierarchyRenderer::new(d, q, &config, &h).unwrap();
    let mut view = ViewDependent::new(&other);
    let camera = Camera::framing_points(h.positions(), 1.0);
    let e = renderer
        .update(d, q, &mut view, &camera, 240.0, 1.0, true)
        .unwrap_err()
        .to_string();
    assert!(e.contains("vertices"), "{e}");
}

/// Draws `scene` after updating it for `camera` (1 px), lit and unlit.
fn scene_images(
    gpu: &Gpu,
    target: &HeadlessTarget,
    scene: &mut InstancedScene<'_>,
    camera: &Camera,
) -> (Image, Image, FrameStats) {
    let (d, q) = (&gpu.device, &gpu.queue);
    let mut images = Vec::new();
    let mut stats = FrameStats::default();
    for shading in [Shading::Lit, Shading::Unlit] {
        let camera = Camera { shading, ..*camera };
        // The first update does the work; the second finds nothing to do.
        let s = scene.update(d, q, &camera, HEIGHT as f32, 1.0).unwrap();
        if shading == Shading::Lit {
            stats = s;
        }
        images.push(target.render_image(d, q, |pass| scene.draw(pass)).unwrap());
    }
    let unlit = images.pop().unwrap();
    (images.pop().unwrap(), unlit, stats)
}

/// Unlit equal pixel for pixel, lit within the rounding of another strip
/// order (see the module docs): two draws of the same triangles.
fn assert_same_triangles(a: &(Image, Image), b: &(Image, Image), context: &str) {
    assert_eq!(difference(&a.1, &b.1), (0, 0), "{context}: coverage");
    let fg = a.1.foreground_pixels();
    let (differ, step) = difference(&a.0, &b.0);
    assert!(
        step <= 1 && differ <= fg / 1000,
        "{context}: lit, {differ} pixels differ by up to {step}"
    );
}

#[test]
fn a_scene_draws_hierarchy_instances_beside_models() {
    // On the default adapter's strip mode (stitched under WGPU_BACKEND=gl).
    let Some(gpu) = default_gpu() else { return };
    let (d, q) = (&gpu.device, &gpu.queue);
    let config = RendererConfig::headless(gpu.report().strip_mode);
    let target = HeadlessTarget::new(d, WIDTH, HEIGHT).unwrap();
    let h = terrain();
    let torus = "torus:2k".parse::<Generated>().unwrap().build();
    let (model, _, _) = mts::model::try_build_from_mesh(
        &torus,
        &mts::model::PipelineOptions::default(),
        &mut |_, _| {},
    )
    .unwrap();
    let turned = |x: f32, a: f32, s: f32| {
        Mat4::from_scale_rotation_translation(
            Vec3::splat(s),
            Quat::from_rotation_y(a),
            Vec3::new(x, 0.0, 0.0),
        )
    };
    let placements = [Mat4::IDENTITY, turned(2.6, 0.6, 0.8)];
    let moved = turned(2.4, 1.1, 0.9);
    let ring = Mat4::from_scale_rotation_translation(
        Vec3::splat(0.15),
        Quat::IDENTITY,
        Vec3::new(1.3, 0.45, 0.9),
    );
    let cameras = [
        Camera::looking(
            Vec3::new(-1.0, 1.4, 3.2),
            Vec3::new(1.3, 0.0, 0.0),
            target.aspect(),
            0.01,
            20.0,
        ),
        Camera::looking(
            Vec3::new(-1.2, 0.45, -1.2),
            Vec3::new(0.0, 0.1, 0.0),
            target.aspect(),
            0.005,
            20.0,
        ),
        Camera::looking(
            Vec3::new(0.3, 0.5, 0.0),
            Vec3::new(-1.0, 0.1, 0.0),
            target.aspect(),
            0.005,
            20.0,
        ),
        Camera::looking(
            Vec3::new(2.0, 0.9, 2.2),
            Vec3::new(2.5, 0.1, 0.0),
            target.aspect(),
            0.005,
            20.0,
        ),
    ];
    // A scene of the final state, built afresh for one camera.
    let fresh = |camera: &Camera, second: Mat4| {
        let mut scene = InstancedScene::new(&config);
        let hid = scene.add_hierarchy(d, q, &h).unwrap();
        let mid = scene.add_model(d, q, &model).unwrap();
        scene.add_hierarchy_instance(hid, placements[0]).unwrap();
        scene.add_hierarchy_instance(hid, second).unwrap();
        scene.add_instance(mid, ring).unwrap();
        let (lit, unlit, stats) = scene_images(&gpu, &target, &mut scene, camera);
        ((lit, unlit), stats)
    };
    let mut scene = InstancedScene::new(&config);
    let hid = scene.add_hierarchy(d, q, &h).unwrap();
    let mid = scene.add_model(d, q, &model).unwrap();
    let ids: Vec<HierarchyInstanceId> = placements
        .iter()
        .map(|&t| scene.add_hierarchy_instance(hid, t).unwrap())
        .collect();
    scene.add_instance(mid, ring).unwrap();
    assert_eq!(scene.hierarchy_instance_count(), 2);
    assert!(scene.add_hierarchy_instance(hid, Mat4::ZERO).is_err());
    // Reference cuts: each instance's ViewDependent updated in its model
    // space.
    let mut references: Vec<ViewDependent> = ids.iter().map(|_| ViewDependent::new(&h)).collect();
    let mut second = placements[1];
    let mut culled = 0;
    for (step, camera) in cameras.iter().chain(&cameras).enumerate() {
        if step == cameras.len() {
            // The host moves the second instance: its cut follows.
            second = moved;
            scene.set_hierarchy_transform(ids[1], second).unwrap();
        }
        let (lit, unlit, stats) = scene_images(&gpu, &target, &mut scene, camera);
        let context = format!("step {step}");
        let mut triangles = 0;
        for (k, (&id, reference)) in ids.iter().zip(&mut references).enumerate() {
            let t = if k == 0 { placements[0] } else { second };
            let world = scene_bound(&h, t);
            let seen = Frustum::from_view_projection(camera.view_proj).may_see(world.0, world.1);
            match scene.hierarchy_frame(id) {
                Some(frame) => {
                    assert!(seen, "{context}: instance {k} drawn out of view");
                    let view = instance_view(camera, t, HEIGHT as f32, 1.0, true).unwrap();
                    reference.update(&view);
                    assert_eq!(
                        frame.triangles,
                        reference.triangle_count(),
                        "{context}, {k}"
                    );
                    assert_eq!(
                        frame.indices_sent,
                        reference.indices_sent(),
                        "{context}, {k}"
                    );
                    triangles += frame.triangles;
                }
                None => {
                    assert!(!seen, "{context}: instance {k} culled in view");
                    culled += 1;
                }
            }
        }
        assert!(triangles > 0 && stats.triangles >= triangles, "{context}");
        let (expected, fresh_stats) = fresh(camera, second);
        assert_eq!(fresh_stats.triangles, stats.triangles, "{context}");
        assert_eq!(fresh_stats.visible, stats.visible, "{context}");
        assert!(unlit.foreground_pixels() >= 5_000, "{context}");
        assert_same_triangles(&(lit, unlit), &expected, &context);
        eprintln!(
            "{context}: {} visible, {} triangles, {} indices drawn, {} bytes uploaded",
            stats.visible, stats.triangles, stats.indices_drawn, stats.upload_bytes
        );
    }
    // The camera looking west from the first instance's middle sees it
    // alone.
    assert!(culled >= 2, "{culled} instances culled");
    let memory = scene.memory();
    assert!(memory.gpu_index_bytes > 0 && memory.cpu_instance_bytes > 0);
    assert!(scene.remove_hierarchy_instance(ids[1]));
    assert!(!scene.remove_hierarchy_instance(ids[1]));
    assert_eq!(scene.hierarchy_instance_count(), 1);

    // An instance at the identity draws what a HierarchyRenderer draws,
    // pixel for pixel: the same cut, arena and vertex orders.
    let mut alone = InstancedScene::new(&config);
    let hid = alone.add_hierarchy(d, q, &h).unwrap();
    alone.add_hierarchy_instance(hid, Mat4::IDENTITY).unwrap();
    let mut renderer = HierarchyRenderer::new(d, q, &config, &h).unwrap();
    let mut view = ViewDependent::new(&h);
    for (i, camera) in cameras.iter().enumerate() {
        for shading in [Shading::Lit, Shading::Unlit] {
            let camera = Camera { shading, ..*camera };
            alone.update(d, q, &camera, HEIGHT as f32, 1.0).unwrap();
            renderer
                .update(d, q, &mut view, &camera, HEIGHT as f32, 1.0, true)
                .unwrap();
            let a = target.render_image(d, q, |pass| alone.draw(pass)).unwrap();
            let b = target
                .render_image(d, q, |pass| renderer.draw(pass))
                .unwrap();
            assert_eq!(difference(&a, &b), (0, 0), "camera {i}, {shading:?}");
        }
    }
}

/// The world bounding sphere of `h` placed at `t`, as the scene computes
/// it.
fn scene_bound(h: &Hierarchy, t: Mat4) -> (Vec3, f32) {
    let (lo, hi) = mts::mesh::bounds_of(h.positions()).unwrap();
    let scale = [t.x_axis, t.y_axis, t.z_axis]
        .iter()
        .map(|c| c.truncate().length())
        .fold(0.0f32, f32::max);
    (
        t.transform_point3((lo + hi) * 0.5),
        (mts::mesh::diagonal_of(lo, hi) as f32) * 0.5 * scale,
    )
}
