//! The `mts` command's model subcommands end to end: `build --json` keys,
//! `extract` at a LoD, triangle budget and ratio, `verify` passing on a
//! sound model and failing (non-zero exit, named place) on a corrupt file;
//! `simplify --regions`.

mod common;

use common::{json, mts};

#[test]
fn build_extract_verify_round_trip() {
    let dir = std::env::temp_dir().join(format!("mts-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("torus.mts");
    let file = file.to_str().unwrap();
    let (ok, out, err) = mts(&["build", "--generated", "torus:5k", "-o", file, "--json"]);
    assert!(ok, "{err}");
    let b = json(&out);
    let triangles = b["triangles"].as_u64().unwrap();
    // The generator rounds to whole rings: 70 x 35 quads.
    assert_eq!(triangles, 4900);
    let vertices = b["vertices"].as_u64().unwrap();
    assert_eq!(vertices, 2450);
    assert_eq!(
        b["raw_bytes"].as_u64().unwrap(),
        12 * vertices + 12 * triangles
    );
    assert_eq!(
        b["bytes"].as_u64().unwrap(),
        std::fs::metadata(file).unwrap().len()
    );
    let max_lod = b["max_lod"].as_u64().unwrap();
    assert!(max_lod > 2000, "a torus simplifies far: {max_lod}");
    assert!(b["strips"].as_u64().unwrap() >= 1);
    assert!(b["ms"].as_f64().unwrap() > 0.0);

    let (ok, out, err) = mts(&["extract", file, "--lod", "0", "--json"]);
    assert!(ok, "{err}");
    let e = json(&out);
    assert_eq!(e["lod"].as_u64(), Some(0));
    assert_eq!(e["triangles"].as_u64(), Some(triangles));
    let indices = e["indices"].as_u64().unwrap();
    assert!(
        indices > triangles && indices < triangles * 3 / 2,
        "{indices}"
    );
    assert!(e["strips"].as_u64().unwrap() >= 1);
    assert!(e["us"].as_f64().unwrap() > 0.0);

    let (ok, out, _) = mts(&["extract", file, "--triangles", "1000", "--json"]);
    assert!(ok);
    let e = json(&out);
    assert!(e["triangles"].as_u64().unwrap() <= 1000);
    assert!(e["triangles"].as_u64().unwrap() >= 990);
    let (ok, out, _) = mts(&["extract", file, "--ratio", "0.5", "--json"]);
    assert!(ok);
    assert!(json(&out)["triangles"].as_u64().unwrap() <= 2500);

    let (ok, out, err) = mts(&["verify", file, "--lods", "all", "--json"]);
    assert!(ok, "{err}");
    let v = json(&out);
    assert_eq!(v["lods_checked"].as_u64(), Some(max_lod + 1));
    assert_eq!(v["mismatches"].as_u64(), Some(0));

    // A flipped byte in the middle: the checksum catches it, the exit
    // status says so and the message names the file.
    let mut bytes = std::fs::read(file).unwrap();
    let mid = bytes.len() / 2;
    bytes[mid] ^= 0x40;
    let bad = dir.join("bad.mts");
    std::fs::write(&bad, bytes).unwrap();
    let (ok, _, err) = mts(&["verify", bad.to_str().unwrap(), "--json"]);
    assert!(!ok);
    assert!(err.contains("bad.mts"), "{err}");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Issue 34: `build` writes the coded file (version 5) by default, the
/// uncoded one (version 3) with `--uncompressed`, at another level with
/// `--level`; the three load to the same model (the same indices at every
/// level `info` prints) and `info` names the version.
#[test]
fn build_writes_the_coded_file_by_default() {
    let dir = std::env::temp_dir().join(format!("mts-cli-coded-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = |name: &str| dir.join(name).to_str().unwrap().to_string();
    let mut sizes = Vec::new();
    let mut levels = Vec::new();
    for (name, extra) in [
        ("coded.mts", vec![]),
        ("plain.mts", vec!["--uncompressed"]),
        ("fast.mts", vec!["--level", "1"]),
    ] {
        let out = path(name);
        let mut args = vec!["build", "--generated", "torus:5k", "-o", &out, "--json"];
        args.extend(extra.iter().copied());
        let (ok, text, err) = mts(&args);
        assert!(ok, "{name}: {err}");
        let b = json(&text);
        assert_eq!(
            b["bytes"].as_u64().unwrap(),
            std::fs::metadata(&out).unwrap().len()
        );
        let (ok, info, err) = mts(&["info", &out, "--json"]);
        assert!(ok, "{name}: {err}");
        let info = json(&info);
        assert_eq!(info["file_version"], b["file_version"], "{name}");
        sizes.push((
            b["file_version"].as_u64().unwrap(),
            b["bytes"].as_u64().unwrap(),
        ));
        levels.push(info["levels"].clone());
    }
    assert_eq!(sizes[0].0, 6);
    assert_eq!(sizes[1].0, 3);
    assert_eq!(sizes[2].0, 6);
    assert!(sizes[0].1 * 2 < sizes[1].1, "{sizes:?}");
    assert!(sizes[0].1 <= sizes[2].1, "level 17 against 1: {sizes:?}");
    assert_eq!(levels[0], levels[1]);
    assert_eq!(levels[0], levels[2]);
    // A level outside Zstandard's and a level with the uncoded file are
    // refused by the argument parser.
    let out = path("x.mts");
    for bad in [
        vec!["--level", "0"],
        vec!["--level", "23"],
        vec!["--level", "9", "--uncompressed"],
    ] {
        let mut args = vec!["build", "--generated", "torus:200", "-o", &out];
        args.extend(bad.iter().copied());
        let (ok, _, err) = mts(&args);
        assert!(!ok && err.contains("--level"), "{bad:?}: {err}");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// `build` writes chunks at 1% and 10% (`prefixes` in its JSON and
/// `info`'s); `extract --bytes N` opens the finest chunk the first N bytes
/// hold (`lods_available`), draws the same triangle count as the whole
/// file at a LoD they hold, and refuses fewer bytes than the first chunk;
/// `verify` checks the chunks; `--prefixes none` writes none.
#[test]
fn a_prefix_of_the_built_file_opens_its_coarse_lods() {
    let dir = std::env::temp_dir().join(format!("mts-cli-prefix-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let out = dir.join("t.mts").to_str().unwrap().to_string();
    let (ok, text, err) = mts(&["build", "--generated", "torus:20k", "-o", &out, "--json"]);
    assert!(ok, "{err}");
    let b = json(&text);
    let chunks = b["prefixes"].as_array().unwrap().clone();
    assert_eq!(chunks.len(), 2, "{chunks:?}");
    let full = b["triangles"].as_u64().unwrap();
    let tenth = &chunks[1];
    assert!(tenth["triangles"].as_u64().unwrap() <= full / 10);
    let end = tenth["bytes"].as_u64().unwrap();
    assert!(end * 100 <= b["bytes"].as_u64().unwrap() * 15, "{tenth}");
    let (ok, info, _) = mts(&["info", &out, "--json"]);
    assert!(ok);
    assert_eq!(json(&info)["prefixes"], b["prefixes"]);
    let extract = |n: u64, ratio: &str| {
        let n = n.to_string();
        mts(&[
            "extract", &out, "--bytes", &n, "--ratio", ratio, "--json", "--repeat", "1",
        ])
    };
    let (ok, text, err) = extract(end, "0.1");
    assert!(ok && !err.contains("not in the first"), "{err}");
    let p = json(&text);
    let first = tenth["first_lod"].as_u64().unwrap();
    assert_eq!(p["lods_available"][0].as_u64().unwrap(), first);
    assert_eq!(p["lods_available"][1], b["max_lod"]);
    assert_eq!(p["whole"], false);
    assert_eq!(p["bytes_used"].as_u64().unwrap(), end);
    let lod = p["lod"].as_u64().unwrap().to_string();
    let (ok, whole, _) = mts(&["extract", &out, "--lod", &lod, "--json", "--repeat", "1"]);
    assert!(ok);
    assert_eq!(json(&whole)["triangles"], p["triangles"]);
    // A finer LoD than the prefix holds draws its first, and says so.
    let (ok, text, err) = extract(end, "1");
    assert!(ok && err.contains("not in the first"), "{err}");
    assert_eq!(json(&text)["lod"].as_u64().unwrap(), first);
    // The whole file, and fewer bytes than the first chunk.
    let (ok, text, _) = extract(u64::MAX, "1");
    assert!(ok && json(&text)["whole"] == true);
    let (ok, _, err) = extract(100, "0.1");
    assert!(
        !ok && err.contains("t.mts") && err.contains("no whole chunk"),
        "{err}"
    );
    let (ok, text, err) = mts(&["verify", &out, "--json"]);
    assert!(ok, "{err}");
    assert_eq!(json(&text)["prefixes_checked"], 2);
    let (ok, text, _) = mts(&[
        "build",
        "--generated",
        "torus:2k",
        "-o",
        &out,
        "--json",
        "--prefixes",
        "none",
    ]);
    assert!(ok && json(&text)["prefixes"].as_array().unwrap().is_empty());
    let (ok, _, err) = mts(&[
        "build",
        "--generated",
        "torus:2k",
        "-o",
        &out,
        "--prefixes",
        "0",
    ]);
    assert!(!ok && err.contains("--prefixes"), "{err}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn verify_takes_a_mesh_and_spread_lods() {
    let (ok, out, err) = mts(&[
        "verify",
        "--generated",
        "icosphere:3k",
        "--lods",
        "25",
        "--json",
    ]);
    assert!(ok, "{err}");
    let v = json(&out);
    assert_eq!(v["lods_checked"].as_u64(), Some(25));
    assert_eq!(v["mismatches"].as_u64(), Some(0));
    let (ok, _, err) = mts(&["verify", "--generated", "icosphere:3k", "--lods", "many"]);
    assert!(!ok);
    assert!(err.contains("--lods"), "{err}");
}

#[test]
fn encode_decode_and_extract_with_every_method() {
    let dir = std::env::temp_dir().join(format!("mts-cli-stream-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("torus.stream");
    let file = file.to_str().unwrap();
    let (ok, out, err) = mts(&["encode", "--generated", "torus:2k", "-o", file, "--json"]);
    assert!(ok, "{err}");
    let e = json(&out);
    assert_eq!(e["vertices"].as_u64(), Some(968));
    assert_eq!(e["triangles"].as_u64(), Some(1936));
    assert_eq!(e["raw_bytes_u16"].as_u64(), Some(12 * 968 + 6 * 1936));
    let bytes = e["bytes"].as_u64().unwrap();
    assert_eq!(bytes, std::fs::metadata(file).unwrap().len());
    assert!(bytes < 12 * 968 + 6 * 1936);

    let (ok, out, err) = mts(&["decode", file, "--json"]);
    assert!(ok, "{err}");
    let d = json(&out);
    assert_eq!(d["vertices"].as_u64(), Some(968));
    assert_eq!(d["triangles"].as_u64(), Some(1936));
    assert_eq!(d["complete"].as_bool(), Some(true));
    assert_eq!(d["bytes_used"].as_u64(), Some(bytes));

    let (ok, out, err) = mts(&["decode", file, "--bytes", "4000", "--json"]);
    assert!(ok, "{err}");
    let p = json(&out);
    assert_eq!(p["complete"].as_bool(), Some(false));
    assert!(p["bytes_used"].as_u64().unwrap() <= 4000);
    let partial = p["triangles"].as_u64().unwrap();
    assert!(partial > 0 && partial < 1936, "{partial}");

    // A truncated stream without --bytes is an error naming the file.
    let cut = dir.join("cut.stream");
    let all = std::fs::read(file).unwrap();
    std::fs::write(&cut, &all[..all.len() / 2]).unwrap();
    let (ok, _, err) = mts(&["decode", cut.to_str().unwrap()]);
    assert!(!ok);
    assert!(err.contains("cut.stream"), "{err}");

    for method in ["mts", "pm", "multilevel", "cluster", "discrete"] {
        let (ok, out, err) = mts(&[
            "extract",
            "--generated",
            "torus:2k",
            "--method",
            method,
            "--ratio",
            "0.5",
            "--repeat",
            "1",
            "--json",
        ]);
        assert!(ok, "{method}: {err}");
        let x = json(&out);
        let triangles = x["triangles"].as_u64().unwrap();
        // At most half of the 1936 triangles, except discrete LoDs, which
        // answer with the coarsest level at or above the budget.
        if method == "discrete" {
            assert!(triangles >= 968, "{method}: {triangles}");
        } else {
            assert!(triangles <= 968 && triangles > 900, "{method}: {triangles}");
        }
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// `encode` and `compare` take `--properties`: the stream carries the
/// property streams (decoded back into the written mesh) and the raw
/// reference counts them; `demo` still refuses them.
#[test]
fn baselines_take_properties() {
    let dir = std::env::temp_dir().join(format!("mts-cli-props-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let stream = dir.join("torus.stream");
    let stream = stream.to_str().unwrap();
    let src = ["--generated", "torus:500", "--properties"];
    let (ok, out, err) = mts(&[&["encode"][..], &src, &["-o", stream, "--json"]].concat());
    assert!(ok, "{err}");
    let e = json(&out);
    let (v, t) = (
        e["vertices"].as_u64().unwrap(),
        e["triangles"].as_u64().unwrap(),
    );
    // Normals, UVs and colours: 36 bytes per vertex on top of the mesh.
    assert_eq!(e["raw_bytes_u16"].as_u64(), Some((12 + 36) * v + 6 * t));
    let obj = dir.join("back.obj");
    let (ok, _, err) = mts(&["decode", stream, "-o", obj.to_str().unwrap()]);
    assert!(ok, "{err}");
    let text = std::fs::read_to_string(&obj).unwrap();
    assert!(
        text.lines().any(|l| l.starts_with("vt ")),
        "no texture coordinates"
    );
    assert!(text.lines().any(|l| l.starts_with("vn ")), "no normals");
    let (ok, out, err) = mts(&[&["compare"][..], &src, &["--requests", "5", "--json"]].concat());
    assert!(ok, "{err}");
    let methods = json(&out)["methods"].as_array().unwrap().len();
    assert!(methods >= 4, "{out}");
    let (ok, _, err) = mts(&[&["demo"][..], &src].concat());
    assert!(!ok && err.contains("--properties"), "{err}");
    std::fs::remove_dir_all(&dir).ok();
}

/// `mts render --scene` (issue 22): every visible instance at full detail
/// with 0 pixels, fewer triangles at 2, the keys a host reads; where there
/// is no adapter the command says so (an error unless `MTS_REQUIRE` names
/// gpu, as in CI, where it must run).
#[test]
fn render_scene_reports_shared_buckets_by_screen_error() {
    let dir = std::env::temp_dir().join(format!("mts-scene-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let png = dir.join("scene.png");
    let run = |px: &str| {
        mts(&[
            "render",
            "--generated",
            "torus:2k",
            "--scene",
            "64",
            "--pixel-error",
            px,
            "--json",
            "-o",
            png.to_str().unwrap(),
        ])
    };
    let (ok, out, err) = run("0");
    if common::skipped_without_adapter(ok, &err) {
        return;
    }
    assert!(ok, "{err}");
    let full = json(&out);
    assert_eq!(full["pixel_threshold"], 0.0);
    assert_eq!(full["triangles"], full["triangles_full_detail"]);
    assert_eq!(full["draws"], 1);
    let (ok, out, err) = run("2");
    assert!(ok, "{err}");
    let coarse = json(&out);
    assert_eq!(coarse["visible"], full["visible"]);
    assert!(
        coarse["triangles"].as_u64() < full["triangles"].as_u64(),
        "{coarse}"
    );
    for key in ["cpu_bytes_per_instance", "gpu_bytes", "buffers", "draws"] {
        assert!(
            coarse[key].as_u64().is_some_and(|v| v > 0),
            "{key}: {coarse}"
        );
    }
    assert!(
        coarse["cpu_bytes_per_instance"].as_u64().unwrap() <= 256,
        "{coarse}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

/// `mts lods` (issue 32): a chain of five levels in one `.glb`, finest
/// first, each with fewer triangles and only its own vertices, screen
/// coverages falling to 0; the file read back by the project's reader is
/// the finest level (the node a viewer without `MSFT_lod` draws), with
/// its properties; a share above 1 is refused.
#[test]
fn lods_writes_a_chain_that_reads_back() {
    let dir = std::env::temp_dir().join(format!("mts-cli-lods-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let glb = dir.join("chain.glb");
    let glb = glb.to_str().unwrap();
    let src = ["--generated", "torus:5k", "--properties"];
    let (ok, out, err) = mts(&[&["lods"][..], &src, &["-o", glb, "--json"]].concat());
    assert!(ok, "{err}");
    let v = json(&out);
    let levels = v["levels"].as_array().unwrap();
    assert_eq!(levels.len(), 5, "{out}");
    let n = |l: &serde_json::Value, k: &str| l[k].as_u64().unwrap();
    assert_eq!(n(&levels[0], "triangles"), 4900);
    for w in levels.windows(2) {
        assert!(n(&w[1], "triangles") < n(&w[0], "triangles"), "{out}");
        assert!(n(&w[1], "vertices") < n(&w[0], "vertices"), "{out}");
        let c = |l: &serde_json::Value| l["screen_coverage"].as_f64().unwrap();
        assert!(c(&w[1]) <= c(&w[0]), "{out}");
    }
    assert_eq!(levels[4]["screen_coverage"].as_f64(), Some(0.0));
    // At most 2% of the triangles at the last level.
    assert!(n(&levels[4], "triangles") <= 98, "{out}");
    assert_eq!(
        v["bytes"].as_u64().unwrap(),
        std::fs::metadata(glb).unwrap().len()
    );
    let (ok, out, err) = mts(&["strips", glb, "--repeat", "1", "--json"]);
    assert!(ok, "{err}");
    let s = json(&out);
    assert_eq!(s["triangles"].as_u64(), Some(4900));
    assert_eq!(s["vertices"].as_u64(), Some(n(&levels[0], "vertices")));
    // Share 0 is the coarsest LoD the sequence reached (a torus keeps some
    // triangles); a share above 1 is refused before any work.
    let (ok, out, err) = mts(&[
        &["lods"][..],
        &src,
        &["-o", glb, "--ratios", "0,1", "--json"],
    ]
    .concat());
    assert!(ok, "{err}");
    let last = &json(&out)["levels"][1];
    assert!(
        n(last, "triangles") > 0 && n(last, "triangles") < 100,
        "{out}"
    );
    let (ok, _, err) = mts(&[&["lods"][..], &src, &["-o", glb, "--ratios", "1,1.5"]].concat());
    assert!(!ok && err.contains("outside 0..=1"), "{err}");
    std::fs::remove_dir_all(&dir).ok();
}

/// `--compress` writes glTF that the reader takes back with the same
/// triangles, smaller than `--quantize`, itself smaller than plain; on
/// every command that writes glTF; refused for another format.
#[test]
fn compress_writes_meshopt_gltf_that_reads_back() {
    let dir = std::env::temp_dir().join(format!("mts-cli-compress-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = |name: &str| dir.join(name).to_str().unwrap().to_string();
    let src = ["--generated", "torus:5k", "--properties"];
    let mut sizes = Vec::new();
    for (name, flag) in [
        ("p.glb", None),
        ("q.glb", Some("--quantize")),
        ("c.glb", Some("--compress")),
    ] {
        let out = path(name);
        let args: Vec<&str> = [&["convert"][..], &src, &["-o", &out]]
            .concat()
            .into_iter()
            .chain(flag)
            .collect();
        let (ok, _, err) = mts(&args);
        assert!(ok, "{err}");
        sizes.push(std::fs::metadata(&out).unwrap().len());
        let (ok, text, err) = mts(&["strips", &out, "--repeat", "1", "--json"]);
        assert!(ok, "{err}");
        assert_eq!(json(&text)["triangles"].as_u64(), Some(4900), "{name}");
    }
    assert!(sizes[2] < sizes[1] && sizes[1] < sizes[0], "{sizes:?}");
    // The other writers of glTF.
    let level = path("level.gltf");
    let (ok, text, err) = mts(&[
        &["simplify"][..],
        &src,
        &["--ratio", "0.5", "-o", &level, "--compress", "--json"],
    ]
    .concat());
    assert!(ok, "{err}");
    let kept = json(&text)["triangles"].as_u64().unwrap();
    let (ok, text, err) = mts(&["strips", &level, "--repeat", "1", "--json"]);
    assert!(ok, "{err}");
    assert_eq!(json(&text)["triangles"].as_u64(), Some(kept));
    let chain = path("chain.glb");
    let (ok, _, err) = mts(&[&["lods"][..], &src, &["-o", &chain, "--compress"]].concat());
    assert!(ok, "{err}");
    let (ok, text, err) = mts(&["strips", &chain, "--repeat", "1", "--json"]);
    assert!(ok, "{err}");
    assert_eq!(json(&text)["triangles"].as_u64(), Some(4900));
    // Only glTF is compressed.
    let obj = path("c.obj");
    let (ok, _, err) = mts(&[&["convert"][..], &src, &["-o", &obj, "--compress"]].concat());
    assert!(
        !ok && err.contains("name the output .glb or .gltf"),
        "{err}"
    );
    assert!(!std::path::Path::new(&obj).exists());
    std::fs::remove_dir_all(&dir).ok();
}

/// `simplify --regions` makes the sequence in parts at once: the level is
/// within the target, the JSON names the parts, and a mesh with vertex
/// properties is refused with the reason.
#[test]
fn simplify_in_regions_reaches_the_target_and_refuses_properties() {
    let (ok, out, err) = mts(&[
        "simplify",
        "--generated",
        "torus:5k",
        "--ratio",
        "0.1",
        "--regions",
        "4",
        "--samples",
        "2000",
        "--no-meshopt",
        "--json",
    ]);
    assert!(ok, "{err}");
    let v = json(&out);
    assert_eq!(v["regions"], 4);
    let (triangles, target) = (
        v["triangles"].as_u64().unwrap(),
        v["target"].as_u64().unwrap(),
    );
    assert!(
        triangles <= target && triangles + 10 >= target,
        "{triangles} for {target}"
    );
    assert!(v["hausdorff"].as_f64().unwrap() < 0.05, "{out}");
    let (ok, _, err) = mts(&[
        "simplify",
        "--generated",
        "torus:2k",
        "--properties",
        "--ratio",
        "0.1",
        "--regions",
        "2",
    ]);
    assert!(!ok);
    assert!(
        err.contains("--regions") && err.contains("positions only"),
        "{err}"
    );
    let (ok, _, err) = mts(&[
        "simplify",
        "--generated",
        "torus:2k",
        "--ratio",
        "0.1",
        "--regions",
        "1",
    ]);
    assert!(!ok && err.contains("regions"), "{err}");
}
