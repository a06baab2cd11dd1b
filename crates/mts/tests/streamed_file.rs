//! The version-6 `.mts` file (issue 34, item 2: a file that streams):
//! every prefix that holds a whole chunk opens as the model of the LoDs it
//! holds, drawing the whole model's triangles there; shorter prefixes,
//! corrupt and lying chunks are refused with the place named; the whole
//! file loads as the version-5 model.

mod common;

use mts::mesh::generate::Generated;
use mts::model::format::{file_version, seal, COMPRESSED_VERSION};
use mts::model::{build_from_mesh, PipelineOptions, DEFAULT_PREFIX_SHARES, STREAMED_VERSION};
use mts::simplify::{Placement, SimplifyOptions};
use mts::{Error, Extractor, Mesh, MtsModel};
use std::path::Path;

fn model_of(mesh: &Mesh, simplify: SimplifyOptions) -> MtsModel {
    let options = PipelineOptions {
        simplify,
        ..PipelineOptions::default()
    };
    build_from_mesh(mesh, &options, &mut |_, _| {}).0
}

fn torus() -> MtsModel {
    let mesh: Mesh = "torus:4k".parse::<Generated>().unwrap().build();
    model_of(&mesh, SimplifyOptions::default())
}

const FILE: &str = "streamed.mts";

/// The sections of a file: (tag, offset of the payload, payload length).
fn sections(bytes: &[u8]) -> Vec<([u8; 4], usize, usize)> {
    let mut at = 32;
    let mut out = Vec::new();
    while at + 12 <= bytes.len() {
        let len = u64::from_le_bytes(bytes[at + 4..at + 12].try_into().unwrap()) as usize;
        out.push((bytes[at..at + 4].try_into().unwrap(), at + 12, len));
        at += 12 + len;
    }
    out
}

fn triangle_set(t: Vec<[u32; 3]>) -> Vec<[u32; 3]> {
    let mut t: Vec<[u32; 3]> = t
        .into_iter()
        .map(|t| {
            let i = (0..3).min_by_key(|&i| t[i]).unwrap();
            [t[i], t[(i + 1) % 3], t[(i + 2) % 3]]
        })
        .collect();
    t.sort_unstable();
    t
}

#[test]
fn the_whole_file_is_the_model_and_its_chunks_come_first() {
    let model = torus();
    let bytes = model.to_streamed_bytes(3, &DEFAULT_PREFIX_SHARES);
    assert_eq!(file_version(&bytes), Some(STREAMED_VERSION));
    let tags: Vec<[u8; 4]> = sections(&bytes).iter().map(|s| s.0).collect();
    assert_eq!(
        tags,
        [
            *b"PRFX", *b"PRFX", *b"META", *b"POSI", *b"STRP", *b"STEP", *b"PROP", *b"CMPN",
            *b"MODL"
        ]
    );
    let back = MtsModel::from_bytes(&bytes, Path::new(FILE)).unwrap();
    assert_eq!(back, model);
    // The chunks cost a few percent of the version-5 file.
    let v5 = model.to_compressed_bytes(3);
    assert!(bytes.len() > v5.len() && bytes.len() < v5.len() * 115 / 100);
    let whole = MtsModel::from_prefix(&bytes, Path::new(FILE)).unwrap();
    assert!(whole.is_whole());
    assert_eq!(whole.lods_available(), 0..=model.max_lod());
    assert_eq!(whole.model, model);
}

