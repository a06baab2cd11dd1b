//! The PLY reader and writer: every encoding, skipped properties,
//! polygons, triangle strips, vertex property streams (normals, texture
//! coordinates, colours) under each of their names and types, the round
//! trip through `save_ply`, and every error case the loader promises a
//! clear message for.

use glam::{Vec2, Vec3, Vec4};
use mts::mesh::io::{load, parse_ply, save_ply, LoadOptions};
use mts::mesh::{clean, CleanOptions, Mesh, Properties, RawMesh, Texture};
use mts::Error;
use std::path::{Path, PathBuf};

/// A unit square (two triangles as one quad face) plus a third triangle,
/// with extra vertex properties (`nx` as double, `confidence` as uchar, a
/// `texlist` list) and an extra face property, in the given encoding.
fn square_ply(format: &str) -> Vec<u8> {
    let header = format!(
        "ply\nformat {format} 1.0\ncomment made by a test\n\
         element vertex 5\nproperty double x\nproperty double y\nproperty double z\n\
         property float nx\nproperty uchar confidence\nproperty list uchar float texlist\n\
         element face 2\nproperty list uchar int vertex_indices\nproperty ushort flags\n\
         element extra 2\nproperty list int short stuff\n\
         end_header\n"
    );
    let verts: [[f64; 3]; 5] = [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [1.0, 1.0, 0.0],
        [0.0, 1.0, 0.0],
        [2.0, 0.0, 0.0],
    ];
    let faces: [&[i32]; 2] = [&[0, 1, 2, 3], &[1, 4, 2]];
    let mut out = header.into_bytes();
    if format == "ascii" {
        for v in verts {
            out.extend(format!("{} {} {} 0.5 7 2 0.25 0.75\n", v[0], v[1], v[2]).bytes());
        }
        for f in faces {
            let idx: Vec<String> = f.iter().map(|i| i.to_string()).collect();
            out.extend(format!("{} {} 3\n", f.len(), idx.join(" ")).bytes());
        }
        out.extend(b"3 1 2 3\n0\n");
        return out;
    }
    let be = format == "binary_big_endian";
    macro_rules! put {
        ($v:expr) => {
            if be {
                out.extend_from_slice(&$v.to_be_bytes())
            } else {
                out.extend_from_slice(&$v.to_le_bytes())
            }
        };
    }
    for v in verts {
        for c in v {
            put!(c);
        }
        put!(0.5f32);
        put!(7u8);
        put!(2u8);
        put!(0.25f32);
        put!(0.75f32);
    }
    for f in faces {
        put!(f.len() as u8);
        for &i in f {
            put!(i);
        }
        put!(3u16);
    }
    put!(3i32);
    put!(1i16);
    put!(2i16);
    put!(3i16);
    put!(0i32);
    out
}

fn parse(bytes: &[u8]) -> mts::Result<mts::mesh::RawMesh> {
    parse_ply(bytes, Path::new("test.ply"))
}

#[test]
fn every_encoding_reads_the_same_mesh() {
    for format in ["ascii", "binary_little_endian", "binary_big_endian"] {
        let raw = parse(&square_ply(format)).unwrap_or_else(|e| panic!("{format}: {e}"));
        assert_eq!(raw.positions.len(), 5, "{format}");
        assert_eq!(raw.positions[2], glam::Vec3::new(1.0, 1.0, 0.0), "{format}");
        assert_eq!(
            raw.triangles,
            vec![[0, 1, 2], [0, 2, 3], [1, 4, 2]],
            "{format}"
        );
    }
}

#[test]
fn tristrips_decode_with_alternating_winding_and_restarts() {
    let text = "ply\nformat ascii 1.0\nelement vertex 6\nproperty float x\nproperty float y\nproperty float z\n\
                element tristrips 1\nproperty list int int vertex_indices\nend_header\n\
                0 0 0\n1 0 0\n0 1 0\n1 1 0\n0 2 0\n1 2 0\n\
                9 0 1 2 3 -1 2 3 3 4\n";
    let raw = parse(text.as_bytes()).unwrap();
    // Run 0 1 2 3 -> (0,1,2), (2,1,3); run 2 3 3 4 -> two degenerate windows.
    assert_eq!(raw.triangles, vec![[0, 1, 2], [2, 1, 3]]);
    assert_eq!(raw.degenerate_in_source, 2);
}

