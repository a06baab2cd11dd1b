//! glTF 2.0 in and out: round trips of a mesh with every property through
//! `.glb` and `.gltf`, hand-made assets (node transforms, a mirror, strips
//! and fans, skipped points, neutral fills, material factors), and every
//! error the reader promises a place for, matched by variant and place.
//! The shared models hold no glTF, so every asset is made here.

mod common;

use glam::{Vec2, Vec3, Vec4};
use mts::mesh::generate::torus;
use mts::mesh::io::{load, parse_gltf, parse_gltf_with, save_gltf, Format, LoadOptions};
use mts::mesh::{Mesh, RawMesh, Texture};
use mts::{Error, Place};
use serde_json::{json, Value};
use std::path::Path;

/// A torus with unit normals, texture coordinates on a 1/4096 grid (the
/// `v` flip is exact there), colours in 0..=1 and `texture`.
fn textured_torus(major: u32, minor: u32, texture: Option<Texture>) -> Mesh {
    let mut mesh = torus(major, minor);
    let n = mesh.positions.len();
    mesh.properties.normals = Some(mesh.positions.iter().map(|p| p.normalize()).collect());
    mesh.properties.uvs = Some(
        (0..n)
            .map(|i| Vec2::new((i % 4096) as f32, (i * 7 % 4097) as f32) / 4096.0)
            .collect(),
    );
    mesh.properties.colors = Some(
        mesh.positions
            .iter()
            .map(|p| Vec4::new(p.x * 0.3 + 0.5, p.y * 0.3 + 0.5, 0.25, 1.0 - p.z.abs()))
            .collect(),
    );
    mesh.properties.texture = texture;
    mesh.validate().unwrap();
    mesh
}

fn bits3(v: &[Vec3]) -> Vec<[u32; 3]> {
    v.iter().map(|p| p.to_array().map(f32::to_bits)).collect()
}

/// `raw` holds exactly `mesh`'s vertices, triangles and properties, bit
/// for bit.
fn assert_same(raw: &RawMesh, mesh: &Mesh) {
    assert_eq!(bits3(&raw.positions), bits3(&mesh.positions));
    assert_eq!(raw.triangles, mesh.triangles);
    let (a, b) = (&raw.properties, &mesh.properties);
    assert_eq!(
        a.normals.as_deref().map(bits3),
        b.normals.as_deref().map(bits3)
    );
    let uv_bits = |u: &[Vec2]| -> Vec<[u32; 2]> {
        u.iter().map(|t| t.to_array().map(f32::to_bits)).collect()
    };
    assert_eq!(a.uvs.as_deref().map(uv_bits), b.uvs.as_deref().map(uv_bits));
    let colour_bits = |c: &[Vec4]| -> Vec<[u32; 4]> {
        c.iter().map(|t| t.to_array().map(f32::to_bits)).collect()
    };
    assert_eq!(
        a.colors.as_deref().map(colour_bits),
        b.colors.as_deref().map(colour_bits)
    );
    assert!(a.position_ids.is_empty());
}

/// Reads `path` back: the raw mesh, after the `gltf` crate's full
/// validation accepted the file as glTF 2.0.
fn read_back(path: &Path) -> RawMesh {
    let bytes = std::fs::read(path).unwrap();
    if path.extension().unwrap() == "glb" {
        gltf::Gltf::from_slice(&bytes).expect("the gltf crate accepts the file");
    }
    parse_gltf(&bytes, path).unwrap()
}

#[test]
fn glb_round_trip_keeps_every_property_to_the_bit() {
    let dir = common::scratch("gltf", "glb_round_trip");
    let texture = Texture::Embedded {
        mime: "image/png".into(),
        bytes: common::PNG.to_vec(),
    };
    let mesh = textured_torus(24, 12, Some(texture.clone()));
    let path = dir.join("torus.glb");
    save_gltf(&mesh, &path).unwrap();
    let raw = read_back(&path);
    assert_same(&raw, &mesh);
    assert_eq!(raw.properties.texture, Some(texture));
    let (loaded, report) = load(&path, LoadOptions::default()).unwrap();
    assert_eq!(loaded.vertex_count(), 24 * 12);
    assert_eq!(loaded.triangle_count(), 2 * 24 * 12);
    assert_eq!(report.degenerate_dropped, 0);
}

#[test]
fn gltf_round_trip_keeps_every_property_and_the_texture_file() {
    let dir = common::scratch("gltf", "gltf_round_trip");
    std::fs::write(dir.join("skin.png"), common::PNG).unwrap();
    let texture = Texture::File(dir.join("skin.png"));
    let mesh = textured_torus(24, 12, Some(texture.clone()));
    let path = dir.join("torus.gltf");
    save_gltf(&mesh, &path).unwrap();
    assert!(dir.join("torus.bin").is_file());
    let document: Value = serde_json::from_slice(&std::fs::read(&path).unwrap()).unwrap();
    assert_eq!(document["images"][0]["uri"], "skin.png");
    assert_eq!(document["buffers"][0]["uri"], "torus.bin");
    gltf::Gltf::from_slice(&std::fs::read(&path).unwrap()).expect("valid glTF");
    let raw = read_back(&path);
    assert_same(&raw, &mesh);
    assert_eq!(raw.properties.texture, Some(texture));

    // An embedded image stays embedded in the .gltf's buffer.
    let embedded = Texture::Embedded {
        mime: String::new(),
        bytes: common::PNG.to_vec(),
    };
    let mesh = textured_torus(5, 4, Some(embedded));
    save_gltf(&mesh, &path).unwrap();
    assert_eq!(
        read_back(&path).properties.texture,
        Some(Texture::Embedded {
            mime: "image/png".into(),
            bytes: common::PNG.to_vec()
        })
    );
}

/// A texture file goes into a `.glb` as bytes; a `.gltf` in another folder
/// refers to it by a relative path.
#[test]
fn texture_files_are_embedded_in_glb_and_referred_to_from_gltf() {
    let dir = common::scratch("gltf", "texture_files");
    std::fs::create_dir_all(dir.join("images")).unwrap();
    std::fs::create_dir_all(dir.join("out")).unwrap();
    let png = dir.join("images/a b.png");
    std::fs::write(&png, common::PNG).unwrap();
    let mesh = textured_torus(6, 5, Some(Texture::File(png.clone())));
    save_gltf(&mesh, &dir.join("out/t.glb")).unwrap();
    assert_eq!(
        read_back(&dir.join("out/t.glb")).properties.texture,
        Some(Texture::Embedded {
            mime: "image/png".into(),
            bytes: common::PNG.to_vec()
        })
    );
    save_gltf(&mesh, &dir.join("out/t.gltf")).unwrap();
    let document: Value =
        serde_json::from_slice(&std::fs::read(dir.join("out/t.gltf")).unwrap()).unwrap();
    assert_eq!(document["images"][0]["uri"], "../images/a%20b.png");
    assert_eq!(
        read_back(&dir.join("out/t.gltf")).properties.texture,
        Some(Texture::File(dir.join("out/../images/a b.png")))
    );
}

/// More than 65535 vertices: u32 indices; a mesh of positions only has no
/// other attribute and no material.
#[test]
fn large_mesh_round_trips_with_u32_indices() {
    let dir = common::scratch("gltf", "large");
    let mesh = torus(300, 250);
    let path = dir.join("big.glb");
    save_gltf(&mesh, &path).unwrap();
    let raw = read_back(&path);
    assert_same(&raw, &mesh);
    assert!(raw.properties.is_empty() && raw.properties.texture.is_none());
    let document = gltf::Gltf::from_slice(&std::fs::read(&path).unwrap()).unwrap();
    let indices = document.accessors().next().unwrap();
    assert_eq!(indices.data_type(), gltf::accessor::DataType::U32);
    assert_eq!(document.materials().count(), 0);
}

