//! Exported levels: the writers keep every property their format holds
//! (and write a mesh without properties byte for byte as before), OBJ's
//! `.mtl` and PLY's texture comment, what `dropped_by` names, the
//! vertex-cache order, and (feature `gltf`) a LoD chain in one glTF file
//! read back level by level with the crate's own reader.

mod common;

use glam::Vec4;
use mts::mesh::generate::Generated;
use mts::mesh::io::{
    chain_from_collapses, dropped_by, load, order_for_cache, save_obj, save_ply, screen_coverages,
    Coverage, LoadOptions,
};
use mts::mesh::{Mesh, Texture};
use mts::simplify::{simplify, Collapses, SimplifyOptions};
use mts::strip::acmr::{fifo_acmr, CACHE_SIZE};
use std::path::Path;

fn generated(name: &str) -> Generated {
    name.parse().unwrap()
}

fn with_properties() -> LoadOptions {
    LoadOptions {
        properties: true,
        ..LoadOptions::default()
    }
}

fn fnv(path: &Path) -> u64 {
    mts::checksum::fnv1a64(&std::fs::read(path).unwrap())
}

/// The OBJ and PLY bytes of meshes without properties, full and at a tenth
/// of their triangles, as the writers wrote them before they gained
/// properties and textures (FNV-1a 64 of each file, recorded from the
/// writers of commit b2814bc): `scripts/output-hashes.sh` hashes such
/// outputs of the CLI.
#[test]
fn meshes_without_properties_are_written_as_before() {
    let dir = common::scratch("export", "unchanged");
    let pins: [(&str, [u64; 4]); 3] = [
        (
            "icosphere:20k",
            [
                0x456fbf570c481b18,
                0x06cc96325f3e0eee,
                0x31479515a1ec5912,
                0xb2741ed337855742,
            ],
        ),
        (
            "torus:5k",
            [
                0xf7eb10306e697c60,
                0xf2a3e0c9a1055095,
                0x975c2e1a14b57f30,
                0x6352a43cb754abc1,
            ],
        ),
        (
            "grid:2k",
            [
                0x49536bd0eefc110d,
                0x56265e75f0f71ba9,
                0xfe4467fd6883a3b9,
                0x4b377b151315c110,
            ],
        ),
    ];
    for (name, pin) in pins {
        let mesh = generated(name).build();
        let c = simplify(&mesh, &SimplifyOptions::default()).collapses;
        let level = c.mesh_at(&mesh, c.lod_for_ratio(0.1));
        let mut got = Vec::new();
        for m in [&mesh, &level] {
            save_obj(m, &dir.join("m.obj")).unwrap();
            save_ply(m, &dir.join("m.ply")).unwrap();
            got.extend([fnv(&dir.join("m.obj")), fnv(&dir.join("m.ply"))]);
        }
        assert_eq!(got, pin, "{name}");
        assert!(!dir.join("m.mtl").exists(), "no material without a texture");
    }
}

/// ```text
///  3---2
///  | / |   a square of two triangles, no properties: `v` and `f` lines
///  0---1
/// ```
#[test]
fn a_square_without_properties_is_v_and_f_lines() {
    let dir = common::scratch("export", "square");
    let mesh = Mesh {
        positions: vec![
            glam::Vec3::new(0.0, 0.0, 0.0),
            glam::Vec3::new(1.0, 0.0, 0.0),
            glam::Vec3::new(1.0, 1.0, 0.0),
            glam::Vec3::new(0.0, 1.0, 0.5),
        ],
        triangles: vec![[0, 1, 2], [0, 2, 3]],
        properties: Default::default(),
    };
    save_obj(&mesh, &dir.join("s.obj")).unwrap();
    assert_eq!(
        std::fs::read_to_string(dir.join("s.obj")).unwrap(),
        "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0.5\nf 1 2 3\nf 1 3 4\n"
    );
}

/// A grid with UVs, normals and colours, textured by `texture`.
fn textured_grid(texture: Texture) -> Mesh {
    let mut mesh = generated("grid:200").build_with_properties();
    mesh.properties.texture = Some(texture);
    mesh.validate().unwrap();
    mesh
}

