//! `mts render` of a glTF scene (issue 32, item 3): five textured or
//! coloured quads under their own nodes, one mesh under two, drawn headless
//! as a scene of parts; each part's colour is checked where the camera the
//! command reports puts its node.

mod common;

use common::{json, mts};
use glam::{Mat4, Vec3};
use mts_render::Image;
use serde_json::{json as j, Value};
use std::path::{Path, PathBuf};

/// Standard base64 with padding.
fn base64(bytes: &[u8]) -> String {
    const ALPHABET: &[u8] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut out = String::new();
    for group in bytes.chunks(3) {
        let b = [
            group[0],
            *group.get(1).unwrap_or(&0),
            *group.get(2).unwrap_or(&0),
        ];
        let n = u32::from(b[0]) << 16 | u32::from(b[1]) << 8 | u32::from(b[2]);
        for k in 0..4 {
            if k <= group.len() {
                out.push(ALPHABET[(n >> (18 - 6 * k) & 63) as usize] as char);
            } else {
                out.push('=');
            }
        }
    }
    out
}

/// A fresh folder for one test.
fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("mts-gltf-scene-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// sRGB bytes of the four textures (2 × 2, one colour each).
const TEXTURES: [[u8; 3]; 4] = [[255, 0, 0], [0, 255, 0], [0, 0, 255], [255, 255, 0]];

/// The base-colour factor of the untextured mesh (linear RGB).
const FACTOR: [f32; 3] = [0.8, 0.1, 0.9];

/// Where the nodes put their meshes, and whether they mirror them (scale
/// -1 in x): node `i` holds mesh `i`, node 5 mesh 0 again, node 6 mesh 1
/// mirrored.
const NODES: [(usize, [f32; 3], bool); 7] = [
    (0, [-3.0, 0.0, 0.0], false),
    (1, [-1.5, 0.0, 0.0], false),
    (2, [0.0, 0.0, 0.0], false),
    (3, [1.5, 0.0, 0.0], false),
    (4, [3.0, 0.0, 0.0], false),
    (0, [0.0, 1.5, 0.0], false),
    (1, [0.0, -1.5, 0.0], true),
];

//  3 --- 2
//  |   / |   each mesh: a unit quad in z = 0 centred on its node,
//  | /   |   counter-clockwise seen from +z (the camera's side); meshes
//  0 --- 1   0-3 with TEXCOORD_0 and a texture, mesh 4 with neither and a
//            material base-colour factor.
//
// `meshes` of them (the first ones) under the first `nodes` nodes, in a
// `.gltf` with the buffer and the PNGs as data URIs.
fn scene_file(dir: &Path, meshes: usize, nodes: usize) -> PathBuf {
    let floats: [f32; 20] = [
        -0.5, -0.5, 0.0, 0.5, -0.5, 0.0, 0.5, 0.5, 0.0, -0.5, 0.5, 0.0, // positions
        0.0, 1.0, 1.0, 1.0, 1.0, 0.0, 0.0, 0.0, // texture coordinates (v down)
    ];
    let mut bin: Vec<u8> = floats.iter().flat_map(|x| x.to_le_bytes()).collect();
    bin.extend([0u16, 1, 2, 0, 2, 3].iter().flat_map(|x| x.to_le_bytes()));
    let images: Vec<Value> = TEXTURES
        .iter()
        .enumerate()
        .map(|(i, &[r, g, b])| {
            let png = dir.join(format!("texture{i}.png"));
            Image {
                width: 2,
                height: 2,
                rgba: [r, g, b, 255].repeat(4),
            }
            .save_png(&png)
            .unwrap();
            let bytes = std::fs::read(&png).unwrap();
            j!({ "uri": format!("data:image/png;base64,{}", base64(&bytes)) })
        })
        .collect();
    let mut materials: Vec<Value> = (0..4)
        .map(|i| j!({ "pbrMetallicRoughness": { "baseColorTexture": { "index": i } } }))
        .collect();
    let [r, g, b] = FACTOR;
    materials.push(j!({ "pbrMetallicRoughness": { "baseColorFactor": [r, g, b, 1.0] } }));
    let mesh = |i: usize| {
        let attributes = if i < 4 {
            j!({ "POSITION": 0, "TEXCOORD_0": 1 })
        } else {
            j!({ "POSITION": 0 })
        };
        j!({
            "name": format!("quad {i}"),
            "primitives": [{ "attributes": attributes, "indices": 2, "material": i }],
        })
    };
    let body = j!({
        "asset": { "version": "2.0" },
        "buffers": [{
            "byteLength": bin.len(),
            "uri": format!("data:application/octet-stream;base64,{}", base64(&bin)),
        }],
        "bufferViews": [
            { "buffer": 0, "byteOffset": 0, "byteLength": 48 },
            { "buffer": 0, "byteOffset": 48, "byteLength": 32 },
            { "buffer": 0, "byteOffset": 80, "byteLength": 12 },
        ],
        "accessors": [
            { "bufferView": 0, "componentType": 5126, "type": "VEC3", "count": 4,
              "min": [-0.5, -0.5, 0.0], "max": [0.5, 0.5, 0.0] },
            { "bufferView": 1, "componentType": 5126, "type": "VEC2", "count": 4 },
            { "bufferView": 2, "componentType": 5123, "type": "SCALAR", "count": 6 },
        ],
        "images": images,
        "samplers": [{}],
        "textures": (0..4).map(|i| j!({ "source": i, "sampler": 0 })).collect::<Vec<_>>(),
        "materials": materials,
        "meshes": (0..meshes).map(mesh).collect::<Vec<_>>(),
        "nodes": NODES[..nodes]
            .iter()
            .map(|&(m, t, mirror)| {
                let x = if mirror { -1.0 } else { 1.0 };
                j!({ "mesh": m, "translation": t, "scale": [x, 1.0, 1.0] })
            })
            .collect::<Vec<_>>(),
        "scenes": [{ "nodes": (0..nodes).collect::<Vec<_>>() }],
        "scene": 0,
    });
    let path = dir.join(format!("scene{meshes}.gltf"));
    std::fs::write(&path, serde_json::to_vec_pretty(&body).unwrap()).unwrap();
    path
}

/// Runs `mts render` with `args`; `None` (the test skipped, with a
/// message) when there is no adapter and `MTS_REQUIRE` does not name gpu.
fn render(args: &[&str]) -> Option<Value> {
    let (ok, out, err) = mts(&[&["render"][..], args, &["--json"]].concat());
    if common::skipped_without_adapter(ok, &err) {
        return None;
    }
    assert!(ok, "{err}");
    Some(json(&out))
}

/// A linear colour as the sRGB bytes the target stores.
fn srgb(linear: Vec3) -> [u8; 3] {
    let encode = |c: f32| {
        let c = c.clamp(0.0, 1.0);
        let s = if c <= 0.003_130_8 {
            12.92 * c
        } else {
            1.055 * c.powf(1.0 / 2.4) - 0.055
        };
        (s * 255.0).round() as u8
    };
    [encode(linear.x), encode(linear.y), encode(linear.z)]
}

fn srgb_to_linear(c: u8) -> f32 {
    let c = f32::from(c) / 255.0;
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

/// Every part drawn with its own texture (or, without texture
/// coordinates, its material's base colour) where its node is; the mesh
/// under two nodes is one part with two instances, the one under a mirror
/// a second model with its winding reversed, lit as the unmirrored one
/// (the mirror in x keeps the quad facing +z); the JSON lists the parts
/// with their triangles.
#[test]
fn each_part_is_drawn_with_its_texture_at_its_node() {
    let dir = scratch("five");
    let file = scene_file(&dir, 5, 7);
    let png = dir.join("scene.png");
    let Some(report) = render(&[
        file.to_str().unwrap(),
        "--size",
        "640x480",
        "-o",
        png.to_str().unwrap(),
    ]) else {
        return;
    };
    assert_eq!(report["part_count"], 5, "{report}");
    assert_eq!(report["instances"], 7);
    assert_eq!(report["visible"], 7);
    // Every instance of a 2-triangle quad at full detail: its first
    // contraction changes its outline by far more than a pixel.
    assert_eq!(report["triangles"], 14);
    assert_eq!(report["triangles_full_detail"], 14);
    assert_eq!(report["pixel_threshold"], 1.0);
    let parts = report["parts"].as_array().unwrap();
    // The models: mesh 1's mirrored one right after its own.
    let models = [
        (0, false, 2),
        (1, false, 1),
        (1, true, 1),
        (2, false, 1),
        (3, false, 1),
        (4, false, 1),
    ];
    assert_eq!(parts.len(), models.len(), "{report}");
    for (part, (mesh, mirrored, instances)) in parts.iter().zip(models) {
        assert_eq!(part["mesh"], mesh, "{part}");
        assert_eq!(part["primitive"], 0, "{part}");
        assert_eq!(part["name"], format!("quad {mesh}"), "{part}");
        assert_eq!(part["triangles"], 2, "{part}");
        assert_eq!(part["mirrored"], mirrored, "{part}");
        assert_eq!(part["lods"], j!(vec![0; instances]), "{part}");
        let texture = if mesh < 4 { j!([2, 2]) } else { Value::Null };
        assert_eq!(part["texture"], texture, "{part}");
    }

    // The camera the command drew with, and the colour a quad facing +z
    // gets under its light: albedo × (ambient + diffuse).
    let floats = |v: &Value| -> Vec<f32> {
        v.as_array()
            .unwrap()
            .iter()
            .map(|x| x.as_f64().unwrap() as f32)
            .collect()
    };
    let view_proj = Mat4::from_cols_slice(&floats(&report["camera"]["view_proj"]));
    let light = Vec3::from_slice(&floats(&report["camera"]["light_dir"]));
    let shade = 0.18 + 0.82 * Vec3::Z.dot(light).max(0.0);
    let image = Image::read_png(&png).unwrap();
    assert_eq!((image.width, image.height), (640, 480));
    let pixel = |p: Vec3| {
        let ndc = view_proj.project_point3(p);
        let x = ((ndc.x + 1.0) * 0.5 * image.width as f32) as usize;
        let y = ((1.0 - ndc.y) * 0.5 * image.height as f32) as usize;
        let at = 4 * (y * image.width as usize + x);
        [image.rgba[at], image.rgba[at + 1], image.rgba[at + 2]]
    };
    for (node, &(mesh, t, _)) in NODES.iter().enumerate() {
        let albedo = match TEXTURES.get(mesh) {
            Some(rgb) => Vec3::from_array(rgb.map(srgb_to_linear)),
            None => Vec3::from_array(FACTOR),
        };
        let want = srgb(albedo * shade);
        // Inside each of the quad's two triangles, off their shared
        // diagonal.
        for offset in [Vec3::new(0.25, -0.1, 0.0), Vec3::new(-0.25, 0.1, 0.0)] {
            let got = pixel(Vec3::from_array(t) + offset);
            let close = got.iter().zip(want).all(|(g, w)| g.abs_diff(w) <= 2);
            assert!(
                close,
                "node {node} (mesh {mesh}) at {offset}: {got:?}, want {want:?}"
            );
        }
    }
    // Nothing drawn between the quads (0.5 apart): the background.
    let between = pixel(Vec3::new(-0.75, 0.0, 0.0));
    assert_eq!(between, [image.rgba[0], image.rgba[1], image.rgba[2]]);
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A file of one part keeps the one-model path (a LoD, a method); a scene
/// refuses what chooses one model's LoD, and one model refuses
/// `--pixel-error`.
#[test]
fn one_part_keeps_the_one_model_path_and_flags_are_checked() {
    let dir = scratch("one");
    let one = scene_file(&dir, 1, 1);
    let five = scene_file(&dir, 5, 7);
    let png = dir.join("out.png");
    let png = png.to_str().unwrap();
    let Some(report) = render(&[one.to_str().unwrap(), "-o", png]) else {
        return;
    };
    assert_eq!(report["method"], "mts", "{report}");
    assert_eq!(report["triangles"], 2);
    assert!(report.get("part_count").is_none(), "{report}");

    let (ok, _, err) = mts(&["render", five.to_str().unwrap(), "--lod", "1", "-o", png]);
    assert!(
        !ok && err.contains("5 parts") && err.contains("--pixel-error"),
        "{err}"
    );
    let (ok, _, err) = mts(&[
        "render",
        five.to_str().unwrap(),
        "--method",
        "list",
        "-o",
        png,
    ]);
    assert!(!ok && err.contains("--method"), "{err}");
    let (ok, _, err) = mts(&[
        "render",
        one.to_str().unwrap(),
        "--pixel-error",
        "2",
        "-o",
        png,
    ]);
    assert!(!ok && err.contains("--pixel-error chooses"), "{err}");
    std::fs::remove_dir_all(&dir).unwrap();
}