/// The `v` flip `1 - v` rounds where `v` has bits below 2^-24: within half
/// an ulp of 1.0.
#[test]
fn arbitrary_texture_coordinates_come_back_within_half_an_ulp_of_one() {
    let dir = common::scratch("gltf", "uv_rounding");
    let mut mesh = torus(7, 5);
    let uvs: Vec<Vec2> = (0..mesh.positions.len())
        .map(|i| Vec2::splat(0.1 + i as f32 * 1e-3))
        .collect();
    mesh.properties.uvs = Some(uvs.clone());
    let path = dir.join("uv.glb");
    save_gltf(&mesh, &path).unwrap();
    let back = read_back(&path).properties.uvs.unwrap();
    for (a, b) in back.iter().zip(&uvs) {
        assert_eq!(a.x.to_bits(), b.x.to_bits());
        assert!((a.y - b.y).abs() <= 2f32.powi(-25), "{} vs {}", a.y, b.y);
    }
}

#[test]
fn format_detection_knows_gltf_by_extension_and_glb_by_magic() {
    assert_eq!(
        Format::detect(Path::new("a.GLTF"), b"{").unwrap(),
        Format::Gltf
    );
    assert_eq!(
        Format::detect(Path::new("a.glb"), b"").unwrap(),
        Format::Gltf
    );
    assert_eq!(
        Format::detect(Path::new("noext"), b"glTF\x02\0\0\0").unwrap(),
        Format::Gltf
    );
}

// ---------------------------------------------------------------------
// Hand-made assets.

/// A buffer being built; each `put` returns the (offset, length) of what it
/// appended, 4-byte aligned.
#[derive(Default)]
struct Bin(Vec<u8>);

impl Bin {
    fn put(&mut self, bytes: &[u8]) -> (usize, usize) {
        self.0.resize(self.0.len().next_multiple_of(4), 0);
        let at = self.0.len();
        self.0.extend_from_slice(bytes);
        (at, bytes.len())
    }
    fn f32s(&mut self, values: &[f32]) -> (usize, usize) {
        let bytes: Vec<u8> = values.iter().flat_map(|x| x.to_le_bytes()).collect();
        self.put(&bytes)
    }
    fn u16s(&mut self, values: &[u16]) -> (usize, usize) {
        let bytes: Vec<u8> = values.iter().flat_map(|x| x.to_le_bytes()).collect();
        self.put(&bytes)
    }
}

/// A buffer view over `(offset, length)` of buffer 0.
fn view((offset, length): (usize, usize)) -> Value {
    json!({ "buffer": 0, "byteOffset": offset, "byteLength": length })
}

/// An accessor over view `view` of `count` elements.
fn accessor(view: usize, component: u32, ty: &str, count: usize) -> Value {
    json!({ "bufferView": view, "componentType": component, "type": ty, "count": count })
}

const FLOAT: u32 = 5126;
const UBYTE: u32 = 5121;
const USHORT: u32 = 5123;

/// `body` as a `.gltf` whose buffer 0 is `bin` as a data URI.
fn gltf_text(bin: &Bin, mut body: Value) -> Vec<u8> {
    body["asset"] = json!({ "version": "2.0" });
    body["buffers"] = json!([{
        "byteLength": bin.0.len(),
        "uri": format!("data:application/octet-stream;base64,{}", common::base64(&bin.0)),
    }]);
    serde_json::to_vec(&body).unwrap()
}

/// `body` as a `.glb` whose BIN chunk is `bin`, and the file offset of the
/// BIN chunk's data.
fn glb(bin: &Bin, mut body: Value) -> (Vec<u8>, u64) {
    body["asset"] = json!({ "version": "2.0" });
    body["buffers"] = json!([{ "byteLength": bin.0.len() }]);
    let mut text = serde_json::to_vec(&body).unwrap();
    text.resize(text.len().next_multiple_of(4), b' ');
    let mut data = bin.0.clone();
    data.resize(data.len().next_multiple_of(4), 0);
    let total = 12 + 8 + text.len() + 8 + data.len();
    let mut out = b"glTF".to_vec();
    out.extend(2u32.to_le_bytes());
    out.extend((total as u32).to_le_bytes());
    out.extend((text.len() as u32).to_le_bytes());
    out.extend(b"JSON");
    out.extend(&text);
    out.extend((data.len() as u32).to_le_bytes());
    out.extend(b"BIN\0");
    let bin_at = out.len() as u64;
    out.extend(&data);
    (out, bin_at)
}

//  2
//  | \      one triangle, counter-clockwise seen from +z, normals
//  0 - 1    (0.6, 0, 0.8), indices u16.
fn triangle_asset(bin: &mut Bin) -> Value {
    let p = bin.f32s(&[0., 0., 0., 1., 0., 0., 0., 1., 0.]);
    let n = bin.f32s(&[0.6, 0., 0.8, 0.6, 0., 0.8, 0.6, 0., 0.8]);
    let i = bin.u16s(&[0, 1, 2]);
    json!({
        "bufferViews": [view(p), view(n), view(i)],
        "accessors": [
            accessor(0, FLOAT, "VEC3", 3),
            accessor(1, FLOAT, "VEC3", 3),
            accessor(2, USHORT, "SCALAR", 3),
        ],
        "meshes": [{ "primitives": [{ "attributes": { "POSITION": 0, "NORMAL": 1 }, "indices": 2 }] }],
    })
}

/// The default scene (1, not 0) places the triangle under a matrix (scale
/// 2, then x + 10) and under a mirror `x -> -x` above a translation
/// `z + 5`: positions moved, the mirrored copy's winding flipped and its
/// normals mirrored. Scene 0's node is not read.
#[test]
fn node_transforms_move_positions_and_mirrors_flip_winding() {
    let mut bin = Bin::default();
    let mut body = triangle_asset(&mut bin);
    body["nodes"] = json!([
        { "matrix": [2, 0, 0, 0, 0, 2, 0, 0, 0, 0, 2, 0, 10, 0, 0, 1], "mesh": 0 },
        { "scale": [-1, 1, 1], "children": [2] },
        { "translation": [0, 0, 5], "mesh": 0 },
        { "translation": [100, 0, 0], "mesh": 0 },
    ]);
    body["scenes"] = json!([{ "nodes": [3] }, { "nodes": [0, 1] }]);
    body["scene"] = json!(1);
    let raw = parse_gltf(&gltf_text(&bin, body), Path::new("t.gltf")).unwrap();
    let v = Vec3::new;
    assert_eq!(
        raw.positions,
        [
            v(10., 0., 0.),
            v(12., 0., 0.),
            v(10., 2., 0.),
            v(0., 0., 5.),
            v(-1., 0., 5.),
            v(0., 1., 5.)
        ]
    );
    assert_eq!(raw.triangles, [[0, 1, 2], [3, 5, 4]]);
    let normals = raw.properties.normals.unwrap();
    let expected = [v(0.6, 0., 0.8); 3]
        .into_iter()
        .chain([v(-0.6, 0., 0.8); 3]);
    for (n, e) in normals.iter().zip(expected) {
        assert!((*n - e).length() < 1e-6, "{n} vs {e}");
    }
}

/// Without scenes every root node is read; without nodes every mesh.
#[test]
fn without_a_scene_root_nodes_then_meshes_are_read() {
    let mut bin = Bin::default();
    let mut body = triangle_asset(&mut bin);
    let raw = parse_gltf(&gltf_text(&bin, body.clone()), Path::new("t.gltf")).unwrap();
    assert_eq!(raw.triangles, [[0, 1, 2]]);
    body["nodes"] = json!([
        { "children": [1], "translation": [0, 0, 1] },
        { "mesh": 0 },
        { "mesh": 0 },
    ]);
    let raw = parse_gltf(&gltf_text(&bin, body), Path::new("t.gltf")).unwrap();
    assert_eq!(raw.triangles, [[0, 1, 2], [3, 4, 5]]);
    assert_eq!(raw.positions[0], Vec3::new(0., 0., 1.));
    assert_eq!(raw.positions[3], Vec3::ZERO);
}