/// A texture file in the OBJ's folder or below is referred to by its
/// relative path from the `.mtl` and reads back as the same file; one
/// outside is copied beside the OBJ. The OBJ has `vt`, `vn` and coloured
/// `v` lines.
#[test]
fn obj_refers_to_a_texture_file_through_its_mtl() {
    let dir = common::scratch("export", "obj_texture_file");
    std::fs::create_dir_all(dir.join("out/images")).unwrap();
    let png = dir.join("out/images/checker.png");
    std::fs::write(&png, common::PNG).unwrap();
    let mesh = textured_grid(Texture::File(png.clone()));
    let path = dir.join("out/m.obj");
    save_obj(&mesh, &path).unwrap();
    assert_eq!(
        std::fs::read_to_string(dir.join("out/m.mtl")).unwrap(),
        "newmtl textured\nKd 1 1 1\nmap_Kd images/checker.png\n"
    );
    assert!(!dir.join("out/m.png").exists(), "the file is referred to");
    let text = std::fs::read_to_string(&path).unwrap();
    assert!(
        text.starts_with("mtllib m.mtl\nusemtl textured\nv "),
        "{text:.80}"
    );
    let count = |prefix: &str| text.lines().filter(|l| l.starts_with(prefix)).count();
    let n = mesh.vertex_count();
    assert_eq!(
        (count("vt "), count("vn "), count("f ")),
        (n, n, mesh.triangle_count())
    );
    // `v x y z r g b`: six numbers.
    let first_v = text.lines().find(|l| l.starts_with("v ")).unwrap();
    assert_eq!(first_v.split_whitespace().count(), 7, "{first_v}");

    let (back, _) = load(&path, with_properties()).unwrap();
    let Some(Texture::File(file)) = &back.properties.texture else {
        panic!("{:?}", back.properties.texture);
    };
    assert_eq!(file.canonicalize().unwrap(), png.canonicalize().unwrap());
    // The reader numbers vertices by first use: the same corners, face
    // by face.
    assert_eq!(back.vertex_count(), n);
    assert_eq!(corners(&back), corners(&mesh));

    // Written into a folder beside the image's: a copy, named by the OBJ.
    std::fs::create_dir_all(dir.join("other")).unwrap();
    let path = dir.join("other/m.obj");
    save_obj(&mesh, &path).unwrap();
    assert_eq!(std::fs::read(dir.join("other/m.png")).unwrap(), common::PNG);
    assert!(std::fs::read_to_string(dir.join("other/m.mtl"))
        .unwrap()
        .ends_with("map_Kd m.png\n"));
    let (back, _) = load(&path, with_properties()).unwrap();
    assert_eq!(
        back.properties.texture,
        Some(Texture::File(dir.join("other/m.png")))
    );
}

/// Position, texture coordinate and normal of every corner, triangle by
/// triangle, as bits.
fn corners(m: &Mesh) -> Vec<[u32; 8]> {
    let p = &m.properties;
    let (uvs, normals) = (p.uvs.as_ref().unwrap(), p.normals.as_ref().unwrap());
    m.triangles
        .iter()
        .flatten()
        .map(|&v| {
            let v = v as usize;
            let (x, t, n) = (m.positions[v], uvs[v], normals[v]);
            [x.x, x.y, x.z, t.x, t.y, n.x, n.y, n.z].map(f32::to_bits)
        })
        .collect()
}

/// Embedded bytes, and a file whose relative path holds a space, are
/// written beside the OBJ as `<stem>.png`, white space made `_`.
#[test]
fn obj_writes_embedded_and_spaced_textures_beside_it() {
    let dir = common::scratch("export", "obj_texture_copy");
    let path = dir.join("my mesh.obj");
    let embedded = textured_grid(Texture::Embedded {
        mime: String::new(),
        bytes: common::PNG.to_vec(),
    });
    save_obj(&embedded, &path).unwrap();
    assert_eq!(std::fs::read(dir.join("my_mesh.png")).unwrap(), common::PNG);
    assert_eq!(
        std::fs::read_to_string(dir.join("my mesh.mtl")).unwrap(),
        "newmtl textured\nKd 1 1 1\nmap_Kd my_mesh.png\n"
    );
    let (back, _) = load(&path, with_properties()).unwrap();
    assert_eq!(
        back.properties.texture,
        Some(Texture::File(dir.join("my_mesh.png")))
    );

    std::fs::create_dir_all(dir.join("a b")).unwrap();
    std::fs::write(dir.join("a b/t.png"), common::PNG).unwrap();
    std::fs::remove_file(dir.join("my_mesh.png")).unwrap();
    let spaced = textured_grid(Texture::File(dir.join("a b/t.png")));
    save_obj(&spaced, &path).unwrap();
    assert_eq!(std::fs::read(dir.join("my_mesh.png")).unwrap(), common::PNG);
    assert!(std::fs::read_to_string(dir.join("my mesh.mtl"))
        .unwrap()
        .ends_with("map_Kd my_mesh.png\n"));
}

