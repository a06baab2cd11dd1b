//! Criterion: building the MTS model of the bunny (or a generated 70K
//! icosphere when `../shared/models` is absent): the graphs from strips and
//! the contraction sequence (one band, and banded), and the whole pipeline
//! from the mesh; loading the model's `.mts` bytes (parse, validate,
//! extractor ready): uncoded (version 3), coded with its chunks (version
//! 6, what `mts build` writes), and opening that file's first chunks only
//! (the 1% and 10% prefixes, built). Extraction is in `benches/extract.rs`.

mod common;

use criterion::{criterion_group, criterion_main, Criterion};
use mts::model::{build, build_from_mesh, BuildOptions, PipelineOptions};
use mts::{stripify, SimplifyOptions, StripifyOptions};
use std::hint::black_box;

fn bench(c: &mut Criterion) {
    let (name, mesh) = common::bunny_or_generated();
    let strips = stripify(&mesh, &StripifyOptions::default());
    let collapses = mts::simplify(&mesh, &SimplifyOptions::default()).collapses;
    let one_band = BuildOptions {
        band_slack: f64::INFINITY,
        ..BuildOptions::default()
    };
    let mut group = c.benchmark_group(format!("model/{name}"));
    group.sample_size(10);
    group.bench_function("build_one_band", |b| {
        b.iter(|| build(black_box(&mesh), &strips, &collapses, &one_band));
    });
    group.bench_function("build_banded", |b| {
        b.iter(|| {
            build(
                black_box(&mesh),
                &strips,
                &collapses,
                &BuildOptions::default(),
            )
        });
    });
    group.bench_function("pipeline_from_mesh", |b| {
        b.iter(|| {
            build_from_mesh(
                black_box(&mesh),
                &PipelineOptions::default(),
                &mut |_, _| {},
            )
        });
    });
    let model = build(&mesh, &strips, &collapses, &BuildOptions::default());
    let bytes = model.to_bytes();
    let file = std::path::Path::new("model.mts");
    group.bench_function("load_ready", |b| {
        b.iter(|| {
            let m = mts::MtsModel::from_bytes(black_box(&bytes), file).expect("loads");
            black_box(mts::Extractor::new(&m).buffer().len())
        });
    });
    let streamed = model.to_streamed_bytes(
        mts::model::compress::DEFAULT_LEVEL,
        &mts::model::DEFAULT_PREFIX_SHARES,
    );
    group.bench_function("load_streamed_whole", |b| {
        b.iter(|| {
            let m = mts::MtsModel::from_bytes(black_box(&streamed), file).expect("loads");
            black_box(mts::Extractor::new(&m).buffer().len())
        });
    });
    let chunks = mts::model::chunk_index(&streamed, file).expect("its chunks");
    for (chunk, share) in chunks.iter().zip(["1", "10"]) {
        let prefix = &streamed[..chunk.end];
        group.bench_function(format!("open_prefix_{share}_percent"), |b| {
            b.iter(|| {
                let p = mts::MtsModel::from_prefix(black_box(prefix), file).expect("opens");
                black_box(mts::Extractor::new(&p.model).buffer().len())
            });
        });
    }
    group.bench_function("validate", |b| {
        b.iter(|| black_box(&model).validate());
    });
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
