//! glTF as engines ship it: quantized (`KHR_mesh_quantization`) and
//! compressed with meshoptimizer's codecs (`EXT_meshopt_compression`, its
//! `KHR_` successor). What [`save_gltf_as`] writes reads back with the
//! same triangles and every attribute within its quantization step; files
//! made here with the other filters (exponential, colour) decode; corrupt
//! streams are refused at their buffer view and byte.

mod common;

use glam::{Vec3, Vec4};
use mts::mesh::generate::Generated;
use mts::mesh::io::{order_for_cache, parse_gltf, save_gltf_as, Encoding, Grid};
use mts::mesh::{Mesh, RawMesh};
use mts::{Error, Place};
use serde_json::{json, Value};
use std::path::Path;

/// A torus with normals, texture coordinates and colours, in vertex-cache
/// order (what the writer's callers give it).
fn textured() -> Mesh {
    let mesh = "torus:2k"
        .parse::<Generated>()
        .unwrap()
        .build_with_properties();
    order_for_cache(&mesh)
}

/// A triangle with its corners rotated so that the least comes first:
/// the index codec keeps triangles and their winding, not the corner a
/// triangle starts at.
fn canonical(t: [u32; 3]) -> [u32; 3] {
    let k = (0..3).min_by_key(|&k| t[k]).unwrap();
    [t[k], t[(k + 1) % 3], t[(k + 2) % 3]]
}

/// `raw` is `mesh` within the quantization of `encoding`, whatever order
/// the writer chose for triangles and vertices (the compressed writer
/// reorders both, and merges vertices stored alike): the same triangles,
/// corner by corner on the position grid with their winding; every vertex
/// read back on a grid point within half a step of a source vertex whose
/// normal is within 2°, texture coordinates within half their 12-bit step
/// (4/32,767) and colour within half of 1/255.
fn assert_within_steps(raw: &RawMesh, mesh: &Mesh, encoding: Encoding) {
    let grid = Grid::covering(&mesh.positions);
    let cell = |p: Vec3| {
        ((p - grid.origin) / grid.step)
            .round()
            .as_ivec3()
            .to_array()
    };
    let corners = |positions: &[Vec3], t: &[u32; 3]| {
        let k = t.map(|v| cell(positions[v as usize]));
        let first = (0..3).min_by_key(|&i| k[i]).unwrap();
        [k[first], k[(first + 1) % 3], k[(first + 2) % 3]]
    };
    let mut ours: Vec<_> = mesh
        .triangles
        .iter()
        .map(|t| corners(&mesh.positions, t))
        .collect();
    let mut theirs: Vec<_> = raw
        .triangles
        .iter()
        .map(|t| corners(&raw.positions, t))
        .collect();
    ours.sort_unstable();
    theirs.sort_unstable();
    assert_eq!(ours, theirs, "{encoding:?}");
    let mut at: std::collections::HashMap<[i32; 3], Vec<usize>> = Default::default();
    for (v, p) in mesh.positions.iter().enumerate() {
        at.entry(cell(*p)).or_default().push(v);
    }
    let (p, q) = (&raw.properties, &mesh.properties);
    let slack = grid.step * 0.5 + 1e-6 * grid.origin.abs().max_element().max(1.0);
    for (v, position) in raw.positions.iter().enumerate() {
        let sources = &at[&cell(*position)];
        let matches = |s: usize| {
            let n = p.normals.as_ref().unwrap()[v].normalize();
            let m = q.normals.as_ref().unwrap()[s].normalize();
            let t = p.uvs.as_ref().unwrap()[v] - q.uvs.as_ref().unwrap()[s];
            let c = p.colors.as_ref().unwrap()[v] - q.colors.as_ref().unwrap()[s];
            (*position - mesh.positions[s]).abs().max_element() <= slack
                && n.dot(m) >= 2f32.to_radians().cos()
                && t.abs().max_element() <= 4.0 / 32767.0 + 1e-6
                && c.abs().max_element() <= 0.5 / 255.0 + 1e-6
        };
        assert!(
            sources.iter().any(|&s| matches(s)),
            "{encoding:?}: vertex {v} at {position} matches none of {sources:?}"
        );
    }
}