//  1   3          a strip (u8 indices 0 1 2 3 3 4: two triangles, then two
//  | \ | \        degenerate joins), a fan over five unindexed vertices, a
//  0 - 2 - 4      points and a lines primitive (skipped).
#[test]
fn strips_and_fans_become_triangles_and_points_are_skipped() {
    let mut bin = Bin::default();
    let p = bin.f32s(&[0., 0., 0., 0., 1., 0., 1., 0., 0., 1., 1., 0., 2., 0., 0.]);
    let i = bin.put(&[0, 1, 2, 3, 3, 4]);
    let body = json!({
        "bufferViews": [view(p), view(i)],
        "accessors": [accessor(0, FLOAT, "VEC3", 5), accessor(1, UBYTE, "SCALAR", 6)],
        "meshes": [{ "name": "parts", "primitives": [
            { "attributes": { "POSITION": 0 }, "indices": 1, "mode": 5 },
            { "attributes": { "POSITION": 0 }, "mode": 0 },
            { "attributes": { "POSITION": 0 }, "mode": 6 },
            { "attributes": { "POSITION": 0 }, "indices": 1, "mode": 1 },
        ] }],
    });
    let raw = parse_gltf(&gltf_text(&bin, body), Path::new("t.gltf")).unwrap();
    assert_eq!(raw.positions.len(), 10);
    assert_eq!(
        raw.triangles,
        [[0, 1, 2], [1, 3, 2], [6, 7, 5], [7, 8, 5], [8, 9, 5]]
    );
    assert_eq!(raw.degenerate_in_source, 2);
}

/// A primitive without normals or colours gets zero normals and its
/// material's base-colour factor as colour; one with `COLOR_0` as
/// normalised u8 vec3 gets alpha 1; no primitive has texture coordinates,
/// so there is no UV stream.
#[test]
fn missing_attributes_are_filled_with_neutral_values() {
    let mut bin = Bin::default();
    let p = bin.f32s(&[0., 0., 0., 1., 0., 0., 0., 1., 0.]);
    let n = bin.f32s(&[0., 0., 1., 0., 0., 1., 0., 0., 1.]);
    let c = bin.put(&[255, 0, 51, 0, 0, 255, 0, 0, 0, 0, 255]);
    let mut colors = accessor(2, UBYTE, "VEC3", 3);
    colors["normalized"] = json!(true);
    let body = json!({
        "bufferViews": [view(p), view(n), { "buffer": 0, "byteOffset": c.0, "byteLength": 11, "byteStride": 4 }],
        "accessors": [accessor(0, FLOAT, "VEC3", 3), accessor(1, FLOAT, "VEC3", 3), colors],
        "materials": [{ "pbrMetallicRoughness": { "baseColorFactor": [0.5, 0.25, 1, 1] } }],
        "meshes": [{ "primitives": [
            { "attributes": { "POSITION": 0 }, "material": 0 },
            { "attributes": { "POSITION": 0, "NORMAL": 1, "COLOR_0": 2 } },
        ] }],
    });
    let raw = parse_gltf(&gltf_text(&bin, body), Path::new("t.gltf")).unwrap();
    let properties = raw.properties;
    assert_eq!(
        properties.normals.unwrap(),
        [[Vec3::ZERO; 3], [Vec3::Z; 3]].concat()
    );
    assert!(properties.uvs.is_none());
    let factor = Vec4::new(0.5, 0.25, 1.0, 1.0);
    let byte = |x: u8| f32::from(x) / 255.0;
    assert_eq!(
        properties.colors.unwrap(),
        [
            factor,
            factor,
            factor,
            Vec4::new(1.0, 0.0, byte(51), 1.0),
            Vec4::new(0.0, 1.0, 0.0, 1.0),
            Vec4::new(0.0, 0.0, 1.0, 1.0),
        ]
    );
}

/// An external buffer is read relative to the `.gltf`'s folder; a missing
/// one is an I/O error naming that file.
#[test]
fn external_buffers_are_read_beside_the_file() {
    let dir = common::scratch("gltf", "external");
    let mut bin = Bin::default();
    let mut body = triangle_asset(&mut bin);
    body["asset"] = json!({ "version": "2.0" });
    body["buffers"] = json!([{ "byteLength": bin.0.len(), "uri": "data%20file.bin" }]);
    let path = dir.join("t.gltf");
    std::fs::write(&path, serde_json::to_vec(&body).unwrap()).unwrap();
    match load(&path, LoadOptions::default()).unwrap_err() {
        Error::Io { file, .. } => assert_eq!(file, dir.join("data file.bin")),
        other => panic!("expected an I/O error, got {other:?}"),
    }
    std::fs::write(dir.join("data file.bin"), &bin.0).unwrap();
    let (mesh, _) = load(&path, LoadOptions::default()).unwrap();
    assert_eq!(mesh.triangles, [[0, 1, 2]]);
}

// ---------------------------------------------------------------------
// Errors, matched by variant and place.

fn parse_error(bytes: &[u8], name: &str) -> Place {
    match parse_gltf(bytes, Path::new(name)) {
        Err(Error::Parse { file, place, .. }) => {
            assert_eq!(file, Path::new(name));
            place
        }
        Err(e) => panic!("not a parse error: {e}"),
        Ok(raw) => panic!("expected an error, got {} triangles", raw.triangles.len()),
    }
}

fn at(element: &str, index: u64, byte: Option<u64>) -> Place {
    Place {
        byte,
        ..Place::element(element, index)
    }
}

#[test]
fn accessor_beyond_its_buffer_view_is_refused_with_its_byte() {
    let mut bin = Bin::default();
    let mut body = triangle_asset(&mut bin);
    body["accessors"][1]["count"] = json!(4);
    body["accessors"][1]["byteOffset"] = json!(0);
    // In a .gltf the data is in a data URI: no byte of the file.
    assert_eq!(
        parse_error(&gltf_text(&bin, body.clone()), "t.gltf"),
        at("accessor", 1, None)
    );
    // In a .glb: the byte where the accessor starts (view 1 is at 36).
    let (file, bin_at) = glb(&bin, body.clone());
    assert_eq!(
        parse_error(&file, "t.glb"),
        at("accessor", 1, Some(bin_at + 36))
    );
    // A view past its buffer's byteLength.
    body["accessors"][1]["count"] = json!(3);
    body["bufferViews"][1]["byteLength"] = json!(1000);
    assert_eq!(
        parse_error(&gltf_text(&bin, body.clone()), "t.gltf"),
        at("bufferView", 1, None)
    );
    // A count whose byte size overflows.
    body["bufferViews"][1]["byteLength"] = json!(36);
    body["accessors"][1]["count"] = json!(u64::MAX / 2);
    let (file, bin_at) = glb(&bin, body);
    assert_eq!(
        parse_error(&file, "t.glb"),
        at("accessor", 1, Some(bin_at + 36))
    );
}

#[test]
fn index_out_of_range_is_refused_with_its_byte() {
    let mut bin = Bin::default();
    let p = bin.f32s(&[0., 0., 0., 1., 0., 0., 0., 1., 0.]);
    let i = bin.u16s(&[0, 1, 2, 2, 1, 3]);
    let body = json!({
        "bufferViews": [view(p), view(i)],
        "accessors": [accessor(0, FLOAT, "VEC3", 3), accessor(1, USHORT, "SCALAR", 6)],
        "meshes": [{ "primitives": [{ "attributes": { "POSITION": 0 }, "indices": 1 }] }],
    });
    let (file, bin_at) = glb(&bin, body);
    assert_eq!(
        parse_error(&file, "t.glb"),
        at("accessor", 1, Some(bin_at + i.0 as u64 + 10))
    );
}