#[test]
fn every_prefix_with_a_whole_chunk_draws_the_files_triangles() {
    let model = torus();
    let bytes = model.to_streamed_bytes(3, &DEFAULT_PREFIX_SHARES);
    let s = sections(&bytes);
    let (coarse_end, fine_end) = (s[0].1 + s[0].2, s[1].1 + s[1].2);
    let path = Path::new(FILE);
    let coarsest = model.lod_for_ratio(0.01);
    let tenth = model.lod_for_ratio(0.1);
    // Shorter than the first chunk: refused, naming the bytes.
    for n in [0, 31, 32, 40, coarse_end - 1] {
        let err = MtsModel::from_prefix(&bytes[..n], path).unwrap_err();
        assert!(
            matches!(err, Error::Parse { .. } | Error::UnknownFormat { .. }),
            "{n}: {err}"
        );
        assert!(err.to_string().contains("streamed.mts"), "{err}");
    }
    let mut whole = Extractor::new(&model);
    for (n, first) in [
        (coarse_end, coarsest),
        (fine_end - 1, coarsest),
        (fine_end, tenth),
        (bytes.len() - 1, tenth),
    ] {
        let p = MtsModel::from_prefix(&bytes[..n], path).unwrap();
        assert!(!p.is_whole());
        assert_eq!(p.first_lod, first, "prefix of {n} bytes");
        assert_eq!(p.lods_available(), first..=model.max_lod());
        assert_eq!(p.full_triangles, model.triangle_count(0));
        assert!(p.bytes_used <= n && p.file_bytes == bytes.len() as u64);
        assert_eq!(p.model.triangle_count(0), model.triangle_count(first));
        // Every LoD it holds draws the file's triangles, in the file's
        // vertex numbers, facing the same way.
        let mut ex = Extractor::new(&p.model);
        for lod in (first..=model.max_lod()).step_by(7) {
            ex.set_lod(p.model_lod(lod));
            whole.set_lod(lod);
            let ours = ex
                .triangles()
                .into_iter()
                .map(|t| t.map(|v| p.file_vertex(v)))
                .collect();
            assert_eq!(
                triangle_set(ours),
                triangle_set(whole.triangles()),
                "LoD {lod}"
            );
        }
        // A finer LoD than it holds draws its first; a budget it holds is
        // one under the file's triangles at the LoD before its first.
        assert_eq!(p.model_lod(0), 0);
        let finer = model.triangle_count(first - 1);
        assert_eq!(p.finer_triangles, finer);
        assert!(p.holds_budget(finer - 1) && !p.holds_budget(finer));
        assert_eq!(
            p.lod_for_triangles(finer - 1),
            model.lod_for_triangles(finer - 1)
        );
        assert!(p
            .check_against(&model, &[0, first, model.max_lod()])
            .is_ok());
    }
    // The chunks share a tenth of the triangles in a small part of the
    // file.
    assert!(fine_end * 4 < bytes.len(), "{fine_end} of {}", bytes.len());
}

#[test]
fn chunks_of_a_model_with_properties_keep_them_and_the_texture_once() {
    let mut mesh: Mesh = "grid:40".parse::<Generated>().unwrap().build();
    let n = mesh.vertex_count();
    mesh.properties.uvs = Some(
        mesh.positions
            .iter()
            .map(|p| glam::Vec2::new(p.x, p.y))
            .collect(),
    );
    mesh.properties.normals = Some(vec![glam::Vec3::Z; n]);
    mesh.properties.texture = Some(mts::mesh::Texture::Embedded {
        mime: "image/png".into(),
        // Bytes Zstandard cannot shrink, as a PNG's.
        bytes: (0..5000)
            .scan(0x9e37_79b9_7f4a_7c15u64, |x, _| {
                *x ^= *x << 13;
                *x ^= *x >> 7;
                *x ^= *x << 17;
                Some((*x >> 32) as u8)
            })
            .collect(),
    });
    let model = model_of(&mesh, SimplifyOptions::default());
    let bytes = model.to_streamed_bytes(3, &[0.05, 0.2, 0.5]);
    let path = Path::new(FILE);
    let s = sections(&bytes);
    assert_eq!(&s[2].0, b"PRFX");
    // The texture is in the first chunk only.
    assert!(s[0].2 > 5000 && s[1].2 < 5000 && s[2].2 < 5000, "{s:?}");
    let end = s[2].1 + s[2].2;
    let p = MtsModel::from_prefix(&bytes[..end], path).unwrap();
    assert_eq!(p.first_lod, model.lod_for_ratio(0.5));
    assert_eq!(p.model.properties().texture, model.properties().texture);
    for (i, &v) in (0..p.model.positions().len() as u32)
        .collect::<Vec<_>>()
        .iter()
        .enumerate()
    {
        let w = p.file_vertex(v) as usize;
        assert_eq!(p.model.positions()[i], model.positions()[w]);
        assert_eq!(
            p.model.properties().uvs.as_ref().unwrap()[i],
            model.properties().uvs.as_ref().unwrap()[w]
        );
    }
    let chunks = MtsModel::prefixes_of(&bytes, path).unwrap();
    assert_eq!(chunks.len(), 3);
    for c in &chunks {
        c.check_against(&model, &[c.first_lod, (c.first_lod + model.max_lod()) / 2])
            .unwrap();
    }
}

