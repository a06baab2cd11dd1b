//! Criterion: the MTS model on the bunny (or a generated 70K icosphere when
//! `../shared/models` is absent): building the graphs from strips and the
//! contraction sequence (one band, and banded), extracting LoD 0 from
//! scratch, and a linear sweep of 1,000 LoD steps with and without the
//! coherence cache (divide by 1,000 for one step).

use criterion::{criterion_group, criterion_main, Criterion};
use mts::mesh::generate::Generated;
use mts::mesh::io::{load, LoadOptions};
use mts::model::{build, BuildOptions};
use mts::{stripify, Extractor, Mesh, SimplifyOptions, StripifyOptions};
use std::hint::black_box;
use std::path::Path;

fn input() -> (String, Mesh) {
    let bunny = Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/models/bunny.ply");
    match load(&bunny, LoadOptions::default()) {
        Ok((mesh, _)) => ("bunny".into(), mesh),
        Err(e) => {
            eprintln!("the bunny is missing ({e}); using icosphere:70k");
            let g: Generated = "icosphere:70k".parse().expect("valid name");
            ("icosphere:70k".into(), g.build())
        }
    }
}

fn bench(c: &mut Criterion) {
    let (name, mesh) = input();
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
    let model = build(&mesh, &strips, &collapses, &BuildOptions::default());
    let mut ex = Extractor::new(&model);
    group.sample_size(50);
    group.bench_function("extract_lod0_from_scratch", |b| {
        b.iter(|| ex.set_lod_from_scratch(black_box(0)));
    });
    // 1,000 consecutive LoDs from the middle of the sequence.
    let start = model.max_lod() / 4;
    let steps = 1000.min(model.max_lod() - start);
    group.bench_function("linear_sweep_1000_coherent", |b| {
        b.iter(|| {
            for lod in start..start + steps {
                ex.set_lod(black_box(lod));
            }
        });
    });
    group.bench_function("linear_sweep_1000_from_scratch", |b| {
        b.iter(|| {
            for lod in start..start + steps {
                ex.set_lod_from_scratch(black_box(lod));
            }
        });
    });
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