#[test]
fn nan_position_is_refused_with_its_byte() {
    let mut bin = Bin::default();
    let mut body = triangle_asset(&mut bin);
    bin.0[12..16].copy_from_slice(&f32::NAN.to_le_bytes());
    let (file, bin_at) = glb(&bin, body.clone());
    assert_eq!(
        parse_error(&file, "t.glb"),
        at("accessor", 0, Some(bin_at + 12))
    );
    // So is a position a transform sends to infinity.
    bin.0[12..16].copy_from_slice(&3e38f32.to_le_bytes());
    body["nodes"] = json!([{ "scale": [10, 1, 1], "mesh": 0 }]);
    assert_eq!(
        parse_error(&glb(&bin, body).0, "t.glb"),
        Place::element("mesh 0 primitive", 0)
    );
}

#[test]
fn truncated_glb_is_refused_at_the_chunk() {
    let mut bin = Bin::default();
    let body = triangle_asset(&mut bin);
    let (file, bin_at) = glb(&bin, body);
    let bin_header = bin_at - 8;
    assert_eq!(
        parse_error(&file[..file.len() - 4], "t.glb"),
        at("GLB chunk", 1, Some(bin_header))
    );
    assert_eq!(
        parse_error(&file[..bin_header as usize + 3], "t.glb"),
        at("GLB chunk", 1, Some(bin_header))
    );
    // Cut exactly between chunks: the header's length tells.
    assert_eq!(
        parse_error(&file[..bin_header as usize], "t.glb"),
        Place {
            byte: Some(8),
            element: Some("GLB header".into()),
            ..Place::default()
        }
    );
    assert_eq!(
        parse_error(&file[..7], "t.glb"),
        Place {
            byte: Some(0),
            element: Some("GLB header".into()),
            ..Place::default()
        }
    );
    // Every cut is an error, never a panic.
    for len in 4..file.len() {
        assert!(
            parse_gltf(&file[..len], Path::new("t.glb")).is_err(),
            "{len}"
        );
    }
}

#[test]
fn bad_base64_is_refused_at_its_buffer() {
    let mut bin = Bin::default();
    let mut body = triangle_asset(&mut bin);
    body["asset"] = json!({ "version": "2.0" });
    for uri in [
        "data:application/octet-stream;base64,AAA!",
        "data:application/octet-stream;base64,AAAAA",
        "data:application/octet-stream;base64,AA=A",
        "data:application/octet-stream,AAAA",
    ] {
        body["buffers"] = json!([{ "byteLength": 3, "uri": uri }]);
        let text = serde_json::to_vec(&body).unwrap();
        assert_eq!(
            parse_error(&text, "t.gltf"),
            Place::element("buffer", 0),
            "{uri}"
        );
    }
}

#[test]
fn unsupported_and_malformed_structures_are_refused_at_their_object() {
    let mut bin = Bin::default();
    let base = triangle_asset(&mut bin);
    let case = |edit: &dyn Fn(&mut Value)| {
        let mut body = base.clone();
        edit(&mut body);
        parse_error(&gltf_text(&bin, body), "t.gltf")
    };
    // A sparse accessor with more substitutions than elements.
    let sparse = json!({ "count": 4, "indices": { "bufferView": 2, "componentType": USHORT },
                         "values": { "bufferView": 0 } });
    assert_eq!(
        case(&|b| b["accessors"][0]["sparse"] = sparse.clone()),
        Place::element("accessor", 0)
    );
    // A POSITION accessor that does not exist (the gltf crate's own
    // validation would panic here).
    assert_eq!(
        case(&|b| b["meshes"][0]["primitives"][0]["attributes"]["POSITION"] = json!(9)),
        Place::element("mesh 0 primitive", 0)
    );
    // Positions as VEC2.
    assert_eq!(
        case(&|b| b["accessors"][0]["type"] = json!("VEC2")),
        Place::element("accessor", 0)
    );
    // A node cycle, and a node listed twice.
    assert_eq!(
        case(&|b| {
            b["nodes"] = json!([{ "children": [1] }, { "children": [0], "mesh": 0 }]);
            b["scenes"] = json!([{ "nodes": [0] }]);
        }),
        Place::element("node", 0)
    );
    assert_eq!(
        case(&|b| {
            b["nodes"] = json!([{ "mesh": 0 }]);
            b["scenes"] = json!([{ "nodes": [0, 0] }]);
        }),
        Place::element("node", 0)
    );
    // A required extension this reader does not know.
    assert_eq!(
        case(&|b| b["extensionsRequired"] = json!(["KHR_draco_mesh_compression"])),
        Place::element("extensionsRequired", 0)
    );
    // (A triangle list whose index count is not a multiple of 3 is read:
    // `a_list_whose_count_is_not_a_multiple_of_3_draws_its_whole_triangles`.)
    // A buffer whose data is shorter than its byteLength.
    let mut body = base.clone();
    body["asset"] = json!({ "version": "2.0" });
    body["buffers"] = json!([{ "byteLength": 1000, "uri": "data:;base64,AAAA" }]);
    assert_eq!(
        parse_error(&serde_json::to_vec(&body).unwrap(), "t.gltf"),
        Place::element("buffer", 0)
    );
    // Not JSON: the line.
    assert_eq!(parse_error(b"{\n\"asset\": ", "t.gltf"), Place::line(2));
}

/// A chain of 100,000 nested nodes is walked without recursion.
#[test]
fn deep_node_chains_do_not_overflow_the_stack() {
    let mut bin = Bin::default();
    let mut body = triangle_asset(&mut bin);
    let depth = 100_000;
    let nodes: Vec<Value> = (0..depth)
        .map(|i| {
            if i + 1 < depth {
                json!({ "children": [i + 1], "translation": [1, 0, 0] })
            } else {
                json!({ "mesh": 0 })
            }
        })
        .collect();
    body["nodes"] = Value::Array(nodes);
    body["scenes"] = json!([{ "nodes": [0] }]);
    let raw = parse_gltf(&gltf_text(&bin, body), Path::new("t.gltf")).unwrap();
    assert_eq!(raw.positions[0], Vec3::new((depth - 1) as f32, 0.0, 0.0));
}

/// Every byte of a small `.glb` set to each of a few values (digits turn
/// counts and offsets into other numbers): an error or a mesh, never a
/// panic, and no mesh with an index out of range.
#[test]
fn corrupted_glb_bytes_never_panic() {
    let mut bin = Bin::default();
    let mut body = triangle_asset(&mut bin);
    body["nodes"] = json!([{ "mesh": 0, "children": [1] }, { "mesh": 0, "scale": [1, -1, 1] }]);
    body["scenes"] = json!([{ "nodes": [0] }]);
    let (file, _) = glb(&bin, body);
    let mut accepted = 0;
    for at in 0..file.len() {
        for value in [0u8, 0xff, b'9', b'0', b'-'] {
            let mut bytes = file.clone();
            bytes[at] = value;
            if let Ok(raw) = parse_gltf(&bytes, Path::new("t.glb")) {
                let n = raw.positions.len() as u32;
                assert!(raw.triangles.iter().flatten().all(|&v| v < n), "byte {at}");
                assert!(raw.positions.iter().all(|p| p.is_finite()), "byte {at}");
                accepted += 1;
            }
        }
    }
    assert!(accepted > 0);
}

// ---------------------------------------------------------------------
// Issue 31: integers past 32 bits, asset versions, extras of any value,
// sparse and all-zero accessors.

/// The place and message of the parse error `bytes` gives.
fn parse_failure(bytes: &[u8], name: &str) -> (Place, String) {
    match parse_gltf(bytes, Path::new(name)) {
        Err(Error::Parse {
            file,
            place,
            message,
        }) => {
            assert_eq!(file, Path::new(name));
            (place, message)
        }
        Err(e) => panic!("not a parse error: {e}"),
        Ok(raw) => panic!("expected an error, got {} triangles", raw.triangles.len()),
    }
}

/// A place naming an object of the root without index (`asset`, `root`).
fn object(element: &str) -> Place {
    Place {
        element: Some(element.into()),
        ..Place::default()
    }
}