#[test]
fn a_model_with_seams_streams_with_its_companion_moves() {
    let Some(mesh) = common::model_with_properties("spot.obj") else {
        return;
    };
    let model = model_of(&mesh, SimplifyOptions::default());
    assert!(model.collapses().has_companions());
    let bytes = model.to_streamed_bytes(3, &DEFAULT_PREFIX_SHARES);
    for c in MtsModel::prefixes_of(&bytes, Path::new(FILE)).unwrap() {
        let mid = (c.first_lod + model.max_lod()) / 2;
        c.check_against(&model, &[c.first_lod, mid, model.max_lod()])
            .unwrap();
    }
}

#[test]
fn optimal_placement_and_empty_shares_write_no_chunk() {
    let mesh: Mesh = "icosphere:2k".parse::<Generated>().unwrap().build();
    let optimal = model_of(
        &mesh,
        SimplifyOptions {
            placement: Placement::Optimal,
            ..SimplifyOptions::default()
        },
    );
    // Without chunks, the version-5 file.
    let bytes = optimal.to_streamed_bytes(3, &DEFAULT_PREFIX_SHARES);
    assert_eq!(bytes, optimal.to_compressed_bytes(3));
    assert_eq!(
        MtsModel::from_bytes(&bytes, Path::new(FILE)).unwrap(),
        optimal
    );
    let err = MtsModel::from_prefix(&bytes[..bytes.len() / 2], Path::new(FILE)).unwrap_err();
    assert!(err.to_string().contains("opens only whole"), "{err}");
    let plain = model_of(&mesh, SimplifyOptions::default());
    let bytes = plain.to_streamed_bytes(3, &[]);
    assert_eq!(file_version(&bytes), Some(COMPRESSED_VERSION));
}

#[test]
fn older_versions_open_only_whole() {
    let model = torus();
    for bytes in [model.to_bytes(), model.to_compressed_bytes(3)] {
        let p = MtsModel::from_prefix(&bytes, Path::new(FILE)).unwrap();
        assert!(p.is_whole());
        let err = MtsModel::from_prefix(&bytes[..bytes.len() - 1], Path::new(FILE)).unwrap_err();
        assert!(err.to_string().contains("opens only whole"), "{err}");
    }
    assert_eq!(
        file_version(&model.to_compressed_bytes(3)),
        Some(COMPRESSED_VERSION)
    );
}

/// Rewrites chunk `i`'s payload with `edit` (the whole file sealed again,
/// so the chunk's own checks are reached).
fn with_chunk(bytes: &[u8], i: usize, edit: impl FnOnce(&mut Vec<u8>)) -> Vec<u8> {
    let s = sections(bytes);
    let (_, at, len) = s[i];
    let mut payload = bytes[at..at + len].to_vec();
    edit(&mut payload);
    let mut out = bytes[..at - 8].to_vec();
    out.extend_from_slice(&(payload.len() as u64).to_le_bytes());
    out.extend_from_slice(&payload);
    out.extend_from_slice(&bytes[at + len..]);
    seal(&mut out);
    out
}

fn varint(mut n: u64) -> Vec<u8> {
    let mut out = Vec::new();
    while n >= 0x80 {
        out.push(n as u8 | 0x80);
        n >>= 7;
    }
    out.push(n as u8);
    out
}

/// A stored chunk part holding `data`.
fn stored(data: &[u8]) -> Vec<u8> {
    let mut out = vec![1, 0];
    for n in [data.len(), data.len()] {
        let mut n = n as u64;
        while n >= 0x80 {
            out.push(n as u8 | 0x80);
            n >>= 7;
        }
        out.push(n as u8);
    }
    out.extend_from_slice(data);
    out
}

