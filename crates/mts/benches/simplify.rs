//! Criterion: the whole contraction sequence (mts) beside meshoptimizer's
//! `simplify` to 10% of the triangles, on the bunny (when
//! `../shared/models` is present) and on generated icospheres.

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use mts::mesh::generate::Generated;
use mts::mesh::io::{load, LoadOptions};
use mts::{peers, simplify, Mesh, SimplifyOptions};
use std::hint::black_box;
use std::path::Path;

fn inputs() -> Vec<(String, Mesh)> {
    let mut out = Vec::new();
    let bunny = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/models/bunny.ply");
    match load(&bunny, LoadOptions::default()) {
        Ok((mesh, _)) => out.push(("bunny".to_string(), mesh)),
        Err(e) => eprintln!("skipped the bunny: {e}"),
    }
    for name in ["icosphere:100k", "icosphere:1M"] {
        let g: Generated = name.parse().expect("a valid generated name");
        out.push((name.to_string(), g.build()));
    }
    out
}

fn bench(c: &mut Criterion) {
    let mut group = c.benchmark_group("simplify");
    group.sample_size(10);
    for (name, mesh) in inputs() {
        group.throughput(Throughput::Elements(mesh.triangle_count() as u64));
        group.bench_with_input(
            BenchmarkId::new("mts_whole_sequence", &name),
            &mesh,
            |b, m| {
                b.iter(|| simplify(black_box(m), &SimplifyOptions::default()));
            },
        );
        let target = mesh.triangle_count() / 10;
        group.bench_with_input(
            BenchmarkId::new("meshopt_to_10_percent", &name),
            &mesh,
            |b, m| {
                b.iter(|| peers::meshopt::simplify(black_box(m), target));
            },
        );
    }
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
