//! Stripification speed: the project's stripifier against meshoptimizer's
//! (`optimize_vertex_cache_strip` + `stripify`) on generated meshes of three
//! sizes (to show linear growth) and on the bunny when `../shared/models`
//! is present; the cache-aware option (`mts-cache-aware`) beside them.

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use mts::mesh::generate::Generated;
use mts::mesh::io::{load, LoadOptions};
use mts::mesh::Mesh;
use mts::{peers, stripify, StripifyOptions};
use std::hint::black_box;
use std::path::Path;

fn meshes() -> Vec<(String, Mesh)> {
    let mut out: Vec<(String, Mesh)> = ["icosphere:100k", "icosphere:300k", "icosphere:1M"]
        .iter()
        .map(|name| {
            let g: Generated = name.parse().expect("valid generated name");
            (name.to_string(), g.build())
        })
        .collect();
    let bunny = Path::new(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../../shared/models/bunny.ply"
    ));
    match load(bunny, LoadOptions::default()) {
        Ok((mesh, _)) => out.insert(0, ("bunny".into(), mesh)),
        Err(e) => eprintln!("skipped the bunny: {e}"),
    }
    out
}

fn bench(c: &mut Criterion) {
    let mut group = c.benchmark_group("stripify");
    group.sample_size(10);
    for (name, mesh) in meshes() {
        group.throughput(Throughput::Elements(mesh.triangle_count() as u64));
        group.bench_with_input(BenchmarkId::new("mts", &name), &mesh, |b, m| {
            b.iter(|| black_box(stripify(m, &StripifyOptions::default())))
        });
        group.bench_with_input(BenchmarkId::new("meshopt", &name), &mesh, |b, m| {
            b.iter(|| black_box(peers::meshopt::stripify(m)))
        });
        let aware = StripifyOptions {
            cache_aware: true,
            ..StripifyOptions::default()
        };
        group.bench_with_input(BenchmarkId::new("mts-cache-aware", &name), &mesh, |b, m| {
            b.iter(|| black_box(stripify(m, &aware)))
        });
    }
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