#[test]
fn real_bunny_reads_binary_or_ascii() {
    let path = Path::new(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../../shared/models/bunny_res4.ply"
    ));
    if !path.exists() {
        eprintln!(
            "skipped: {} not found (../shared/models is absent)",
            path.display()
        );
        return;
    }
    let (mesh, report) = load(path, LoadOptions::default()).unwrap();
    assert_eq!(mesh.triangle_count(), 948);
    assert_eq!(report.source_vertices, 453);
}

/// The place of the parse error `bytes` give (a panic for any other
/// outcome): tests match variants and places, not message text.
fn place_of(bytes: &[u8]) -> mts::Place {
    match parse(bytes) {
        Err(Error::Parse { file, place, .. }) => {
            assert_eq!(file, Path::new("test.ply"));
            place
        }
        Err(e) => panic!("not a parse error: {e}"),
        Ok(_) => panic!("expected an error"),
    }
}

/// A place of line, byte, element and index.
fn at(
    line: Option<u64>,
    byte: Option<u64>,
    element: Option<&str>,
    index: Option<u64>,
) -> mts::Place {
    mts::Place {
        line,
        byte,
        element: element.map(str::to_owned),
        index,
    }
}

#[test]
fn truncated_binary_names_element_and_byte() {
    let bytes = square_ply("binary_little_endian");
    let cut = &bytes[..bytes.len() - 30];
    assert_eq!(place_of(cut), at(None, Some(548), Some("face"), Some(0)));
}

#[test]
fn truncated_ascii_names_line() {
    let bytes = square_ply("ascii");
    let text = String::from_utf8(bytes).unwrap();
    let cut = &text[..text.find("4 0 1 2 3").unwrap()];
    let place = place_of(cut.as_bytes());
    assert_eq!(
        (place.element.as_deref(), place.index),
        (Some("face"), Some(0))
    );
    assert!(place.line.is_some(), "{place:?}");
}

#[test]
fn index_out_of_range_names_the_face() {
    let text = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n\
                element face 2\nproperty list uchar int vertex_indices\nend_header\n\
                0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n3 0 1 3\n";
    assert_eq!(
        place_of(text.as_bytes()),
        at(Some(14), None, Some("face"), Some(1))
    );
    let negative = text.replace("3 0 1 3\n", "3 0 -1 2\n");
    assert_eq!(
        place_of(negative.as_bytes()),
        at(Some(14), None, Some("face"), Some(1))
    );
}

#[test]
fn nan_and_infinite_coordinates_are_refused() {
    for bad in ["nan", "inf", "-inf", "1e300"] {
        let text = format!(
            "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n\
             element face 1\nproperty list uchar int vertex_indices\nend_header\n\
             0 0 0\n1 {bad} 0\n0 1 0\n3 0 1 2\n"
        );
        assert_eq!(
            place_of(text.as_bytes()),
            at(Some(11), None, Some("vertex"), Some(1)),
            "{bad}"
        );
    }
}

#[test]
fn absurd_header_counts_fail_fast_without_allocating() {
    // Four billion vertices declared, three present: a clear truncation error,
    // no multi-gigabyte reservation.
    let text = "ply\nformat binary_little_endian 1.0\nelement vertex 4000000000\nproperty float x\n\
                property float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n";
    let mut bytes = text.as_bytes().to_vec();
    for v in [0f32, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0] {
        bytes.extend_from_slice(&v.to_le_bytes());
    }
    let place = place_of(&bytes);
    assert_eq!(
        (place.element.as_deref(), place.index, place.byte),
        (Some("vertex"), Some(3), Some(text.len() as u64 + 36)),
    );

    // A list claiming 4 billion items.
    let text = "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\n\
                property float z\nelement face 1\nproperty list uint int vertex_indices\nend_header\n";
    let mut bytes = text.as_bytes().to_vec();
    for v in [0f32, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0] {
        bytes.extend_from_slice(&v.to_le_bytes());
    }
    bytes.extend_from_slice(&4_000_000_000u32.to_le_bytes());
    bytes.extend_from_slice(&0i32.to_le_bytes());
    // Named where the second index would start: after the vertices, the
    // list's count and its first index.
    let place = place_of(&bytes);
    assert_eq!(
        (place.element.as_deref(), place.index, place.byte),
        (Some("face"), Some(0), Some(text.len() as u64 + 36 + 8))
    );

    // An element with no properties and a huge count reads nothing.
    let text = "ply\nformat ascii 1.0\nelement nothing 18446744073709551615\nelement vertex 3\nproperty float x\n\
                property float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n\
                0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
    assert_eq!(parse(text.as_bytes()).unwrap().triangles.len(), 1);
}

