//! Criterion: one headless frame (submit and wait) of the MTS strips and of
//! the meshoptimizer-ordered triangle list (`optimize_vertex_cache`) at
//! 100%, 50% and 10% of the bunny's triangles (a generated 70K icosphere
//! when `../shared/models` is absent), in one group per level with
//! `Throughput::Elements(triangles)`; and one LoD step (extraction plus
//! dirty-range upload). The adapter is printed first; without one the bench
//! says so and measures nothing.

#[path = "../../mts/benches/common/mod.rs"]
mod common;

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use mts::model::{build, BuildOptions};
use mts::{peers, stripify, Extractor, SimplifyOptions, StripifyOptions};
use mts_render::headless::HeadlessTarget;
use mts_render::{Camera, Gpu, RendererConfig, StripRenderer};

fn bench(c: &mut Criterion) {
    let gpu = match Gpu::new_headless() {
        Ok(gpu) => gpu,
        Err(e) => {
            eprintln!("render bench skipped: {e}");
            return;
        }
    };
    let report = gpu.report();
    eprintln!("adapter: {report}");
    let (name, mesh) = common::bunny_or_generated();
    let strips = stripify(&mesh, &StripifyOptions::default());
    let collapses = mts::simplify(&mesh, &SimplifyOptions::default()).collapses;
    let model = build(&mesh, &strips, &collapses, &BuildOptions::default());
    let (d, q) = (&gpu.device, &gpu.queue);
    let config = RendererConfig::headless(report.strip_mode);
    let target = HeadlessTarget::new(d, 1024, 768).expect("1024x768 fits any adapter");
    let camera = Camera::framing_points(model.positions(), target.aspect());
    let mut mts_renderer = StripRenderer::for_model(d, q, &config, &model).expect("renderer");
    let mut list_renderer = StripRenderer::for_model(d, q, &config, &model).expect("renderer");
    mts_renderer.set_camera(q, &camera);
    list_renderer.set_camera(q, &camera);
    let mut ex = Extractor::new(&model);
    for ratio in [1.0, 0.5, 0.1] {
        let lod = model.lod_for_ratio(ratio);
        let triangles = model.triangle_count(lod);
        ex.set_lod(lod);
        mts_renderer.upload_strips(d, q, &ex).expect("upload");
        let oracle = collapses.triangles_at(&mesh, lod);
        let ordered = peers::meshopt::optimize_vertex_cache(&oracle, model.positions().len());
        list_renderer.upload_list(d, q, &ordered).expect("upload");
        let level = format!("{:.0}%", 100.0 * ratio);
        let mut group = c.benchmark_group(format!("render/{name}/{}", report.backend));
        group.sample_size(20);
        group.measurement_time(std::time::Duration::from_secs(3));
        group.throughput(Throughput::Elements(triangles as u64));
        for (method, renderer) in [("mts", &mts_renderer), ("meshopt", &list_renderer)] {
            group.bench_function(BenchmarkId::new(method, &level), |b| {
                b.iter(|| {
                    target
                        .render(d, q, |pass| renderer.draw(pass))
                        .expect("frame");
                });
            });
        }
        group.finish();
    }
    // One LoD step back and forth in the middle of the sequence.
    let mid = model.max_lod() / 2;
    let mut group = c.benchmark_group(format!("render/{name}/lod_step"));
    let mut flip = false;
    group.bench_function("extract_and_upload", |b| {
        b.iter(|| {
            flip = !flip;
            ex.set_lod(mid + usize::from(flip));
            mts_renderer.update_strips(d, q, &ex).expect("upload");
            // Submitting makes wgpu copy the staged writes (and keeps them
            // from piling up over millions of iterations).
            q.submit([]);
        });
    });
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