#[test]
fn corrupt_lying_and_amplifying_chunks_are_refused_with_their_place() {
    let model = torus();
    let bytes = model.to_streamed_bytes(3, &DEFAULT_PREFIX_SHARES);
    let path = Path::new(FILE);
    let s = sections(&bytes);
    let prefix_of = |b: &[u8]| {
        let s = sections(b);
        let end = s[0].1 + s[0].2;
        MtsModel::from_prefix(&b[..end], path)
    };
    // (what, the file, the prefix's error, whether loading the whole file
    // refuses it too: it decodes each chunk and checks its recipe's
    // header, not what the recipe builds).
    let cases: Vec<(&str, Vec<u8>, &str, bool)> = vec![
        (
            "a flipped byte in the frame",
            with_chunk(&bytes, 0, |p| {
                let n = p.len();
                p[n / 2] ^= 0x5a;
            }),
            "PRFX",
            true,
        ),
        (
            "a part announcing a gigabyte",
            with_chunk(&bytes, 0, |p| {
                *p = vec![1, 1, 0x80, 0x80, 0x80, 0x80, 4, 1, 0]
            }),
            "more than 1024",
            true,
        ),
        (
            "a chunk holding a ready file",
            with_chunk(&bytes, 0, |p| {
                let mut data = vec![5, 100, 100, 0, 0];
                data.extend_from_slice(&model.to_bytes());
                *p = stored(&data);
            }),
            "not a recipe",
            true,
        ),
        (
            "more vertex numbers than the recipe's vertices",
            with_chunk(&bytes, 0, |p| {
                let mut data = vec![5];
                data.extend_from_slice(&varint(model.triangle_count(0) as u64));
                data.extend_from_slice(&varint(model.triangle_count(4) as u64));
                data.extend_from_slice(&[0, 3, 0, 0, 0]);
                data.extend_from_slice(&torus().to_recipe_bytes());
                *p = stored(&data);
            }),
            "vertex numbers",
            false,
        ),
        (
            "a recipe larger than the model it says it is a chunk of",
            with_chunk(&bytes, 0, |p| {
                let n = model.positions().len();
                let mut data = vec![5, 1, 1, 0];
                let mut ids = vec![0u8; n];
                let mut m = n as u64;
                let mut count = Vec::new();
                while m >= 0x80 {
                    count.push(m as u8 | 0x80);
                    m >>= 7;
                }
                count.push(m as u8);
                data.extend_from_slice(&count);
                data.append(&mut ids);
                data.extend_from_slice(&model.to_recipe_bytes());
                *p = stored(&data);
            }),
            "for a model of 1",
            true,
        ),
    ];
    for (what, file, expect, whole_refuses) in cases {
        let err = prefix_of(&file).unwrap_err();
        let text = err.to_string();
        assert!(
            text.contains("streamed.mts") && text.contains(expect),
            "{what}: {text}"
        );
        match MtsModel::from_bytes(&file, path) {
            Ok(back) => assert!(!whole_refuses && back == model, "{what}"),
            Err(e) => assert!(
                whole_refuses && e.to_string().contains("PRFX"),
                "{what}: {e}"
            ),
        }
        // And `prefixes_of` (what `mts verify` reads) reports it.
        assert!(MtsModel::prefixes_of(&file, path).is_err(), "{what}");
    }
    // A chunk of another model loads but does not match the file's.
    let other = model_of(
        &"torus:4k".parse::<Generated>().unwrap().build(),
        SimplifyOptions {
            stop_at_triangles: Some(2000),
            ..SimplifyOptions::default()
        },
    );
    let other_bytes = other.to_streamed_bytes(3, &DEFAULT_PREFIX_SHARES);
    let foreign = with_chunk(&bytes, 1, |p| {
        let o = sections(&other_bytes);
        // Its only chunk: 1% and 10% both give its last LoD.
        assert_eq!(&o[1].0, b"META");
        *p = other_bytes[o[0].1..o[0].1 + o[0].2].to_vec();
    });
    let chunks = MtsModel::prefixes_of(&foreign, path).unwrap();
    assert!(chunks[1]
        .check_against(&model, &[0, model.max_lod()])
        .is_err());
    // A header that claims more chunks than there are: the body's META is
    // not a chunk.
    let mut lying = bytes.clone();
    lying[12] += 1;
    seal(&mut lying);
    assert!(MtsModel::from_bytes(&lying, path)
        .unwrap_err()
        .to_string()
        .contains("\"PRFX\""));
    let _ = s;
}