#[test]
fn unknown_formats_are_named() {
    let e = parse(b"solid cube\nfacet normal 0 0 1\n").unwrap_err();
    assert!(matches!(e, Error::UnknownFormat { .. }), "{e}");
    let e = parse(b"ply\nformat binary_middle_endian 1.0\nend_header\n").unwrap_err();
    assert!(matches!(e, Error::UnknownFormat { .. }), "{e}");
    // A header without `end_header`: named at the line after its last.
    let place = place_of(b"ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\n");
    assert_eq!((place.line, place.byte), (Some(5), None));
    let place = place_of(b"ply\nformat ascii 1.0\nelement vertex 1\nproperty quad x\nend_header\n");
    assert_eq!(place.line, Some(4));
}

#[test]
fn missing_coordinates_and_empty_meshes_are_refused() {
    let place = place_of(b"ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nend_header\n0 0\n");
    assert_eq!(place.line, Some(3));
    // Vertices without faces: refused by the reader, at the data's start.
    let place = place_of(b"ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nend_header\n0 0 0\n1 0 0\n0 1 0\n");
    assert_eq!(place, at(Some(8), Some(100), None, None));
    // A raw mesh from elsewhere without triangles: refused by clean.
    let raw = mts::mesh::RawMesh {
        positions: vec![glam::Vec3::ZERO; 3],
        triangles: Vec::new(),
        degenerate_in_source: 0,
        properties: Default::default(),
    };
    let e = clean(raw, CleanOptions::default(), "test.ply").unwrap_err();
    assert!(
        matches!(&e, Error::InvalidMesh { source_name, .. } if source_name == "test.ply"),
        "{e}"
    );
}

#[test]
fn non_numeric_token_is_named() {
    let place = place_of(b"ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nproperty float z\nend_header\n0 zero 0\n");
    assert_eq!(place, at(Some(8), None, Some("vertex"), Some(0)));
}

#[test]
fn load_names_missing_files() {
    let e = load(Path::new("/nonexistent/bunny.ply"), LoadOptions::default()).unwrap_err();
    assert!(e.to_string().starts_with("/nonexistent/bunny.ply: "), "{e}");
}