/// PLY names an embedded texture, written beside it, by MeshLab's
/// `comment TextureFile`; it reads back with the streams. A texture file
/// outside the PLY's folder is copied the same way.
#[test]
fn ply_writes_an_embedded_texture_beside_it() {
    let dir = common::scratch("export", "ply_texture");
    let mesh = textured_grid(Texture::Embedded {
        mime: "image/png".into(),
        bytes: common::PNG.to_vec(),
    });
    let path = dir.join("g.ply");
    save_ply(&mesh, &path).unwrap();
    assert_eq!(std::fs::read(dir.join("g.png")).unwrap(), common::PNG);
    let (back, _) = load(&path, with_properties()).unwrap();
    assert_eq!(
        back.properties.texture,
        Some(Texture::File(dir.join("g.png")))
    );
    assert_eq!(back.properties.uvs, mesh.properties.uvs);
    assert_eq!(back.properties.normals, mesh.properties.normals);
    assert!(back.properties.colors.is_some());

    std::fs::create_dir_all(dir.join("out")).unwrap();
    let outside = textured_grid(Texture::File(dir.join("g.png")));
    let path = dir.join("out/h.ply");
    save_ply(&outside, &path).unwrap();
    assert_eq!(std::fs::read(dir.join("out/h.png")).unwrap(), common::PNG);
    let (back, _) = load(&path, with_properties()).unwrap();
    assert_eq!(
        back.properties.texture,
        Some(Texture::File(dir.join("out/h.png")))
    );
}

#[test]
fn dropped_by_names_what_obj_cannot_hold() {
    // The generated grid's colours are opaque and one per point.
    let mut mesh = textured_grid(Texture::File("t.png".into()));
    for ext in ["obj", "ply", "glb", "gltf", "stl"] {
        assert!(dropped_by(&mesh, Path::new(&format!("m.{ext}"))).is_empty());
    }
    mesh.properties.colors.as_mut().unwrap()[3].w = 0.5;
    assert_eq!(dropped_by(&mesh, Path::new("m.OBJ")), ["colour alpha"]);
    assert!(dropped_by(&mesh, Path::new("m.ply")).is_empty());
    // The seamed torus: vertices of one point with other colours.
    let torus = generated("torus:500").build_with_properties();
    assert_eq!(dropped_by(&torus, Path::new("t.obj")), ["colour seams"]);
    let mut both = torus.clone();
    both.properties.colors.as_mut().unwrap()[0] = Vec4::new(1.0, 1.0, 1.0, 0.0);
    assert_eq!(
        dropped_by(&both, Path::new("t.obj")),
        ["colour alpha", "colour seams"]
    );
}