/// gltf-json reads indices modulo 2^32 (`"mesh": 4294967296` is mesh 0):
/// an index or code of 2^32 or more is refused at its object, naming the
/// field, wherever it is; 2^32 - 1 reaches the existence check; extras and
/// extensions may hold any integer.
#[test]
fn indices_of_2_to_the_32_or_more_are_refused_at_their_field() {
    let mut bin = Bin::default();
    let mut base = triangle_asset(&mut bin);
    let png = bin.put(common::PNG);
    base["bufferViews"].as_array_mut().unwrap().push(view(png));
    base["nodes"] = json!([{ "mesh": 0 }]);
    base["scenes"] = json!([{ "nodes": [0] }]);
    base["scene"] = json!(0);
    base["images"] = json!([{ "bufferView": 3, "mimeType": "image/png" }]);
    base["textures"] = json!([{ "source": 0 }]);
    base["materials"] = json!([{ "pbrMetallicRoughness": { "baseColorTexture": { "index": 0 } } }]);
    base["meshes"][0]["primitives"][0]["material"] = json!(0);
    let raw = parse_gltf(&gltf_text(&bin, base.clone()), Path::new("t.gltf")).unwrap();
    assert_eq!(raw.triangles, [[0, 1, 2]]);
    assert!(matches!(
        raw.properties.texture,
        Some(Texture::Embedded { .. })
    ));

    let big = 1u64 << 32;
    let case = |pointer: &str, value: u64| {
        let mut body = base.clone();
        let (parent, key) = pointer.rsplit_once('/').unwrap();
        let parent = body.pointer_mut(parent).unwrap();
        match key.parse::<usize>() {
            Ok(i) if parent.is_array() => parent[i] = json!(value),
            _ => parent[key] = json!(value),
        }
        parse_failure(&gltf_text(&bin, body), "t.gltf")
    };
    for (pointer, place, field) in [
        ("/nodes/0/mesh", Place::element("node", 0), "mesh"),
        ("/scene", object("root"), "scene"),
        ("/scenes/0/nodes/0", Place::element("scene", 0), "nodes[0]"),
        (
            "/meshes/0/primitives/0/attributes/POSITION",
            Place::element("mesh", 0),
            "primitives[0].attributes.POSITION",
        ),
        (
            "/meshes/0/primitives/0/indices",
            Place::element("mesh", 0),
            "primitives[0].indices",
        ),
        (
            "/meshes/0/primitives/0/material",
            Place::element("mesh", 0),
            "primitives[0].material",
        ),
        (
            "/accessors/1/bufferView",
            Place::element("accessor", 1),
            "bufferView",
        ),
        (
            "/bufferViews/2/buffer",
            Place::element("bufferView", 2),
            "buffer",
        ),
        (
            "/materials/0/pbrMetallicRoughness/baseColorTexture/index",
            Place::element("material", 0),
            "pbrMetallicRoughness.baseColorTexture.index",
        ),
        ("/textures/0/source", Place::element("texture", 0), "source"),
        (
            "/images/0/bufferView",
            Place::element("image", 0),
            "bufferView",
        ),
    ] {
        let (at, message) = case(pointer, big);
        assert_eq!(at, place, "{pointer}");
        assert_eq!(
            message,
            format!("{field} 4294967296 is not an index"),
            "{pointer}"
        );
        // Far past 2^32 too (2^32 + 1 would be index 1).
        let (at, message) = case(pointer, u64::MAX);
        assert_eq!(at, place, "{pointer}");
        assert!(
            message.starts_with(&format!("{field} {} ", u64::MAX)),
            "{message}"
        );
    }
    // Node children, and the codes: componentType 2^32 + FLOAT, mode 2^32 + 4.
    let mut body = base.clone();
    body["nodes"] = json!([{ "children": [1] }, { "mesh": 0 }]);
    body["nodes"][0]["children"][0] = json!(big + 1);
    assert_eq!(
        parse_failure(&gltf_text(&bin, body), "t.gltf"),
        (
            Place::element("node", 0),
            "children[0] 4294967297 is not an index".into()
        )
    );
    let (at, message) = case("/accessors/0/componentType", big + u64::from(FLOAT));
    assert_eq!(at, Place::element("accessor", 0));
    assert!(
        message.starts_with("componentType 4294972422 is not a valid value"),
        "{message}"
    );
    let (at, message) = case("/meshes/0/primitives/0/mode", big + 4);
    assert_eq!(at, Place::element("mesh", 0));
    assert!(
        message.starts_with("primitives[0].mode 4294967300 is not"),
        "{message}"
    );
    // Sparse views, in a .glb: the place is the object, no byte.
    let mut body = base.clone();
    body["accessors"][0]["sparse"] = json!({ "count": 1,
        "indices": { "bufferView": big, "componentType": USHORT },
        "values": { "bufferView": 0 } });
    assert_eq!(
        parse_failure(&glb(&bin, body).0, "t.glb"),
        (
            Place::element("accessor", 0),
            "sparse.indices.bufferView 4294967296 is not an index".into()
        )
    );
    // 2^32 - 1 is an index, of no mesh.
    let (at, message) = case("/nodes/0/mesh", big - 1);
    assert_eq!(at, Place::element("node", 0));
    assert!(
        message.contains("mesh 4294967295 does not exist"),
        "{message}"
    );
    // Any integer in extras and extensions; sizes are 64-bit, checked
    // against the data.
    let mut body = base.clone();
    body["nodes"][0]["extras"] = json!({ "mesh": u64::MAX, "big": [big] });
    body["nodes"][0]["extensions"] = json!({ "X_made_up": { "mesh": big } });
    let raw = parse_gltf(&gltf_text(&bin, body), Path::new("t.gltf")).unwrap();
    assert_eq!(raw.triangles, [[0, 1, 2]]);
    let (at, message) = case("/accessors/0/count", big);
    assert_eq!(at, Place::element("accessor", 0));
    assert!(
        message.starts_with("4294967296 elements of 12 bytes"),
        "{message}"
    );
}

/// `body` as a `.gltf` (buffer 0 `bin` as a data URI) with `asset`.
fn gltf_with_asset(bin: &Bin, body: Value, asset: Value) -> Vec<u8> {
    let mut document: Value = serde_json::from_slice(&gltf_text(bin, body)).unwrap();
    document["asset"] = asset;
    serde_json::to_vec(&document).unwrap()
}

/// A loader must refuse a major version it does not know (glTF 2.0,
/// "Asset"), and a minVersion above what it reads: 1.0, 3.0 and
/// minVersion 2.1 are refused at `asset`; 2.1 with minVersion 2.0 is read.
#[test]
fn asset_versions_other_than_2_are_refused_at_the_asset() {
    let mut bin = Bin::default();
    let body = triangle_asset(&mut bin);
    let read = |asset: Value| {
        parse_gltf(
            &gltf_with_asset(&bin, body.clone(), asset),
            Path::new("t.gltf"),
        )
    };
    let raw = read(json!({ "version": "2.1", "minVersion": "2.0" })).unwrap();
    assert_eq!(raw.triangles, [[0, 1, 2]]);
    assert_eq!(
        read(json!({ "version": "2.0" })).unwrap().positions.len(),
        3
    );
    for (asset, expected) in [
        (
            json!({ "version": "1.0" }),
            "version \"1.0\": glTF 1.x is not read, only 2.x",
        ),
        (
            json!({ "version": "3.0" }),
            "version \"3.0\": glTF 3.x is not read, only 2.x",
        ),
        (
            json!({ "version": "2" }),
            "version \"2\" is not MAJOR.MINOR",
        ),
        (
            json!({ "version": "2.1", "minVersion": "2.1" }),
            "minVersion \"2.1\": the asset needs a reader of glTF 2.1, this one reads 2.0",
        ),
        (
            json!({ "version": "3.0", "minVersion": "3.0" }),
            "version \"3.0\": glTF 3.x is not read, only 2.x",
        ),
    ] {
        match read(asset.clone()) {
            Err(Error::Parse { place, message, .. }) => {
                assert_eq!(place, object("asset"), "{asset}");
                assert_eq!(message, expected);
            }
            other => panic!("{asset}: expected a parse error, got {other:?}"),
        }
    }
    // A glTF 1.0 document (objects by name, not arrays) is refused for its
    // version, not for its shape.
    let old = br#"{ "asset": { "version": "1.0" }, "meshes": { "m": { "primitives": [] } } }"#;
    assert_eq!(parse_failure(old, "t.gltf").0, object("asset"));
}

