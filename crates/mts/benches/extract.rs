//! Criterion: LoD extraction on the bunny (or a generated 70K icosphere when
//! `../shared/models` is absent), the MTS paper's Table 2: the linear,
//! exponential and random request sequences (1,000 requests each, see
//! `mts::model::requests`), with the coherence cache and from scratch, side
//! by side in one group; plus LoD 0 from scratch and 1,000 consecutive LoDs
//! (a step of one, the "linear sweep over all LoDs" case). Throughput is
//! per LoD change. A second group: one-step changes near LoD 0 on the
//! built-in 100K-triangle icosphere, whose LoD 0 is one long strip (the
//! case coherence inside strips is for).

mod common;

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use mts::model::{build_from_mesh, requests, PipelineOptions};
use mts::Extractor;
use std::hint::black_box;

const REQUESTS: usize = 1000;

fn bench(c: &mut Criterion) {
    let (name, mesh) = common::bunny_or_generated();
    let (model, _, _) = build_from_mesh(&mesh, &PipelineOptions::default(), &mut |_, _| {});
    let max_lod = model.max_lod();
    let start = max_lod / 4;
    let [linear, exponential, random] = requests::table2(model.triangle_counts(), REQUESTS);
    let sequences = [
        linear,
        exponential,
        random,
        (
            "consecutive",
            (start..(start + REQUESTS).min(max_lod + 1)).collect(),
        ),
    ];
    let mut ex = Extractor::new(&model);
    let mut group = c.benchmark_group(format!("extract/{name}"));
    group.sample_size(50);
    group.throughput(Throughput::Elements(1));
    group.bench_function("lod0_from_scratch", |b| {
        b.iter(|| ex.set_lod_from_scratch(black_box(0)));
    });
    group.sample_size(10);
    for (seq, lods) in &sequences {
        group.throughput(Throughput::Elements(lods.len() as u64));
        group.bench_function(format!("{seq}/coherent"), |b| {
            b.iter(|| {
                for &lod in lods {
                    ex.set_lod(black_box(lod));
                }
            });
        });
        group.bench_function(format!("{seq}/from_scratch"), |b| {
            b.iter(|| {
                for &lod in lods {
                    ex.set_lod_from_scratch(black_box(lod));
                }
            });
        });
    }
    group.finish();

    let ico: mts::Mesh = "icosphere:100k"
        .parse::<mts::mesh::generate::Generated>()
        .expect("valid name")
        .build();
    let (model, _, _) = build_from_mesh(&ico, &PipelineOptions::default(), &mut |_, _| {});
    let mut ex = Extractor::new(&model);
    let mut group = c.benchmark_group("extract/icosphere:100k");
    group.sample_size(20);
    // 1 -> 2 -> 1 -> ...: every call a one-step change near LoD 0.
    let steps: Vec<usize> = (0..1000).map(|i| 1 + i % 2).collect();
    group.throughput(Throughput::Elements(steps.len() as u64));
    for (label, coherent) in [
        ("one_step_near_lod0/coherent", true),
        ("one_step_near_lod0/from_scratch", false),
    ] {
        group.bench_function(label, |b| {
            b.iter(|| {
                for &lod in &steps {
                    if coherent {
                        ex.set_lod(black_box(lod));
                    } else {
                        ex.set_lod_from_scratch(black_box(lod));
                    }
                }
            });
        });
    }
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
