//! Criterion: microseconds per LoD change of MTS and every baseline on the
//! MTS paper's Table 2 request sequences (linear, exponential, random; 100
//! requests each, from each method's own LoD table), one group per
//! sequence with the methods side by side. The bunny, or a generated 70K
//! icosphere when `../shared/models` is absent. Throughput is per change.

mod common;

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use mts::methods::Method;
use mts::model::{build_from_mesh, requests, PipelineOptions};
use mts::LodSource;
use std::hint::black_box;

const REQUESTS: usize = 100;

fn bench(c: &mut Criterion) {
    let (name, mesh) = common::bunny_or_generated();
    let (model, _, _) = build_from_mesh(&mesh, &PipelineOptions::default(), &mut |_, _| {});
    let mut sources: Vec<Box<dyn LodSource + '_>> = Method::ALL
        .iter()
        .map(|m| {
            m.source(&model, &mesh)
                .expect("every method builds on the bench mesh")
        })
        .collect();
    for seq in ["linear", "exponential", "random"] {
        let mut group = c.benchmark_group(format!("lod_change/{name}/{seq}"));
        // Short: the machine is shared (warm-up 1 s, 2 s per method).
        group.sample_size(10);
        group.warm_up_time(std::time::Duration::from_secs(1));
        group.measurement_time(std::time::Duration::from_secs(2));
        group.throughput(Throughput::Elements(REQUESTS as u64));
        for source in &mut sources {
            let max_lod = source.max_lod();
            let counts: Vec<u32> = (0..=max_lod)
                .map(|l| source.triangle_count(l) as u32)
                .collect();
            let (_, lods) = requests::table2(&counts, REQUESTS)
                .into_iter()
                .find(|(name, _)| *name == seq)
                .expect("a Table 2 sequence");
            group.bench_function(source.name(), |b| {
                b.iter(|| {
                    for &lod in &lods {
                        source.set_lod(black_box(lod));
                    }
                });
            });
        }
        group.finish();
    }
}

criterion_group!(benches, bench);
criterion_main!(benches);
