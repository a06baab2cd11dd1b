//! The PLY reader: every encoding, skipped properties, polygons, triangle
//! strips, and every error case the loader promises a clear message for.

use mts::mesh::io::{load, parse_ply, LoadOptions};
use mts::mesh::{clean, CleanOptions};
use mts::Error;
use std::path::Path;

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