/// The reordered mesh is the same surface, its vertices numbered in order
/// of first use, and its FIFO-16 ACMR is below the input order's.
#[test]
fn order_for_cache_keeps_the_surface_and_numbers_by_first_use() {
    let mesh = generated("torus:5k").build_with_properties();
    let ordered = order_for_cache(&mesh);
    ordered.validate().unwrap();
    assert_eq!(ordered.vertex_count(), mesh.vertex_count());
    let mut next = 0;
    for &v in ordered.triangles.iter().flatten() {
        assert!(v <= next, "vertex {v} before {next}");
        next = next.max(v + 1);
    }
    let corners = |m: &Mesh| {
        let uvs = m.properties.uvs.as_ref().unwrap();
        let mut t: Vec<[[u32; 5]; 3]> = m
            .triangles
            .iter()
            .map(|t| {
                let c = t.map(|v| {
                    let (p, u) = (m.positions[v as usize], uvs[v as usize]);
                    [p.x, p.y, p.z, u.x, u.y].map(f32::to_bits)
                });
                // Rotated to its smallest corner: the same triangle.
                let k = (0..3).min_by_key(|&k| c[k]).unwrap();
                [c[k], c[(k + 1) % 3], c[(k + 2) % 3]]
            })
            .collect();
        t.sort_unstable();
        t
    };
    assert_eq!(corners(&ordered), corners(&mesh));
    let n = mesh.vertex_count();
    let before = fifo_acmr(&mesh.triangles, n, CACHE_SIZE);
    let after = fifo_acmr(&ordered.triangles, n, CACHE_SIZE);
    assert!(after < 0.75 && after < before, "{before} -> {after}");
}

/// The levels at the CLI's ratios 1, 0.5, 0.25, 0.1, 0.02 of a sequence.
fn chain_lods(c: &Collapses) -> Vec<usize> {
    let mut lods: Vec<usize> = [1.0, 0.5, 0.25, 0.1, 0.02]
        .iter()
        .map(|&r| c.lod_for_ratio(r))
        .collect();
    lods.dedup();
    lods
}

/// The level an engine following the hints draws at coverage `c` is the
/// coarsest level of the chain whose error spans at most the threshold,
/// which is the coarsest chain level at or before the core's
/// `lod_for_screen_error` LoD for the same view.
#[test]
fn screen_coverage_picks_the_level_the_core_would() {
    let mesh = generated("torus:4k").build();
    let collapses = simplify(&mesh, &SimplifyOptions::default()).collapses;
    let lods = chain_lods(&collapses);
    assert_eq!(lods.len(), 5);
    let levels = chain_from_collapses(&mesh, &collapses, &lods).unwrap();
    let errors: Vec<f32> = levels.iter().map(|l| l.error).collect();
    assert_eq!(errors[0], 0.0);
    let coverage = Coverage::default();
    let s = screen_coverages(&errors, &coverage);
    assert_eq!(s.len(), 5);
    assert_eq!(s[4], 0.0);
    assert!(s.windows(2).all(|w| w[0] > w[1]), "{s:?}");
    assert!(s[0] <= 1.0);
    let d = mesh.diagonal();
    for i in 1..=1000 {
        let c = i as f32 / 1000.0;
        // MSFT_lod: level 0 down to s[0], level k from s[k-1] down to s[k].
        let drawn = s.iter().position(|&t| c >= t).unwrap();
        let ppu = c * coverage.screen_height / d;
        let core = mts::lod_for_screen_error(&collapses, d, 1.0, ppu, coverage.pixel_threshold);
        let expected = lods.iter().rposition(|&l| l <= core).unwrap();
        assert_eq!(
            drawn, expected,
            "coverage {c}: core LoD {core}, chain {lods:?}"
        );
    }
    // Fine to coarse only.
    assert!(chain_from_collapses(&mesh, &collapses, &[3, 3]).is_err());
    assert!(chain_from_collapses(&mesh, &collapses, &[collapses.max_lod() + 1]).is_err());
    assert!(chain_from_collapses(&mesh, &collapses, &[]).is_err());
}

/// Our triangle order against meshoptimizer's `optimize_vertex_cache`, in
/// FIFO-16 ACMR on generated meshes (pinned: the order is deterministic).
#[cfg(feature = "peers")]
#[test]
fn vertex_cache_order_is_near_meshoptimizer_s() {
    let cases = [
        ("icosphere:20k", 0.7074, 0.6856),
        ("torus:5k", 0.7284, 0.6841),
        ("grid:2k", 0.6738, 0.6382),
    ];
    let measured: Vec<(f64, f64)> = cases
        .iter()
        .map(|(name, _, _)| {
            let mesh = generated(name).build();
            let n = mesh.vertex_count();
            let ours = mts::strip::cache_order::reorder_for_vertex_cache(&mesh.triangles, n);
            let theirs = mts::peers::meshopt::optimize_vertex_cache(&mesh.triangles, n);
            (
                fifo_acmr(&ours, n, CACHE_SIZE),
                fifo_acmr(&theirs, n, CACHE_SIZE),
            )
        })
        .collect();
    for ((name, ours_pin, theirs_pin), (ours, theirs)) in cases.iter().zip(&measured) {
        println!("{name}: ours {ours:.4}, meshoptimizer {theirs:.4}");
        assert!((ours - ours_pin).abs() < 5e-5, "{name}: ours {ours}");
        assert!(
            (theirs - theirs_pin).abs() < 5e-5,
            "{name}: theirs {theirs}"
        );
        assert!(*ours < 1.08 * theirs, "{name}: {ours} against {theirs}");
    }
}