/// A PLY of the square below: `vertex` properties `(type, name)` after
/// `float x y z`, with one row of values per vertex, each written as its
/// declared type; then the faces as `list uchar int vertex_indices`
/// followed by MeshLab's per-face `list uchar float texcoord` and a
/// `uchar red`, which the reader skips. The header names a texture.
///
/// ```text
///  3 --- 2
///  |   / |
///  | /   |
///  0 --- 1
/// ```
fn streams_ply(format: &str, properties: &[(&str, &str)], rows: &[Vec<f64>]) -> Vec<u8> {
    let mut header = format!(
        "ply\nformat {format} 1.0\ncomment TextureFile checker board.png\nelement vertex 4\n\
         property float x\nproperty float y\nproperty float z\n"
    );
    for (ty, name) in properties {
        header += &format!("property {ty} {name}\n");
    }
    header += "element face 2\nproperty list uchar int vertex_indices\n\
               property list uchar float texcoord\nproperty uchar red\nend_header\n";
    let positions = [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [1.0, 1.0, 0.0],
        [0.0, 1.0, 0.0],
    ];
    let faces: [[i32; 3]; 2] = [[0, 1, 2], [0, 2, 3]];
    let mut out = header.into_bytes();
    if format == "ascii" {
        for (p, row) in positions.iter().zip(rows) {
            let values: Vec<String> = p.iter().chain(row).map(f64::to_string).collect();
            out.extend(format!("{}\n", values.join(" ")).bytes());
        }
        for f in faces {
            out.extend(format!("3 {} {} {} 6 0 0 1 0 1 1 200\n", f[0], f[1], f[2]).bytes());
        }
        return out;
    }
    let be = format == "binary_big_endian";
    macro_rules! put {
        ($v:expr) => {
            if be {
                out.extend_from_slice(&$v.to_be_bytes())
            } else {
                out.extend_from_slice(&$v.to_le_bytes())
            }
        };
    }
    for (p, row) in positions.iter().zip(rows) {
        for &c in p {
            put!(c as f32);
        }
        for (&(ty, _), &v) in properties.iter().zip(row) {
            match ty {
                "char" => put!(v as i8),
                "uchar" => put!(v as u8),
                "short" => put!(v as i16),
                "ushort" => put!(v as u16),
                "int" => put!(v as i32),
                "uint" => put!(v as u32),
                "float" => put!(v as f32),
                "double" => put!(v),
                _ => panic!("type {ty}"),
            }
        }
    }
    for f in faces {
        put!(3u8);
        for i in f {
            put!(i);
        }
        put!(6u8);
        for t in [0f32, 0.0, 1.0, 0.0, 1.0, 1.0] {
            put!(t);
        }
        put!(200u8);
    }
    out
}

const FORMATS: [&str; 3] = ["ascii", "binary_little_endian", "binary_big_endian"];

/// Rows of vertex `i` = 0..4: normal `(0, 0, 2)` (normalised by clean, not
/// by the reader), texture coordinate `(i, i / 4)`, colour `(i / 5, i / 5,
/// i / 5, 1)` times `max` (255 for uchar, 1 for float).
fn stream_rows(max: f64) -> Vec<Vec<f64>> {
    (0..4)
        .map(|i| {
            let (f, c) = (f64::from(i), f64::from(i) * max / 5.0);
            vec![0.0, 0.0, 2.0, f, 0.25 * f, c, c, c, max]
        })
        .collect()
}

/// What [`stream_rows`] reads as.
fn assert_streams(raw: &RawMesh, what: &str) {
    assert_eq!(raw.triangles, vec![[0, 1, 2], [0, 2, 3]], "{what}");
    assert_eq!(
        raw.properties.normals,
        Some(vec![Vec3::new(0.0, 0.0, 2.0); 4]),
        "{what}"
    );
    let uvs = (0..4).map(|i| Vec2::new(i as f32, 0.25 * i as f32));
    assert_eq!(raw.properties.uvs, Some(uvs.collect()), "{what}");
    let colors = raw.properties.colors.as_ref().expect(what);
    assert_eq!(colors.len(), 4, "{what}");
    for (i, c) in colors.iter().enumerate() {
        let want = Vec4::new(0.2, 0.2, 0.2, 0.0) * i as f32 + Vec4::W;
        assert!((*c - want).abs().max_element() < 1e-6, "{what}: {c} {want}");
    }
}

#[test]
fn every_encoding_reads_normals_texture_coordinates_and_colours() {
    for (color, max) in [("uchar", 255.0), ("float", 1.0), ("double", 1.0)] {
        let properties = [
            ("float", "nx"),
            ("double", "ny"),
            ("float", "nz"),
            ("float", "texture_u"),
            ("float", "texture_v"),
            (color, "red"),
            (color, "green"),
            (color, "blue"),
            (color, "alpha"),
        ];
        for format in FORMATS {
            let what = format!("{format}, {color} colours");
            let bytes = streams_ply(format, &properties, &stream_rows(max));
            let raw = parse(&bytes).unwrap_or_else(|e| panic!("{what}: {e}"));
            assert_streams(&raw, &what);
            assert_eq!(
                raw.properties.texture,
                Some(Texture::File(PathBuf::from("checker board.png"))),
                "{what}"
            );
        }
    }
}

