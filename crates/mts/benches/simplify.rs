//! Criterion: the whole contraction sequence (mts, serial and in 4 regions
//! at once) beside meshoptimizer's `simplify` to 10% of the triangles, on the bunny (when
//! `../shared/models` is present), on generated icospheres and on a dense
//! non-manifold mesh (20,000 random distinct triangles over 256 vertices:
//! issue 31's wide fans, `docs/experiments/simplify-dense.md`).

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use glam::Vec3;
use mts::mesh::generate::Generated;
use mts::mesh::io::{load, LoadOptions};
use mts::{peers, simplify, Mesh, SimplifyOptions};
use std::collections::HashSet;
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
    out.push(("dense:20k/256".to_string(), dense(256, 20_000)));
    out
}

/// `count` distinct random triangles (no two on the same three vertices)
/// over `vertices` random points of the unit cube, from a fixed linear
/// congruential sequence: every vertex in about `3 count / vertices`
/// triangles, every pair of vertices a common neighbour.
fn dense(vertices: u32, count: usize) -> Mesh {
    let mut state = 31u64;
    let mut next = move || {
        state = state
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (state >> 33) as u32
    };
    let positions = (0..vertices)
        .map(|_| Vec3::new(next() as f32, next() as f32, next() as f32) / 2f32.powi(31))
        .collect();
    let mut seen = HashSet::new();
    let mut triangles = Vec::with_capacity(count);
    while triangles.len() < count {
        let t = [next() % vertices, next() % vertices, next() % vertices];
        let mut key = t;
        key.sort_unstable();
        if key[0] != key[1] && key[1] != key[2] && seen.insert(key) {
            triangles.push(t);
        }
    }
    Mesh {
        positions,
        triangles,
        properties: Default::default(),
    }
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
        // The same sequence made in 4 parts at once (`simplify_in_regions`),
        // on meshes of positions only.
        if mts::simplify::regions_refusal(&mesh, &SimplifyOptions::default()).is_none() {
            group.bench_with_input(
                BenchmarkId::new("mts_whole_sequence_4_regions", &name),
                &mesh,
                |b, m| {
                    b.iter(|| {
                        mts::simplify::simplify_in_regions(
                            black_box(m),
                            &SimplifyOptions::default(),
                            4,
                        )
                    });
                },
            );
        }
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