#[cfg(feature = "gltf")]
mod gltf_chain {
    use super::*;
    use mts::mesh::io::{load_bytes, parse_gltf, save_gltf, save_lod_chain, ChainLevel, Encoding};
    use serde_json::{json, Value};

    /// The JSON and BIN chunks of a `.glb`.
    fn chunks(bytes: &[u8]) -> (Value, Vec<u8>) {
        let word = |at: usize| u32::from_le_bytes(bytes[at..at + 4].try_into().unwrap()) as usize;
        assert_eq!(&bytes[..4], b"glTF");
        assert_eq!(word(8), bytes.len());
        let json_len = word(12);
        let json = serde_json::from_slice(&bytes[20..20 + json_len]).unwrap();
        let bin_at = 20 + json_len;
        let bin = bytes[bin_at + 8..bin_at + 8 + word(bin_at)].to_vec();
        (json, bin)
    }

    /// A `.glb` of `json` and `bin`.
    fn glb(json: &Value, bin: &[u8]) -> Vec<u8> {
        let mut text = serde_json::to_vec(json).unwrap();
        text.resize(text.len().next_multiple_of(4), b' ');
        let total = 12 + 8 + text.len() + 8 + bin.len();
        let mut out = b"glTF".to_vec();
        for w in [2, total as u32, text.len() as u32] {
            out.extend(w.to_le_bytes());
        }
        out.extend(b"JSON");
        out.extend(&text);
        out.extend((bin.len() as u32).to_le_bytes());
        out.extend(b"BIN\0");
        out.extend(bin);
        out
    }

    /// A textured torus with every property, and its chain at the CLI's
    /// ratios.
    fn textured_chain() -> (Mesh, Vec<usize>, Vec<ChainLevel>) {
        let mut mesh = generated("torus:4k").build_with_properties();
        mesh.properties.texture = Some(Texture::Embedded {
            mime: "image/png".into(),
            bytes: common::PNG.to_vec(),
        });
        let collapses = simplify(&mesh, &SimplifyOptions::default()).collapses;
        let lods = chain_lods(&collapses);
        let levels = chain_from_collapses(&mesh, &collapses, &lods).unwrap();
        (mesh, lods, levels)
    }

    #[test]
    fn a_chain_reads_back_level_by_level() {
        let dir = common::scratch("export", "chain");
        let (mesh, lods, levels) = textured_chain();
        assert_eq!(lods.len(), 5, "{lods:?}");
        let path = dir.join("chain.glb");
        save_lod_chain(&levels, &Coverage::default(), &path, Encoding::Plain).unwrap();
        let bytes = std::fs::read(&path).unwrap();
        gltf::Gltf::from_slice(&bytes).expect("the gltf crate accepts the chain");
        let (json, bin) = chunks(&bytes);

        let n = levels.len();
        assert_eq!(json["extensionsUsed"], json!(["MSFT_lod"]));
        assert!(json.get("extensionsRequired").is_none());
        assert_eq!(json["scenes"], json!([{ "nodes": [0] }]));
        assert_eq!(
            json["nodes"][0]["extensions"]["MSFT_lod"]["ids"],
            json!([1, 2, 3, 4])
        );
        let coverage: Vec<f64> = json["nodes"][0]["extras"]["MSFT_screencoverage"]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_f64().unwrap())
            .collect();
        assert_eq!(coverage.len(), n);
        assert!(coverage.windows(2).all(|w| w[0] > w[1]), "{coverage:?}");
        assert_eq!(coverage[n - 1], 0.0);
        assert_eq!(json["materials"].as_array().unwrap().len(), 1);
        assert_eq!(json["images"].as_array().unwrap().len(), 1);