/// The specification lets `extras` be any JSON value: arrays, strings,
/// numbers and null are read past, at the root and on every object.
#[test]
fn extras_of_any_json_value_are_accepted() {
    let mut bin = Bin::default();
    let mut body = triangle_asset(&mut bin);
    body["nodes"] = json!([{ "mesh": 0 }]);
    body["scenes"] = json!([{ "nodes": [0] }]);
    body["materials"] = json!([{ "pbrMetallicRoughness": { "baseColorFactor": [1, 1, 1, 1] } }]);
    body["meshes"][0]["primitives"][0]["material"] = json!(0);
    let plain = parse_gltf(&gltf_text(&bin, body.clone()), Path::new("t.gltf")).unwrap();
    let places = [
        "",
        "/nodes/0",
        "/scenes/0",
        "/meshes/0",
        "/meshes/0/primitives/0",
        "/accessors/0",
        "/accessors/2",
        "/bufferViews/1",
        "/materials/0",
        "/materials/0/pbrMetallicRoughness",
    ];
    for extras in [
        json!([1, 2, 3]),
        json!("hello"),
        json!(3),
        json!(null),
        json!([]),
    ] {
        let mut body = body.clone();
        for place in places {
            body.pointer_mut(place).unwrap()["extras"] = extras.clone();
        }
        let mut document: Value = serde_json::from_slice(&gltf_text(&bin, body)).unwrap();
        document["asset"]["extras"] = extras.clone();
        document["buffers"][0]["extras"] = extras.clone();
        let raw = parse_gltf(&serde_json::to_vec(&document).unwrap(), Path::new("t.gltf"))
            .unwrap_or_else(|e| panic!("extras {extras}: {e}"));
        assert_eq!(raw.positions, plain.positions);
        assert_eq!(raw.triangles, [[0, 1, 2]]);
        assert_eq!(raw.properties.normals, plain.properties.normals);
    }
    // A glTF mistake in a file with such extras still names its line
    // where it comes first, and is still refused where it comes after.
    let text = "{\n\"asset\": { \"version\": \"2.0\" },\n\
                \"accessors\": [{ \"componentType\": 5126, \"type\": \"VEC3\", \"count\": \"three\" }],\n\
                \"extras\": [1]\n}";
    let (place, message) = parse_failure(text.as_bytes(), "t.gltf");
    assert_eq!(place, Place::line(3));
    assert!(message.contains("\"three\""), "{message}");
    let text = "{\n\"asset\": { \"version\": \"2.0\", \"extras\": [1] },\n\
                \"accessors\": [{ \"componentType\": 5126, \"type\": \"VEC3\", \"count\": \"three\" }]\n}";
    let (place, message) = parse_failure(text.as_bytes(), "t.gltf");
    assert_eq!(place, Place::default());
    assert!(message.contains("\"three\""), "{message}");
}

//  3 - 2       a square whose vertices 1 and 3 are sparse substitutions
//  |   |       (u8 indices from byte 1 of their view) over a base view
//  0 - 1       holding 9s; normals all zero but vertex 2's (u16 index,
//              no bufferView); UV 0 substituted (u32 index); colours zero
//              but vertex 3's red (no bufferView, normalised u8); the
//              triangle list's last index substituted: (0 1 2) (0 2 3).
fn sparse_asset(bin: &mut Bin) -> Value {
    let p = bin.f32s(&[0., 0., 0., 9., 9., 9., 1., 1., 0., 9., 9., 9.]);
    let pi = bin.put(&[7, 1, 3]);
    let pv = bin.f32s(&[1., 0., 0., 0., 1., 0.]);
    let ni = bin.u16s(&[2]);
    let nv = bin.f32s(&[0., 0., 1.]);
    let t = bin.f32s(&[0., 0., 1., 0., 1., 1., 0., 1.]);
    let ti = bin.put(&0u32.to_le_bytes());
    let tv = bin.f32s(&[0.5, 0.25]);
    let ci = bin.put(&[3]);
    let cv = bin.put(&[255, 0, 0, 255]);
    let i = bin.u16s(&[0, 1, 2, 0, 2, 2]);
    let ii = bin.put(&[5]);
    let iv = bin.u16s(&[3]);
    let sparse = |count: usize, indices: usize, component: u32, values: usize| {
        json!({ "count": count, "indices": { "bufferView": indices, "componentType": component },
                "values": { "bufferView": values } })
    };
    let mut positions = accessor(0, FLOAT, "VEC3", 4);
    positions["sparse"] = sparse(2, 1, UBYTE, 2);
    positions["sparse"]["indices"]["byteOffset"] = json!(1);
    let normals = json!({ "componentType": FLOAT, "type": "VEC3", "count": 4,
                          "sparse": sparse(1, 3, USHORT, 4) });
    let mut uvs = accessor(5, FLOAT, "VEC2", 4);
    uvs["sparse"] = sparse(1, 6, UINT, 7);
    let colors = json!({ "componentType": UBYTE, "type": "VEC4", "count": 4, "normalized": true,
                         "sparse": sparse(1, 8, UBYTE, 9) });
    let mut indices = accessor(10, USHORT, "SCALAR", 6);
    indices["sparse"] = sparse(1, 11, UBYTE, 12);
    let views = [p, pi, pv, ni, nv, t, ti, tv, ci, cv, i, ii, iv].map(view);
    json!({
        "bufferViews": views,
        "accessors": [positions, normals, uvs, colors, indices],
        "meshes": [{ "primitives": [{
            "attributes": { "POSITION": 0, "NORMAL": 1, "TEXCOORD_0": 2, "COLOR_0": 3 },
            "indices": 4,
        }] }],
    })
}

const UINT: u32 = 5125;

#[test]
fn sparse_accessors_substitute_their_values() {
    let mut bin = Bin::default();
    let body = sparse_asset(&mut bin);
    let v = Vec3::new;
    for (file, name) in [
        (gltf_text(&bin, body.clone()), "t.gltf"),
        (glb(&bin, body.clone()).0, "t.glb"),
    ] {
        let raw = parse_gltf(&file, Path::new(name)).unwrap();
        assert_eq!(
            raw.positions,
            [v(0., 0., 0.), v(1., 0., 0.), v(1., 1., 0.), v(0., 1., 0.)]
        );
        assert_eq!(raw.triangles, [[0, 1, 2], [0, 2, 3]]);
        let p = &raw.properties;
        assert_eq!(
            p.normals.as_deref().unwrap(),
            [Vec3::ZERO, Vec3::ZERO, Vec3::Z, Vec3::ZERO]
        );
        // v flipped: 1 - v.
        assert_eq!(
            p.uvs.as_deref().unwrap(),
            [
                Vec2::new(0.5, 0.75),
                Vec2::new(1., 1.),
                Vec2::new(1., 0.),
                Vec2::new(0., 0.)
            ]
        );
        assert_eq!(
            p.colors.as_deref().unwrap(),
            [
                Vec4::ZERO,
                Vec4::ZERO,
                Vec4::ZERO,
                Vec4::new(1., 0., 0., 1.)
            ]
        );
    }
    let (mesh, report) = load_bytes(&gltf_text(&bin, body), Path::new("t.gltf")).unwrap();
    assert_eq!(mesh.triangles.len(), 2);
    assert_eq!(report.degenerate_dropped, 0);
}

fn load_bytes(bytes: &[u8], path: &Path) -> mts::Result<(Mesh, mts::mesh::CleanReport)> {
    mts::mesh::io::load_bytes(bytes, path, LoadOptions::default())
}