#[test]
fn every_name_variant_and_integer_type_reads() {
    let uv_names = [
        ["texture_u", "texture_v"],
        ["u", "v"],
        ["s", "t"],
        ["texture_s", "texture_t"],
    ];
    let color_names = [
        ["red", "green", "blue", "alpha"],
        ["r", "g", "b", "a"],
        [
            "diffuse_red",
            "diffuse_green",
            "diffuse_blue",
            "diffuse_alpha",
        ],
    ];
    for (uv, color) in uv_names.iter().zip(color_names.iter().cycle()) {
        for (ty, max) in [("uchar", 255.0), ("ushort", 65535.0)] {
            let properties = [
                ("short", "nx"),
                ("char", "ny"),
                ("int", "nz"),
                ("double", uv[0]),
                ("float", uv[1]),
                (ty, color[0]),
                (ty, color[1]),
                (ty, color[2]),
                (ty, color[3]),
            ];
            for format in FORMATS {
                let what = format!("{format}, {uv:?}, {color:?} as {ty}");
                let bytes = streams_ply(format, &properties, &stream_rows(max));
                assert_streams(&parse(&bytes).unwrap(), &what);
            }
        }
    }
    // No alpha: opaque. A path's folder is the texture's.
    let rows: Vec<Vec<f64>> = stream_rows(255.0)
        .into_iter()
        .map(|r| [&r[5..8], &r[3..5]].concat())
        .collect();
    let properties = [
        ("uchar", "red"),
        ("uchar", "green"),
        ("uchar", "blue"),
        ("float", "u"),
        ("float", "v"),
    ];
    let bytes = streams_ply("binary_little_endian", &properties, &rows);
    let raw = parse_ply(&bytes, Path::new("models/square.ply")).unwrap();
    let alpha: Vec<f32> = raw.properties.colors.unwrap().iter().map(|c| c.w).collect();
    assert_eq!(alpha, vec![1.0; 4]);
    assert_eq!(
        raw.properties.texture,
        Some(Texture::File(PathBuf::from("models/checker board.png")))
    );
}

#[test]
fn partial_streams_are_skipped() {
    // A lone nx, u without v, red and green without blue, an alpha alone,
    // and components of two families that do not make one.
    let properties = [
        ("float", "nx"),
        ("float", "ny"),
        ("float", "u"),
        ("float", "texture_v"),
        ("uchar", "red"),
        ("uchar", "green"),
        ("uchar", "b"),
        ("uchar", "alpha"),
    ];
    let rows = vec![vec![1.0, 0.0, 0.5, 0.5, 9.0, 9.0, 9.0, 9.0]; 4];
    for format in FORMATS {
        let raw = parse(&streams_ply(format, &properties, &rows)).unwrap();
        assert_eq!(raw.positions.len(), 4, "{format}");
        assert_eq!(raw.triangles.len(), 2, "{format}");
        // Without texture coordinates the texture is dropped too.
        assert_eq!(raw.properties, Properties::default(), "{format}");
    }
}

#[test]
fn stream_components_declared_as_lists_are_refused_at_their_line() {
    for (name, line) in [("x", 4), ("nx", 7), ("texture_u", 7), ("alpha", 7)] {
        let mut lines = [
            "ply",
            "format ascii 1.0",
            "element vertex 3",
            "property float x",
            "property float y",
            "property float z",
            "",
            "end_header",
        ];
        let list = format!("property list uchar float {name}");
        lines[line as usize - 1] = &list;
        let text = lines.join("\n") + "\n";
        assert_eq!(
            place_of(text.as_bytes()),
            at(Some(line), None, None, None),
            "{name}"
        );
    }
    // Indices of a non-integer type: the list's line.
    let text = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n\
                property float z\nelement face 1\nproperty uchar flags\n\
                property list uchar float vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n";
    assert_eq!(place_of(text.as_bytes()), at(Some(9), None, None, None));
}

