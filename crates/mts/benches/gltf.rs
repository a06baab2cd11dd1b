//! Criterion: reading the bunny (or a generated 70K icosphere when
//! `../shared/models` is absent) as glTF from bytes in memory, as `mts`
//! writes it plain (floats), quantized (`KHR_mesh_quantization`) and
//! compressed (`EXT_meshopt_compression`): parse, decode, check, the
//! `RawMesh` ready. The level is in vertex-cache order, as the writer's
//! callers give it. The files are written to a temporary folder first.

mod common;

use criterion::{criterion_group, criterion_main, Criterion};
use mts::mesh::io::{order_for_cache, parse_gltf, save_gltf_as, Encoding};
use std::hint::black_box;

fn bench(c: &mut Criterion) {
    let (name, mesh) = common::bunny_or_generated();
    let mesh = order_for_cache(&mesh);
    let dir = std::env::temp_dir().join(format!("mts-bench-gltf-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("a temporary folder");
    let mut group = c.benchmark_group(format!("gltf/{name}"));
    group.sample_size(20);
    for (label, encoding) in [
        ("read_plain", Encoding::Plain),
        ("read_quantized", Encoding::Quantized),
        ("read_compressed", Encoding::Compressed),
    ] {
        let path = dir.join(format!("{label}.glb"));
        save_gltf_as(&mesh, &path, encoding).expect("the file is written");
        let bytes = std::fs::read(&path).expect("the file is read");
        eprintln!("{label}: {} bytes", bytes.len());
        group.bench_function(label, |b| {
            b.iter(|| parse_gltf(black_box(&bytes), &path).expect("the file parses"));
        });
    }
    group.finish();
    let _ = std::fs::remove_dir_all(&dir);
}

criterion_group!(benches, bench);
criterion_main!(benches);