#[test]
fn quantized_and_compressed_files_read_back_within_their_steps() {
    let dir = common::scratch("gltf_compressed", "round_trip");
    let mesh = textured();
    let plain = dir.join("plain.glb");
    save_gltf_as(&mesh, &plain, Encoding::Plain).unwrap();
    let plain_bytes = std::fs::metadata(&plain).unwrap().len();
    let mut sizes = Vec::new();
    for encoding in [Encoding::Quantized, Encoding::Compressed] {
        for name in ["m.glb", "m.gltf"] {
            let path = dir.join(name);
            save_gltf_as(&mesh, &path, encoding).unwrap();
            let bytes = std::fs::read(&path).unwrap();
            if name.ends_with("glb") {
                // The gltf crate's validation refuses any required
                // extension it does not implement; its structure check
                // holds (the Khronos validator is run outside the tests).
                gltf::Gltf::from_slice_without_validation(&bytes).expect("a glTF document");
                sizes.push(bytes.len() as u64);
            }
            let raw = parse_gltf(&bytes, &path).unwrap();
            assert_within_steps(&raw, &mesh, encoding);
            let text = if name.ends_with("glb") {
                let n = u32::from_le_bytes(bytes[12..16].try_into().unwrap()) as usize;
                bytes[20..20 + n].to_vec()
            } else {
                bytes
            };
            let document: Value = serde_json::from_slice(&text).unwrap();
            let required = &document["extensionsRequired"];
            assert!(required.to_string().contains("KHR_mesh_quantization"));
            assert_eq!(
                required.to_string().contains("EXT_meshopt_compression"),
                encoding == Encoding::Compressed
            );
        }
    }
    // Quantizing shrinks the file, compressing shrinks it again.
    assert!(sizes[0] < plain_bytes * 6 / 10, "{sizes:?} {plain_bytes}");
    assert!(sizes[1] < sizes[0] * 3 / 4, "{sizes:?}");
}

/// The JSON chunk of a `.glb` and the file offset of its BIN chunk's data.
fn split(file: &[u8]) -> (Value, usize) {
    let n = u32::from_le_bytes(file[12..16].try_into().unwrap()) as usize;
    (
        serde_json::from_slice(&file[20..20 + n]).unwrap(),
        20 + n + 8,
    )
}

/// `file` with its JSON chunk replaced by `document` (padded; the BIN
/// chunk kept).
fn with_json(file: &[u8], document: &Value) -> Vec<u8> {
    let n = u32::from_le_bytes(file[12..16].try_into().unwrap()) as usize;
    let mut text = serde_json::to_vec(document).unwrap();
    text.resize(text.len().next_multiple_of(4), b' ');
    let rest = &file[20 + n..];
    let mut out = b"glTF".to_vec();
    out.extend(2u32.to_le_bytes());
    out.extend(((12 + 8 + text.len() + rest.len()) as u32).to_le_bytes());
    out.extend((text.len() as u32).to_le_bytes());
    out.extend(b"JSON");
    out.extend(&text);
    out.extend(rest);
    out
}

fn parse_failure(bytes: &[u8]) -> (Place, String) {
    match parse_gltf(bytes, Path::new("c.glb")) {
        Err(Error::Parse { place, message, .. }) => (place, message),
        other => panic!("expected a parse error, got {other:?}"),
    }
}