#[test]
fn nan_and_infinite_property_values_are_refused_where_they_are() {
    let properties = [
        ("float", "nx"),
        ("float", "ny"),
        ("float", "nz"),
        ("float", "texture_u"),
        ("double", "texture_v"),
        ("float", "red"),
        ("float", "green"),
        ("float", "blue"),
    ];
    // Byte offsets of the values in a vertex: x y z, then the above.
    let offsets = [12, 16, 20, 24, 28, 36, 40, 44];
    let vertex_bytes = 48;
    // Vertex 2's value `k` (0-based after x y z) made bad.
    for (k, bad) in [
        (1, f64::NAN),
        (4, f64::INFINITY),
        (4, -1e300),
        (6, f64::NAN),
    ] {
        let mut rows = vec![vec![0.0, 0.0, 1.0, 0.5, 0.5, 1.0, 1.0, 1.0]; 4];
        rows[2][k] = bad;
        for format in FORMATS {
            let bytes = streams_ply(format, &properties, &rows);
            let data = bytes
                .windows(11)
                .position(|w| w == b"end_header\n")
                .unwrap()
                + 11;
            let header_lines = bytes[..data].iter().filter(|&&b| b == b'\n').count() as u64;
            let want = if format == "ascii" {
                at(Some(header_lines + 3), None, Some("vertex"), Some(2))
            } else {
                let byte = data + 2 * vertex_bytes + offsets[k];
                at(None, Some(byte as u64), Some("vertex"), Some(2))
            };
            assert_eq!(place_of(&bytes), want, "{format}, value {k} = {bad}");
        }
    }
    // A coordinate: its own byte too (vertex 1's y).
    let mut bytes = b"ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\n\
property float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
        .to_vec();
    let data = bytes.len();
    for x in [0.0, 0.0, 0.0, 1.0, f32::NAN, 0.0, 0.0, 1.0, 0.0] {
        bytes.extend_from_slice(&f32::to_le_bytes(x));
    }
    assert_eq!(
        place_of(&bytes),
        at(None, Some(data as u64 + 16), Some("vertex"), Some(1))
    );
}

/// A square of two triangles with every stream and a seam: vertices 2
/// and 4 are one point with different texture coordinates.
///
/// ```text
///  3 --- 2,4
///  |   /  |
///  | /    |
///  0 ---- 1
/// ```
fn square_with_streams(texture: &Path) -> Mesh {
    let raw = RawMesh {
        positions: vec![
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(1.0, 1.0, 0.5),
            Vec3::new(0.0, 1.0, 0.0),
            Vec3::new(1.0, 1.0, 0.5),
        ],
        triangles: vec![[0, 1, 2], [0, 4, 3]],
        degenerate_in_source: 0,
        properties: Properties {
            normals: Some(
                (0..5)
                    .map(|i| Vec3::new(0.1 * i as f32, -0.3, 1.0))
                    .collect(),
            ),
            uvs: Some(
                (0..5)
                    .map(|i| Vec2::new(0.5 * i as f32, 1.0 - 0.125 * i as f32))
                    .collect(),
            ),
            colors: Some(
                (0..5)
                    .map(|i| Vec4::new(0.1 * i as f32, 0.33, 1.0, 0.7))
                    .collect(),
            ),
            position_ids: vec![0, 1, 2, 3, 2],
            texture: Some(Texture::File(texture.to_owned())),
        },
    };
    clean(raw, CleanOptions::default(), "square").unwrap().0
}

/// Whether `a` and `b` have the same colours within 1/255 (the writer's
/// `uchar`) and the same normals within `normal_error`; returns `b` with
/// `a`'s colours and normals for an exact comparison of the rest.
fn close_streams(a: &Properties, b: &Properties, normal_error: f32) -> Properties {
    let (ca, cb) = (a.colors.as_ref(), b.colors.as_ref());
    assert_eq!(ca.map(Vec::len), cb.map(Vec::len));
    for (x, y) in ca.into_iter().flatten().zip(cb.into_iter().flatten()) {
        assert!((*x - *y).abs().max_element() <= 1.0 / 255.0, "{x} {y}");
    }
    let (na, nb) = (a.normals.as_ref(), b.normals.as_ref());
    assert_eq!(na.map(Vec::len), nb.map(Vec::len));
    for (x, y) in na.into_iter().flatten().zip(nb.into_iter().flatten()) {
        assert!((*x - *y).abs().max_element() <= normal_error, "{x} {y}");
    }
    Properties {
        colors: a.colors.clone(),
        normals: a.normals.clone(),
        ..b.clone()
    }
}