/// Every sparse mistake is refused at its accessor, with the byte of the
/// offending index or value in a `.glb`.
#[test]
fn bad_sparse_accessors_are_refused_with_their_byte() {
    let mut bin = Bin::default();
    let body = sparse_asset(&mut bin);
    let offset = |v: usize| body["bufferViews"][v]["byteOffset"].as_u64().unwrap();
    let failure = |bin: &Bin, body: &Value| {
        let (file, bin_at) = glb(bin, body.clone());
        let (place, message) = parse_failure(&file, "t.glb");
        (place, message, bin_at)
    };
    // Indices not increasing: 3 then 1, at byte 2 of view 1.
    let mut bad = Bin(bin.0.clone());
    bad.0[offset(1) as usize + 1..][..2].copy_from_slice(&[3, 1]);
    let (place, message, bin_at) = failure(&bad, &body);
    assert_eq!(place, at("accessor", 0, Some(bin_at + offset(1) + 2)));
    assert!(
        message.starts_with("sparse index 1 is 1, not above sparse index 0 (3)"),
        "{message}"
    );
    // An index past the accessor's count.
    let mut bad = Bin(bin.0.clone());
    bad.0[offset(1) as usize + 2] = 4;
    let (place, message, bin_at) = failure(&bad, &body);
    assert_eq!(place, at("accessor", 0, Some(bin_at + offset(1) + 2)));
    assert!(
        message.starts_with("sparse index 1 is 4, the accessor has 4 elements"),
        "{message}"
    );
    // A substituted index past the vertex count.
    let mut bad = Bin(bin.0.clone());
    bad.0[offset(12) as usize] = 4;
    let (place, message, bin_at) = failure(&bad, &body);
    assert_eq!(place, at("accessor", 4, Some(bin_at + offset(12))));
    assert!(
        message.starts_with("sparse value 0 (index 5) is 4, the primitive has 4 vertices"),
        "{message}"
    );
    // A substituted NaN: component 1 of value 1.
    let mut bad = Bin(bin.0.clone());
    bad.0[offset(2) as usize + 16..][..4].copy_from_slice(&f32::NAN.to_le_bytes());
    let (place, message, bin_at) = failure(&bad, &body);
    assert_eq!(place, at("accessor", 0, Some(bin_at + offset(2) + 16)));
    assert!(
        message.starts_with("component 1 of sparse value 1 (element 3) is NaN"),
        "{message}"
    );
    // Three indices from byte 1 of a 3-byte view; three values in a view
    // of two.
    let mut long = body.clone();
    long["accessors"][0]["sparse"]["count"] = json!(3);
    let (place, message, bin_at) = failure(&bin, &long);
    assert_eq!(place, at("accessor", 0, Some(bin_at + offset(1) + 1)));
    assert!(
        message.starts_with("sparse.indices: 3 elements of 1 bytes"),
        "{message}"
    );
    long["accessors"][0]["sparse"]["indices"]["byteOffset"] = json!(0);
    let (place, message, bin_at) = failure(&bin, &long);
    assert_eq!(place, at("accessor", 0, Some(bin_at + offset(2))));
    assert!(
        message.starts_with("sparse.values: 3 elements of 12 bytes"),
        "{message}"
    );
    // More substitutions than elements; float indices.
    let mut bad = body.clone();
    bad["accessors"][1]["sparse"]["count"] = json!(5);
    assert_eq!(failure(&bin, &bad).0, Place::element("accessor", 1));
    let mut bad = body.clone();
    bad["accessors"][1]["sparse"]["indices"]["componentType"] = json!(FLOAT);
    let (place, message, _) = failure(&bin, &bad);
    assert_eq!(place, Place::element("accessor", 1));
    assert!(
        message.contains("sparse.indices.componentType"),
        "{message}"
    );
    // Sparse indices in a view that does not exist.
    let mut bad = body.clone();
    bad["accessors"][2]["sparse"]["indices"]["bufferView"] = json!(99);
    assert_eq!(failure(&bin, &bad).0, Place::element("accessor", 2));
}

/// An accessor with neither bufferView nor sparse reads as zeros: three
/// coincident points make one triangle of no area, which the cleaning
/// step's weld makes degenerate, then reports no triangle left. Nothing
/// bounds such a
/// count but the caller's limit: three times its triangles.
#[test]
fn accessors_without_buffer_view_are_zeros_within_the_limit() {
    let body = json!({
        "accessors": [{ "componentType": FLOAT, "type": "VEC3", "count": 3 }],
        "meshes": [{ "primitives": [{ "attributes": { "POSITION": 0 } }] }],
    });
    let file = gltf_text(&Bin::default(), body.clone());
    let raw = parse_gltf(&file, Path::new("t.gltf")).unwrap();
    assert_eq!(raw.positions, [Vec3::ZERO; 3]);
    assert_eq!(raw.triangles, [[0, 1, 2]]);
    // Kept apart, the three vertices make a triangle of no area; welded,
    // none is left.
    let (mesh, _) = load_bytes(&file, Path::new("t.gltf")).unwrap();
    assert_eq!(mesh.triangles, [[0, 1, 2]]);
    let weld = LoadOptions {
        clean: mts::mesh::CleanOptions { weld: true },
        ..LoadOptions::default()
    };
    match mts::mesh::io::load_bytes(&file, Path::new("t.gltf"), weld).unwrap_err() {
        Error::InvalidMesh { source_name, .. } => assert_eq!(source_name, "t.gltf"),
        other => panic!("expected an invalid-mesh error, got {other:?}"),
    }
    // Limit 10 triangles: 30 zero vertices are read, 31 refused.
    let zeros = |count: u64, limit: u64| {
        let mut body = body.clone();
        body["accessors"][0]["count"] = json!(count);
        parse_gltf_with(
            &gltf_text(&Bin::default(), body),
            Path::new("t.gltf"),
            limit,
        )
    };
    assert_eq!(zeros(30, 10).unwrap().positions.len(), 30);
    for (count, limit) in [(31, 10), (u64::MAX, mts::mesh::io::DEFAULT_MAX_TRIANGLES)] {
        match zeros(count, limit) {
            Err(Error::Parse { place, message, .. }) => {
                assert_eq!(place, Place::element("accessor", 0));
                assert!(
                    message.starts_with(&format!("no bufferView: {count} elements of zeros")),
                    "{message}"
                );
            }
            other => panic!("expected a parse error, got {other:?}"),
        }
    }
    // Zero indices: a triangle list of the first vertex, within the limit.
    let mut body = body.clone();
    body["accessors"]
        .as_array_mut()
        .unwrap()
        .push(json!({ "componentType": USHORT, "type": "SCALAR", "count": 6 }));
    body["meshes"][0]["primitives"][0]["indices"] = json!(1);
    let file = gltf_text(&Bin::default(), body.clone());
    assert_eq!(
        parse_gltf(&file, Path::new("t.gltf")).unwrap().triangles,
        [[0, 0, 0], [0, 0, 0]]
    );
    body["accessors"][1]["count"] = json!(1u64 << 40);
    let (place, message) = parse_failure(&gltf_text(&Bin::default(), body), "t.gltf");
    assert_eq!(place, Place::element("accessor", 1));
    assert!(message.starts_with("no bufferView"), "{message}");
}

// ---------------------------------------------------------------------
// Valid files the typed model alone would refuse: each class of the
// Khronos validator's suite that is valid glTF, read as the specification
// allows.

/// `count: 3.0`: JSON has one number type, and the validator reads an
/// integral float where an integer is due.
#[test]
fn integers_written_as_floats_are_read() {
    let mut bin = Bin::default();
    let mut body = triangle_asset(&mut bin);
    body["accessors"][0]["count"] = json!(3.0);
    body["meshes"][0]["primitives"][0]["indices"] = json!(2.0);
    let raw = parse_gltf(&gltf_text(&bin, body), Path::new("t.gltf")).unwrap();
    assert_eq!(raw.triangles, [[0, 1, 2]]);
}