#[test]
fn corrupt_streams_are_refused_at_their_view_and_byte() {
    let dir = common::scratch("gltf_compressed", "corrupt");
    let path = dir.join("c.glb");
    save_gltf_as(&textured(), &path, Encoding::Compressed).unwrap();
    let file = std::fs::read(&path).unwrap();
    let (document, bin_at) = split(&file);
    // View 1 holds the positions (view 0 the triangles).
    let ext = &document["bufferViews"][1]["extensions"]["EXT_meshopt_compression"];
    let offset = ext["byteOffset"].as_u64().unwrap() as usize;
    // The place of compressed byte `v` in `file` (whose JSON chunk may
    // have another length than the original's).
    let at = |file: &[u8], v: u64| Place {
        byte: Some(split(file).1 as u64 + v),
        ..Place::element("bufferView", 1)
    };

    let mut broken = file.clone();
    broken[bin_at + offset] = 0x00;
    let (place, message) = parse_failure(&broken);
    assert_eq!(place, at(&broken, offset as u64));
    assert!(message.contains("header byte (0x00)"), "{message}");

    // A stream cut short.
    let mut doc = document.clone();
    let length = ext["byteLength"].as_u64().unwrap();
    doc["bufferViews"][1]["extensions"]["EXT_meshopt_compression"]["byteLength"] =
        json!(length / 2);
    let changed = with_json(&file, &doc);
    let (place, message) = parse_failure(&changed);
    assert_eq!(place, at(&changed, offset as u64));
    assert!(message.contains("ends early"), "{message}");

    // A count that no stream of these bytes holds: refused before any
    // allocation, by the expansion bound.
    let mut doc = document.clone();
    let count = 1u64 << 40;
    doc["bufferViews"][1]["byteLength"] = json!(count * 8);
    doc["bufferViews"][1]["extensions"]["EXT_meshopt_compression"]["count"] = json!(count);
    doc["accessors"][1]["count"] = json!(count);
    let changed = with_json(&file, &doc);
    let (place, message) = parse_failure(&changed);
    assert_eq!(place, at(&changed, offset as u64));
    assert!(
        message.contains("which no valid stream expands to"),
        "{message}"
    );

    // The extension's rules, at the view, before any byte is read.
    let mut doc = document.clone();
    doc["bufferViews"][1]["byteLength"] = json!(12);
    let (place, message) = parse_failure(&with_json(&file, &doc));
    assert_eq!(place, Place::element("bufferView", 1));
    assert!(
        message.contains("is not the view's byteLength 12"),
        "{message}"
    );

    // Compressed bytes past their buffer.
    let mut doc = document;
    doc["bufferViews"][1]["extensions"]["EXT_meshopt_compression"]["byteOffset"] =
        json!(1u64 << 40);
    let (place, message) = parse_failure(&with_json(&file, &doc));
    assert_eq!(place, Place::element("bufferView", 1));
    assert!(message.contains("lie beyond buffer 0"), "{message}");

    // Every single-byte corruption of the streams: an error or a mesh,
    // never a panic.
    for k in (bin_at..file.len()).step_by(97) {
        let mut broken = file.clone();
        broken[k] ^= 0x5a;
        let _ = parse_gltf(&broken, Path::new("c.glb"));
    }
}