        for (k, level) in levels.iter().enumerate() {
            assert_eq!(json["nodes"][k]["mesh"], json!(k));
            let primitive = &json["meshes"][k]["primitives"][0];
            assert_eq!(primitive["material"], json!(0));
            let position = primitive["attributes"]["POSITION"].as_u64().unwrap() as usize;
            // The JSON says how many vertices: the level's, not the mesh's.
            assert_eq!(
                json["accessors"][position]["count"],
                json!(level.mesh.vertex_count())
            );
            // Level k alone: the same file with node k as the scene.
            let mut one = json.clone();
            one["scenes"] = json!([{ "nodes": [k] }]);
            let file = glb(&one, &bin);
            let name = dir.join(format!("level{k}.glb"));
            let raw = parse_gltf(&file, &name).unwrap();
            let expected = order_for_cache(&level.mesh);
            assert_eq!(raw.positions, expected.positions, "level {k}");
            assert_eq!(raw.triangles, expected.triangles, "level {k}");
            assert_eq!(
                raw.properties.uvs.as_ref().map(Vec::len),
                Some(expected.vertex_count())
            );
            assert_eq!(raw.properties.texture, mesh.properties.texture);
            // Exactly the vertices used, each at least once.
            let mut used = vec![false; raw.positions.len()];
            for &v in raw.triangles.iter().flatten() {
                used[v as usize] = true;
            }
            assert!(used.iter().all(|&u| u), "level {k}: an unused vertex");
            let (loaded, _) = load_bytes(&file, &name, with_properties()).unwrap();
            assert_eq!(
                loaded.triangle_count(),
                level.mesh.triangle_count(),
                "level {k}"
            );
        }
        let counts: Vec<usize> = levels.iter().map(|l| l.mesh.triangle_count()).collect();
        assert!(counts.windows(2).all(|w| w[0] > w[1]), "{counts:?}");
        assert_eq!(counts[0], mesh.triangle_count());

        // The default scene is the finest level: what a viewer without the
        // extension draws.
        let (whole, _) = load(&path, LoadOptions::default()).unwrap();
        assert_eq!(whole.triangle_count(), mesh.triangle_count());