/// An animation channel whose target has no `node` (KHR_animation_pointer
/// names it instead) and a scene without `nodes`: both optional in glTF
/// 2.0, both required by the typed model; animations are not read.
#[test]
fn optional_fields_the_model_requires_are_not_required() {
    let mut bin = Bin::default();
    let mut body = triangle_asset(&mut bin);
    body["nodes"] = json!([{ "mesh": 0 }]);
    body["scenes"] = json!([{ "nodes": [0] }, {}]);
    body["scene"] = json!(0);
    body["animations"] = json!([{
        "channels": [{ "sampler": 0, "target": { "path": "pointer" } }],
        "samplers": [{ "input": 0, "output": 0 }],
    }]);
    let raw = parse_gltf(&gltf_text(&bin, body.clone()), Path::new("t.gltf")).unwrap();
    assert_eq!(raw.triangles, [[0, 1, 2]]);
    // The empty scene, chosen, draws nothing: no triangle, no error here
    // (the cleaning step reports the empty mesh).
    body["scene"] = json!(1);
    let raw = parse_gltf(&gltf_text(&bin, body), Path::new("t.gltf")).unwrap();
    assert!(raw.triangles.is_empty());
}

/// A GLB whose header length leaves bytes after it (the validator's
/// GLB_EXTRA_DATA, a warning): the chunks within the length are read. A
/// length past the file's end is still a truncated file.
#[test]
fn bytes_after_a_glb_s_declared_length_are_ignored() {
    let mut bin = Bin::default();
    let body = triangle_asset(&mut bin);
    let (mut file, _) = glb(&bin, body);
    let mut longer = file.clone();
    longer.push(0);
    let raw = parse_gltf(&longer, Path::new("t.glb")).unwrap();
    assert_eq!(raw.triangles, [[0, 1, 2]]);
    let n = file.len() as u32 + 4;
    file[8..12].copy_from_slice(&n.to_le_bytes());
    let (place, message) = parse_failure(&file, "t.glb");
    assert_eq!(place.byte, Some(8));
    assert!(message.contains("truncated"), "{message}");
}

/// A triangle list of 4 indices (the validator's
/// MESH_PRIMITIVE_INCOMPATIBLE_MODE, a warning) draws its whole triangle.
#[test]
fn a_list_whose_count_is_not_a_multiple_of_3_draws_its_whole_triangles() {
    let mut bin = Bin::default();
    let p = bin.f32s(&[0., 0., 0., 1., 0., 0., 0., 1., 0., 1., 1., 0.]);
    let body = json!({
        "bufferViews": [view(p)],
        "accessors": [accessor(0, FLOAT, "VEC3", 4)],
        "meshes": [{ "primitives": [{ "attributes": { "POSITION": 0 } }] }],
    });
    let raw = parse_gltf(&gltf_text(&bin, body), Path::new("t.gltf")).unwrap();
    assert_eq!(raw.triangles, [[0, 1, 2]]);
}

/// A primitive without POSITION is skipped (a client should not render
/// it), as is one whose data lie in a buffer with no uri in a `.gltf`
/// (no bytes anywhere); the others are read.
#[test]
fn primitives_without_positions_or_data_are_skipped() {
    let mut bin = Bin::default();
    let mut body = triangle_asset(&mut bin);
    let good = body["meshes"][0]["primitives"][0].clone();
    body["meshes"][0]["primitives"] = json!([{ "attributes": { "NORMAL": 1 } }, good]);
    let raw = parse_gltf(&gltf_text(&bin, body.clone()), Path::new("t.gltf")).unwrap();
    assert_eq!(raw.triangles, [[0, 1, 2]]);
    assert_eq!(
        mts::mesh::io::gltf_part_count(&gltf_text(&bin, body), Path::new("t.gltf")).unwrap(),
        1
    );
    // The same data in a buffer without uri: nothing to draw, and so no
    // triangle (the error is the cleaning step's "empty mesh").
    let mut body = triangle_asset(&mut bin);
    body["asset"] = json!({ "version": "2.0" });
    body["buffers"] = json!([{ "byteLength": bin.0.len() }]);
    let text = serde_json::to_vec(&body).unwrap();
    assert!(parse_gltf(&text, Path::new("t.gltf"))
        .unwrap()
        .triangles
        .is_empty());
    assert_eq!(
        mts::mesh::io::gltf_part_count(&text, Path::new("t.gltf")).unwrap(),
        0
    );
    match load_bytes(&text, Path::new("t.gltf")) {
        Err(Error::InvalidMesh { .. }) => {}
        other => panic!("expected an empty mesh, got {other:?}"),
    }
}

/// The base-colour texture's KHR_texture_transform applies to TEXCOORD_0,
/// checked on the extension's own example (offset [0, 1], rotation π/2,
/// scale [0.5, 0.5]: the lower-left quadrant, rotated); then `v` is
/// flipped as for every glTF coordinate.
#[test]
fn texture_transforms_apply_to_the_coordinates() {
    let mut bin = Bin::default();
    let mut body = triangle_asset(&mut bin);
    let t = bin.f32s(&[0., 0., 1., 0., 0., 1.]);
    body["bufferViews"].as_array_mut().unwrap().push(view(t));
    body["accessors"]
        .as_array_mut()
        .unwrap()
        .push(accessor(3, FLOAT, "VEC2", 3));
    body["meshes"][0]["primitives"][0]["attributes"]["TEXCOORD_0"] = json!(3);
    body["meshes"][0]["primitives"][0]["material"] = json!(0);
    body["materials"] = json!([{ "pbrMetallicRoughness": { "baseColorTexture": {
        "index": 0,
        "extensions": { "KHR_texture_transform": {
            "offset": [0, 1], "rotation": std::f64::consts::FRAC_PI_2, "scale": [0.5, 0.5] } },
    } } }]);
    body["textures"] = json!([{ "source": 0 }]);
    body["images"] = json!([{ "uri": "missing.png" }]);
    body["extensionsUsed"] = json!(["KHR_texture_transform"]);
    let raw = parse_gltf(&gltf_text(&bin, body), Path::new("t.gltf")).unwrap();
    let uvs = raw.properties.uvs.unwrap();
    // glTF (u, v) -> (0.5 v, 1 - 0.5 u), then v -> 1 - v.
    let want = [
        Vec2::new(0.0, 0.0),
        Vec2::new(0.0, 0.5),
        Vec2::new(0.5, 0.0),
    ];
    for (got, want) in uvs.iter().zip(want) {
        assert!((*got - want).abs().max_element() < 1e-6, "{got} {want}");
    }
}

/// A texture whose image is only in KHR_texture_basisu (no `source`) is
/// drawn untextured, its geometry read, even where the extension is
/// required.
#[test]
fn basisu_textures_leave_the_mesh_untextured() {
    let mut bin = Bin::default();
    let mut body = triangle_asset(&mut bin);
    body["meshes"][0]["primitives"][0]["material"] = json!(0);
    body["materials"] = json!([{ "pbrMetallicRoughness": { "baseColorTexture": { "index": 0 } } }]);
    body["textures"] = json!([{ "extensions": { "KHR_texture_basisu": { "source": 0 } } }]);
    body["images"] = json!([{ "uri": "t.ktx2", "mimeType": "image/ktx2" }]);
    body["extensionsUsed"] = json!(["KHR_texture_basisu"]);
    body["extensionsRequired"] = json!(["KHR_texture_basisu"]);
    let raw = parse_gltf(&gltf_text(&bin, body.clone()), Path::new("t.gltf")).unwrap();
    assert_eq!(raw.triangles, [[0, 1, 2]]);
    assert!(raw.properties.texture.is_none());
    // With a KTX2 image as `source` itself: the same.
    body["textures"] = json!([{ "source": 0 }]);
    let raw = parse_gltf(&gltf_text(&bin, body), Path::new("t.gltf")).unwrap();
    assert!(raw.properties.texture.is_none());
}