/// A `.glb` built here with `KHR_meshopt_compression`: float positions
/// through the exponential filter, colours through the colour filter (the
/// `KHR_` extension's), triangles through the index codec; buffer 1 a
/// fallback without data.
#[test]
fn exponential_and_colour_filters_decode() {
    let positions: Vec<[f32; 3]> = vec![[0.0, 0.0, 0.0], [1.5, 0.0, -2.0], [0.0, 3.25, 0.5]];
    let colors: Vec<[f32; 4]> = vec![
        [1.0, 0.0, 0.0, 1.0],
        [0.0, 1.0, 0.0, 0.5],
        [0.2, 0.4, 0.6, 1.0],
    ];
    let exp = meshopt::encode_filter_exp::<3>(&positions, 23, meshopt::EncodeExpMode::Separate);
    let col: Vec<[u8; 4]> = meshopt::encode_filter_color::<u8>(&colors, 8);
    let streams = [
        meshopt::encode_vertex_buffer(&exp).unwrap(),
        meshopt::encode_vertex_buffer(&col).unwrap(),
        meshopt::encode_index_buffer(&[0, 1, 2], 3).unwrap(),
    ];
    let mut bin = Vec::new();
    let mut offsets = Vec::new();
    for s in &streams {
        bin.resize(bin.len().next_multiple_of(4), 0);
        offsets.push(bin.len());
        bin.extend_from_slice(s);
    }
    bin.resize(bin.len().next_multiple_of(4), 0);
    let ext = |k: usize, stride: usize, count: usize, mode: &str, filter: &str| {
        json!({ "KHR_meshopt_compression": { "buffer": 0, "byteOffset": offsets[k],
            "byteLength": streams[k].len(), "byteStride": stride, "count": count,
            "mode": mode, "filter": filter } })
    };
    let document = json!({
        "asset": { "version": "2.0" },
        "extensionsUsed": ["KHR_meshopt_compression"],
        "extensionsRequired": ["KHR_meshopt_compression"],
        "buffers": [{ "byteLength": bin.len() }, { "byteLength": 64 }],
        "bufferViews": [
            { "buffer": 1, "byteOffset": 0, "byteLength": 36, "byteStride": 12,
              "extensions": ext(0, 12, 3, "ATTRIBUTES", "EXPONENTIAL") },
            { "buffer": 1, "byteOffset": 36, "byteLength": 12, "byteStride": 4,
              "extensions": ext(1, 4, 3, "ATTRIBUTES", "COLOR") },
            { "buffer": 1, "byteOffset": 48, "byteLength": 12,
              "extensions": ext(2, 4, 3, "TRIANGLES", "NONE") },
        ],
        "accessors": [
            { "bufferView": 0, "componentType": 5126, "type": "VEC3", "count": 3,
              "min": [0, 0, -2], "max": [1.5, 3.25, 0.5] },
            { "bufferView": 1, "componentType": 5121, "normalized": true, "type": "VEC4", "count": 3 },
            { "bufferView": 2, "componentType": 5125, "type": "SCALAR", "count": 3 },
        ],
        "meshes": [{ "primitives": [{ "attributes": { "POSITION": 0, "COLOR_0": 1 }, "indices": 2 }] }],
    });
    let mut text = serde_json::to_vec(&document).unwrap();
    text.resize(text.len().next_multiple_of(4), b' ');
    let mut file = b"glTF".to_vec();
    file.extend(2u32.to_le_bytes());
    file.extend(((12 + 8 + text.len() + 8 + bin.len()) as u32).to_le_bytes());
    file.extend((text.len() as u32).to_le_bytes());
    file.extend(b"JSON");
    file.extend(&text);
    file.extend((bin.len() as u32).to_le_bytes());
    file.extend(b"BIN\0");
    file.extend(&bin);
    let raw = parse_gltf(&file, Path::new("k.glb")).unwrap();
    assert_eq!(canonical(raw.triangles[0]), [0, 1, 2]);
    for (a, b) in raw.positions.iter().zip(&positions) {
        assert_eq!(*a, Vec3::from_array(*b));
    }
    for (a, b) in raw.properties.colors.unwrap().iter().zip(&colors) {
        assert!(
            (*a - Vec4::from_array(*b)).abs().max_element() <= 2.0 / 255.0,
            "{a} {b:?}"
        );
    }
    // EXT_ does not know the colour filter.
    let renamed = String::from_utf8(text.clone())
        .unwrap()
        .replace("KHR_meshopt_compression", "EXT_meshopt_compression");
    let (place, message) = match parse_gltf(
        &with_json(&file, &serde_json::from_str(&renamed).unwrap()),
        Path::new("k.glb"),
    ) {
        Err(Error::Parse { place, message, .. }) => (place, message),
        other => panic!("expected a parse error, got {other:?}"),
    };
    assert_eq!(place, Place::element("bufferView", 1));
    assert!(message.contains("`filter` is \"COLOR\""), "{message}");
}