        // A .gltf holds the same chain, its buffer beside it.
        save_lod_chain(
            &levels,
            &Coverage::default(),
            &dir.join("chain.gltf"),
            Encoding::Plain,
        )
        .unwrap();
        let text: Value =
            serde_json::from_slice(&std::fs::read(dir.join("chain.gltf")).unwrap()).unwrap();
        assert_eq!(text["buffers"][0]["uri"], "chain.bin");
        assert_eq!(
            text["nodes"][0]["extensions"],
            json["nodes"][0]["extensions"]
        );
    }

    #[test]
    fn bad_chains_are_refused() {
        let dir = common::scratch("export", "bad_chain");
        let (_, _, mut levels) = textured_chain();
        let path = dir.join("c.glb");
        assert!(save_lod_chain(&[], &Coverage::default(), &path, Encoding::Plain).is_err());
        let flat = Coverage {
            pixel_threshold: 0.0,
            ..Coverage::default()
        };
        assert!(save_lod_chain(&levels, &flat, &path, Encoding::Plain).is_err());
        assert!(save_lod_chain(
            &levels,
            &Coverage::default(),
            &dir.join("c.obj"),
            Encoding::Plain
        )
        .is_err());
        levels.swap(1, 3);
        let err =
            save_lod_chain(&levels, &Coverage::default(), &path, Encoding::Plain).unwrap_err();
        // Level 1 now has the error of level 3, more than level 2's.
        assert!(err.to_string().contains("level 2"), "{err}");
        assert!(!path.exists());
        // One level: plain glTF, no extension.
        save_lod_chain(&levels[..1], &Coverage::default(), &path, Encoding::Plain).unwrap();
        let (json, _) = chunks(&std::fs::read(&path).unwrap());
        assert!(json.get("extensionsUsed").is_none());
        assert!(json["nodes"][0].get("extensions").is_none());
    }

    /// A textured `.glb` round trip: material, texture and streams back.
    #[test]
    fn a_textured_glb_keeps_its_material_and_texture() {
        let dir = common::scratch("export", "textured_glb");
        let mesh = textured_grid(Texture::Embedded {
            mime: "image/png".into(),
            bytes: common::PNG.to_vec(),
        });
        let path = dir.join("g.glb");
        save_gltf(&mesh, &path).unwrap();
        let (json, _) = chunks(&std::fs::read(&path).unwrap());
        assert_eq!(
            json["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"]["index"],
            json!(0)
        );
        assert_eq!(json["meshes"][0]["primitives"][0]["material"], json!(0));
        let attributes = json["meshes"][0]["primitives"][0]["attributes"]
            .as_object()
            .unwrap();
        let names: Vec<&str> = attributes.keys().map(String::as_str).collect();
        assert_eq!(names, ["COLOR_0", "NORMAL", "POSITION", "TEXCOORD_0"]);
        let (back, _) = load(&path, with_properties()).unwrap();
        assert_eq!(back.properties.texture, mesh.properties.texture);
        // `v` is flipped on the way out and in: within half an ulp of 1.
        let (a, b) = (
            back.properties.uvs.unwrap(),
            mesh.properties.uvs.clone().unwrap(),
        );
        assert!(a
            .iter()
            .zip(&b)
            .all(|(s, t)| s.abs_diff_eq(*t, 2f32.powi(-25))));
        assert_eq!(back.properties.normals, mesh.properties.normals);
        assert_eq!(back.properties.colors, mesh.properties.colors);
        assert_eq!(back.triangles, mesh.triangles);
    }

    /// A zero normal ("none") is written as its point's area-weighted
    /// normal: glTF normals are unit length.
    #[test]
    fn zero_normals_are_written_as_face_normals() {
        let dir = common::scratch("export", "zero_normals");
        let mut mesh = generated("grid:50").build_with_properties();
        mesh.properties.normals.as_mut().unwrap()[7] = glam::Vec3::ZERO;
        let path = dir.join("z.glb");
        save_gltf(&mesh, &path).unwrap();
        let raw = parse_gltf(&std::fs::read(&path).unwrap(), &path).unwrap();
        // The grid lies in z = 0, counter-clockwise seen from +z.
        assert!(raw
            .properties
            .normals
            .unwrap()
            .iter()
            .all(|&n| n == glam::Vec3::Z));
    }

    /// glTF outputs of the writers before they were split into pieces for
    /// the chain (FNV-1a 64 of the `.glb`, and of the `.gltf` then its
    /// `.bin`; recorded from the writer of commit b2814bc).
    #[test]
    fn gltf_outputs_are_unchanged() {
        let dir = common::scratch("export", "gltf_unchanged");
        let pins = [
            (
                "torus:5k",
                [
                    0x88422cb4a1438766,
                    0x21cc362f765331a9,
                    0x79eee64332f927bb,
                    0x7744e5e77b9697e1,
                ],
            ),
            (
                "grid:2k",
                [
                    0x0e5702beb31a292d,
                    0x25c0b92fdc483509,
                    0x5936c030556ba52e,
                    0x31e046895ad8f7fe,
                ],
            ),
            (
                "icosphere:5k",
                [
                    0x18c9a8c8a1f9e05a,
                    0x72e67e862d304e78,
                    0x7b0ebc4a859f0ce9,
                    0xb39089a27063595c,
                ],
            ),
        ];
        for (name, pin) in pins {
            let g = generated(name);
            let mut with = g.build_with_properties();
            with.properties.texture = Some(Texture::Embedded {
                mime: String::new(),
                bytes: b"\x89PNG\r\n\x1a\nxxxx".to_vec(),
            });
            let mut got = Vec::new();
            for m in [g.build(), with] {
                for ext in ["glb", "gltf"] {
                    let p = dir.join(format!("a.{ext}"));
                    save_gltf(&m, &p).unwrap();
                    let mut bytes = std::fs::read(&p).unwrap();
                    if ext == "gltf" {
                        bytes.extend(std::fs::read(dir.join("a.bin")).unwrap());
                    }
                    got.push(mts::checksum::fnv1a64(&bytes));
                }
            }
            assert_eq!(got, pin, "{name}");
        }
    }
}