#[test]
fn save_ply_reads_back_to_the_same_mesh() {
    let folder = Path::new(env!("CARGO_TARGET_TMPDIR"));
    let path = folder.join("save_ply_streams.ply");
    let mesh = square_with_streams(&folder.join("checker.png"));
    assert_eq!(mesh.properties.position_ids, vec![0, 1, 2, 3, 2]);
    save_ply(&mesh, &path).unwrap();
    // The reader gives back every value (normals to the bit), but not the
    // position ids, which PLY has no place for.
    let raw = parse_ply(&std::fs::read(&path).unwrap(), &path).unwrap();
    assert_eq!(raw.positions, mesh.positions);
    assert_eq!(raw.triangles, mesh.triangles);
    let read = close_streams(&mesh.properties, &raw.properties, 0.0);
    let want = Properties {
        position_ids: Vec::new(),
        ..mesh.properties.clone()
    };
    assert_eq!(read, want);
    // Cleaned with the weld, the seam's two vertices are one point again;
    // clean normalises normals again (a change in the last bit).
    let weld = CleanOptions { weld: true };
    let (again, report) = clean(raw.clone(), weld, "again").unwrap();
    assert_eq!(report.welded, 0);
    assert_eq!(again.positions, mesh.positions);
    assert_eq!(again.triangles, mesh.triangles);
    let read = close_streams(&mesh.properties, &again.properties, 1e-6);
    assert_eq!(read, mesh.properties);
    let bytes = std::fs::read(&path).unwrap();
    let text = String::from_utf8_lossy(
        &bytes[..bytes.windows(10).position(|w| w == b"end_header").unwrap()],
    );
    assert!(
        text.contains("\ncomment TextureFile checker.png\n"),
        "{text}"
    );
    assert!(
        text.contains("\nproperty float texture_u\nproperty float texture_v\n"),
        "{text}"
    );

    // Positions only, a closed surface: the same bits.
    let sphere = mts::mesh::generate::icosphere(12, 0.1, 7);
    let path = folder.join("save_ply_sphere.ply");
    save_ply(&sphere, &path).unwrap();
    let raw = parse_ply(&std::fs::read(&path).unwrap(), &path).unwrap();
    assert_eq!(raw.properties, Properties::default());
    assert_eq!(
        clean(raw, CleanOptions::default(), "again").unwrap().0,
        sphere
    );
}

#[test]
fn save_ply_refuses_invalid_meshes_and_unwritable_textures() {
    let folder = Path::new(env!("CARGO_TARGET_TMPDIR"));
    let path = folder.join("save_ply_refused.ply");
    let mut mesh = square_with_streams(Path::new("t.png"));
    mesh.properties.uvs.as_mut().unwrap().pop();
    assert!(matches!(save_ply(&mesh, &path), Err(Error::Invalid(_))));
    let mesh = square_with_streams(&folder.join("two\nlines.png"));
    assert!(matches!(
        save_ply(&mesh, &path),
        Err(Error::InvalidArgument(_))
    ));
    let mesh = square_with_streams(Path::new("t.png"));
    let e = save_ply(&mesh, Path::new("/nonexistent/m.ply")).unwrap_err();
    assert!(
        matches!(&e, Error::Io { file, .. } if file == Path::new("/nonexistent/m.ply")),
        "{e}"
    );
}

/// MeshLab writes `property list uchar float texcoord` after the indices:
/// reading that list once emptied the index list, so every face was lost.
#[test]
fn a_list_after_the_indices_keeps_them() {
    let text = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n\
                property float z\nelement face 1\nproperty list uchar int vertex_indices\n\
                property list uchar float texcoord\nend_header\n0 0 0\n1 0 0\n0 1 0\n\
                3 0 1 2 6 0 0 1 0 0 1\n";
    assert_eq!(parse(text.as_bytes()).unwrap().triangles, vec![[0, 1, 2]]);
}

/// Two `vertex` elements would give streams and indices two numberings.
#[test]
fn a_second_vertex_element_is_refused_at_its_line() {
    let text = "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n\
                property float z\nelement vertex 1\nproperty float nx\nend_header\n0 0 0\n1\n";
    assert_eq!(place_of(text.as_bytes()), at(Some(7), None, None, None));
}
