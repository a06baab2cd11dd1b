//! Corrupted input never panics: random truncations, byte flips and
//! insertions applied to valid PLY (all three encodings) and OBJ files give
//! either a mesh or an error, and an error always names the file.

use mts::mesh::io::{parse, Format};
use proptest::prelude::*;
use std::path::Path;

fn ply(format: &str) -> Vec<u8> {
    let mut out = format!(
        "ply\nformat {format} 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n\
         property list uchar int extra\nelement face 2\nproperty list uchar int vertex_indices\nend_header\n"
    )
    .into_bytes();
    let verts = [
        [0f32, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [1.0, 1.0, 0.0],
        [0.0, 1.0, 0.0],
    ];
    if format == "ascii" {
        for v in verts {
            out.extend(format!("{} {} {} 1 7\n", v[0], v[1], v[2]).bytes());
        }
        out.extend(b"3 0 1 2\n3 0 2 3\n");
        return out;
    }
    let be = format == "binary_big_endian";
    let mut put = |b: &[u8]| out.extend(b.iter().copied());
    for v in verts {
        for c in v {
            put(&if be { c.to_be_bytes() } else { c.to_le_bytes() });
        }
        put(&[1]);
        put(&if be {
            7i32.to_be_bytes()
        } else {
            7i32.to_le_bytes()
        });
    }
    for f in [[0i32, 1, 2], [0, 2, 3]] {
        put(&[3]);
        for i in f {
            put(&if be { i.to_be_bytes() } else { i.to_le_bytes() });
        }
    }
    out
}

const OBJ: &[u8] = b"# quad\nmtllib none.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvn 0 0 1\nf 1//1 2//1 3//1 4//1\n";

#[derive(Debug, Clone)]
enum Edit {
    Truncate(usize),
    Flip(usize, u8),
    Insert(usize, u8),
}

fn apply(mut bytes: Vec<u8>, edits: &[Edit]) -> Vec<u8> {
    for e in edits {
        if bytes.is_empty() {
            break;
        }
        match *e {
            Edit::Truncate(at) => bytes.truncate(at % bytes.len()),
            Edit::Flip(at, x) => {
                let i = at % bytes.len();
                bytes[i] ^= x;
            }
            Edit::Insert(at, x) => {
                let i = at % bytes.len();
                bytes.insert(i, x);
            }
        }
    }
    bytes
}

fn edit() -> impl Strategy<Value = Edit> {
    prop_oneof![
        any::<usize>().prop_map(Edit::Truncate),
        (any::<usize>(), 1u8..=255).prop_map(|(a, x)| Edit::Flip(a, x)),
        (any::<usize>(), any::<u8>()).prop_map(|(a, x)| Edit::Insert(a, x)),
    ]
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(2000))]

    #[test]
    fn corrupted_files_give_a_mesh_or_a_named_error(
        which in 0usize..4,
        edits in prop::collection::vec(edit(), 1..4),
    ) {
        let (bytes, format, name) = match which {
            0 => (ply("ascii"), Format::Ply, "c.ply"),
            1 => (ply("binary_little_endian"), Format::Ply, "c.ply"),
            2 => (ply("binary_big_endian"), Format::Ply, "c.ply"),
            _ => (OBJ.to_vec(), Format::Obj, "c.obj"),
        };
        let bytes = apply(bytes, &edits);
        match parse(&bytes, format, Path::new(name)) {
            Ok(raw) => {
                // Whatever was read satisfies the loader's promises.
                prop_assert!(raw.positions.iter().all(|p| p.is_finite()));
                let n = raw.positions.len();
                prop_assert!(raw.triangles.iter().flatten().all(|&i| (i as usize) < n));
            }
            Err(e) => prop_assert!(e.to_string().starts_with(name), "{}", e),
        }
    }
}
