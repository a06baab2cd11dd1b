//! mts-render inside a caller's own wgpu code: the caller owns the
//! instance, device, queue, target texture and render pass.
//!
//! First one `StripRenderer`: it uploads vertices once, then after each LoD
//! change the index ranges the extractor rewrote, and records its draw.
//! Then an `InstancedScene` the host drives: two models, instances placed,
//! moved every frame, removed and added, each given the coarsest LoD whose
//! error projects within one pixel, drawn from buffers shared by all
//! instances in its LoD bucket (one instanced draw per model and bucket),
//! culled by the instance BVH (refitted when instances move, rebuilt when
//! they come and go), drawn in the host's pass.
//!
//! Run with `cargo run --release -p mts-render --example embed` (lavapipe
//! is enough).

use glam::{Mat4, Vec3};
use mts::mesh::generate::Generated;
use mts::model::{build, BuildOptions};
use mts::{stripify, Extractor, Mesh, SimplifyOptions, StripifyOptions};
use mts_render::wgpu;
use mts_render::{Camera, RendererConfig, StripMode, StripRenderer};
use std::time::Instant;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    // The model: a 20K-triangle torus, strips, contraction sequence, graphs.
    let mesh: Mesh = "torus:20k".parse::<Generated>()?.build();
    let strips = stripify(&mesh, &StripifyOptions::default());
    let collapses = mts::simplify(&mesh, &SimplifyOptions::default()).collapses;
    let model = build(&mesh, &strips, &collapses, &BuildOptions::default());

    // The caller's own device and queue.
    let instance =
        wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle_from_env());
    let adapter =
        pollster::block_on(instance.request_adapter(&wgpu::RequestAdapterOptions::default()))?;
    let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
        required_limits: wgpu::Limits::downlevel_defaults().using_resolution(adapter.limits()),
        ..wgpu::DeviceDescriptor::default()
    }))?;
    let info = adapter.get_info();
    println!("adapter: {} ({:?})", info.name, info.backend);

    // The caller's own target: 640 x 480 colour and depth.
    let size = wgpu::Extent3d {
        width: 640,
        height: 480,
        depth_or_array_layers: 1,
    };
    let texture = |format, label| {
        device
            .create_texture(&wgpu::TextureDescriptor {
                label: Some(label),
                size,
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format,
                usage: wgpu::TextureUsages::RENDER_ATTACHMENT,
                view_formats: &[],
            })
            .create_view(&wgpu::TextureViewDescriptor::default())
    };
    let color = texture(wgpu::TextureFormat::Bgra8UnormSrgb, "colour");
    let depth = texture(wgpu::TextureFormat::Depth24Plus, "depth");

    // The renderer, told the caller's formats and the strip mode that
    // suits the adapter's backend.
    let config = RendererConfig {
        color_format: wgpu::TextureFormat::Bgra8UnormSrgb,
        depth_format: Some(wgpu::TextureFormat::Depth24Plus),
        strip_mode: StripMode::for_backend(info.backend),
    };
    let mut renderer = StripRenderer::for_model(&device, &queue, &config, &model)?;
    renderer.set_camera(
        &queue,
        &Camera::framing_points(model.positions(), 640.0 / 480.0),
    );
    println!(
        "{} vertices, {:?} indices, strips by {}",
        renderer.vertex_count(),
        renderer.index_format(),
        renderer.strip_mode()
    );

    let mut extractor = Extractor::new(&model);
    for ratio in [1.0, 0.9, 0.5, 0.45, 0.2, 0.05, 0.5, 1.0] {
        let t = Instant::now();
        let update = extractor.set_ratio(ratio);
        let upload = renderer.update_strips(&device, &queue, &extractor)?;
        let us = t.elapsed().as_secs_f64() * 1e6;

        // The caller's frame: its encoder, its pass, the renderer's draw.
        let t = Instant::now();
        frame(&device, &queue, &color, &depth, |pass| renderer.draw(pass))?;
        let frame_ms = t.elapsed().as_secs_f64() * 1e3;
        println!(
            "ratio {ratio:4}: LoD {:5}, {:5} triangles, {:2} strips walked, \
             {:2} dirty ranges -> {:3} writes, {:6} bytes uploaded, \
             {:5} indices sent; extract+upload {us:6.0} us, frame {frame_ms:5.1} ms",
            update.lod,
            model.triangle_count(update.lod),
            update.strips_walked,
            update.dirty_ranges,
            upload.writes,
            upload.bytes,
            extractor.indices_sent(),
        );
    }

    // The scene: two models, 300 instances on a ring that turns a little
    // every frame; every tenth frame some leave and others arrive.
    let sphere: Mesh = "icosphere:5k".parse::<Generated>()?.build();
    let sphere_model = build(
        &sphere,
        &stripify(&sphere, &StripifyOptions::default()),
        &mts::simplify(&sphere, &SimplifyOptions::default()).collapses,
        &BuildOptions::default(),
    );
    let mut scene = mts_render::InstancedScene::new(&config);
    let models = [
        scene.add_model(&device, &queue, &model)?,
        scene.add_model(&device, &queue, &sphere_model)?,
    ];
    let place = |i: usize, turn: f32| {
        let angle = i as f32 * 0.021 + turn;
        let radius = 12.0 + (i % 7) as f32 * 3.0;
        Mat4::from_translation(Vec3::new(angle.cos(), 0.0, angle.sin()) * radius)
    };
    let mut live: Vec<(usize, mts_render::InstanceId)> = (0..300)
        .map(|i| Ok((i, scene.add_instance(models[i % 2], place(i, 0.0))?)))
        .collect::<mts::Result<_>>()?;
    let camera = Camera::looking(
        Vec3::new(0.0, 18.0, 45.0),
        Vec3::ZERO,
        640.0 / 480.0,
        0.1,
        200.0,
    );
    for step in 0..30 {
        let turn = step as f32 * 0.05;
        for &(i, id) in &live {
            scene.set_transform(id, place(i, turn))?;
        }
        if step % 10 == 9 {
            // Twenty leave, twenty new ones arrive.
            for (_, id) in live.drain(..20) {
                scene.remove_instance(id);
            }
            for i in 300 + step * 20..320 + step * 20 {
                live.push((i, scene.add_instance(models[i % 2], place(i, turn))?));
            }
        }
        let t = Instant::now();
        let stats = scene.update(
            &device,
            &queue,
            &camera,
            480.0,
            mts_render::scene::DEFAULT_PIXEL_ERROR,
        )?;
        let update_ms = t.elapsed().as_secs_f64() * 1e3;
        frame(&device, &queue, &color, &depth, |pass| scene.draw(pass))?;
        if step % 5 == 0 || step % 10 == 9 {
            let memory = scene.memory();
            println!(
                "scene frame {step:2}: {} instances, {} visible, {} triangles ({} at full \
                 detail), {} draws, {} bucket changes, {} extractions, {} bytes uploaded, BVH \
                 {:?}; update {update_ms:.2} ms; {} CPU bytes per instance, {} GPU bytes in {} \
                 buffers",
                scene.instance_count(),
                stats.visible,
                stats.triangles,
                stats.triangles_full_detail,
                stats.draws,
                stats.lod_changes,
                stats.extractions,
                stats.upload_bytes,
                stats.bvh,
                memory.cpu_bytes_per_instance(),
                memory.gpu_bytes(),
                memory.buffers
            );
        }
    }
    Ok(())
}

/// The caller's frame: its encoder, its pass (cleared colour and depth),
/// `draw` recording into it, submitted and waited for.
fn frame(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    color: &wgpu::TextureView,
    depth: &wgpu::TextureView,
    draw: impl FnOnce(&mut wgpu::RenderPass<'_>),
) -> Result<(), Box<dyn std::error::Error>> {
    let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor::default());
    {
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("frame"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: color,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Clear(wgpu::Color::BLACK),
                    store: wgpu::StoreOp::Store,
                },
            })],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: depth,
                depth_ops: Some(wgpu::Operations {
                    load: wgpu::LoadOp::Clear(1.0),
                    store: wgpu::StoreOp::Discard,
                }),
                stencil_ops: None,
            }),
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        draw(&mut pass);
    }
    queue.submit([encoder.finish()]);
    device.poll(wgpu::PollType::wait_indefinitely())?;
    Ok(())
}
