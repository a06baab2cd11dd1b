//! Issue 19's hostile arguments through the `mts` command, each shrunk to
//! its smallest case (the library's cases are in the core crate's
//! `tests/hostile.rs`; `scripts/hostile.py` generates thousands more).

mod common;

use common::mts as mts_cli;
use std::process::Command;

/// A refused argument: exit non-zero, no panic, `expected` in the message.
fn refused(args: &[&str], expected: &str) {
    let (ok, _, err) = mts_cli(args);
    assert!(!ok, "{args:?} accepted");
    assert!(!err.contains("panicked"), "{args:?}: {err}");
    assert!(err.contains(expected), "{args:?}: {err}");
}

#[test]
fn absurd_arguments_are_refused_by_their_meaning() {
    let max = "18446744073709551615";
    refused(
        &["strips", "--generated", "grid:1", "--repeat", max],
        "outside 1..=10000",
    );
    refused(
        &["strips", "--generated", "grid:1", "--repeat", "0"],
        "outside 1..=10000",
    );
    refused(
        &["extract", "--generated", "grid:8", "--repeat", max],
        "outside",
    );
    refused(
        &[
            "compare",
            "--generated",
            "grid:8",
            "--requests",
            "1000000000",
        ],
        "outside",
    );
    refused(
        &[
            "simplify",
            "--generated",
            "grid:8",
            "--ratio",
            "0.5",
            "--samples",
            max,
        ],
        "outside",
    );
    refused(
        &[
            "render",
            "--generated",
            "grid:8",
            "--scene",
            "100000000",
            "-o",
            "x.png",
        ],
        "outside",
    );
    refused(
        &["bench", "render", "--generated", "grid:8", "--frames", "0"],
        "outside",
    );
    refused(
        &["build", "--generated", "icosphere:1e9", "-o", "x.mts"],
        "16777216",
    );
    refused(
        &["build", "--generated", "grid:1073741824", "-o", "x.mts"],
        "16777216",
    );
    refused(
        &[
            "build",
            "--generated",
            "grid:8",
            "-o",
            "x.mts",
            "--band-slack",
            "nan",
        ],
        "nan",
    );
    refused(
        &[
            "build",
            "--generated",
            "grid:8",
            "-o",
            "x.mts",
            "--band-slack",
            "0",
        ],
        "--single-band",
    );
    refused(
        &["verify", "--generated", "grid:8", "--lods", "0"],
        "checks nothing",
    );
    refused(&["decode", "x.stream", "--bytes", "-100"], "-100");
    refused(
        &["extract", "--generated", "grid:8", "--ratio", "-0.5"],
        "not -0.5",
    );
    refused(
        &["simplify", "--generated", "grid:8", "--ratio", "2"],
        "not 2",
    );
}

#[test]
fn verify_lods_past_the_model_checks_every_lod() {
    let (ok, out, err) = mts_cli(&[
        "verify",
        "--generated",
        "grid:8",
        "--lods",
        "99999999999",
        "--json",
    ]);
    assert!(ok, "{err}");
    let v: serde_json::Value = serde_json::from_str(out.trim()).unwrap();
    let (ok, all, _) = mts_cli(&["verify", "--generated", "grid:8", "--json"]);
    assert!(ok);
    let all: serde_json::Value = serde_json::from_str(all.trim()).unwrap();
    assert_eq!(v["lods_checked"], all["lods_checked"]);
    assert!(v["lods_checked"].as_u64().unwrap() > 4);
}

/// `decode --bytes N` with N at least the file's size read the whole stream
/// without its checksum: a flipped body bit decoded as "complete".
#[test]
fn decode_of_the_whole_stream_checks_the_checksum() {
    let dir = std::env::temp_dir().join(format!("mts-hostile-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("t.stream");
    let f = file.to_str().unwrap();
    let (ok, _, err) = mts_cli(&["encode", "--generated", "torus:200", "-o", f]);
    assert!(ok, "{err}");
    let mut bytes = std::fs::read(&file).unwrap();
    let last = bytes.len() - 1;
    bytes[last] ^= 0x10;
    std::fs::write(&file, &bytes).unwrap();
    let len = bytes.len().to_string();
    for args in [vec!["decode", f], vec!["decode", f, "--bytes", &len]] {
        let (ok, _, err) = mts_cli(&args);
        assert!(!ok && err.contains("checksum"), "{args:?}: {err}");
    }
    std::fs::remove_dir_all(&dir).ok();
}

/// A headless render printed libwayland's "error: XDG_RUNTIME_DIR is
/// invalid or not set" twice (Mesa's device-select layer probing for a
/// display); it is switched off when there is no session.
#[test]
fn a_headless_render_prints_no_window_system_error() {
    let dir = std::env::temp_dir().join(format!("mts-xdg-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let png = dir.join("t.png");
    let out = Command::new(env!("CARGO_BIN_EXE_mts"))
        .args([
            "render",
            "--generated",
            "torus:200",
            "--size",
            "32x32",
            "-o",
        ])
        .arg(&png)
        .env_remove("XDG_RUNTIME_DIR")
        .env_remove("NODEVICE_SELECT")
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!err.contains("XDG_RUNTIME_DIR"), "{err}");
    assert!(!err.contains("panicked"), "{err}");
    std::fs::remove_dir_all(&dir).ok();
}

/// A folder of its own for one test's files.
fn scratch(name: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("mts-31-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Issue 31, item 1: standard output that fails. A full disk is an error
/// naming standard output; a closed pipe ends the command quietly, with the
/// status a shell reports for a tool SIGPIPE ended (141), as `head` expects.
#[cfg(unix)]
#[test]
fn printing_to_a_full_disk_or_a_closed_pipe_does_not_panic() {
    use std::process::Stdio;
    let full = std::fs::OpenOptions::new()
        .write(true)
        .open("/dev/full")
        .unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_mts"))
        .args(["strips", "--generated", "icosphere:2k", "--repeat", "1"])
        .stdout(full)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(!err.contains("panicked"), "{err}");
    assert_eq!(
        err.trim(),
        "error: cannot write to standard output: No space left on device (os error 28)"
    );
    // A pipe whose reader is gone before the command writes.
    let mut child = Command::new(env!("CARGO_BIN_EXE_mts"))
        .args(["strips", "--generated", "icosphere:2k", "--repeat", "1"])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    drop(child.stdout.take());
    let out = child.wait_with_output().unwrap();
    assert_eq!(out.status.code(), Some(141));
    assert_eq!(String::from_utf8_lossy(&out.stderr), "");
}

/// Issue 31, items 2 and 6: `view --scene` is bounded like `render`'s
/// (refused before any window opens), weights refuse NaN and infinity, and
/// `-0` is a number, not a flag.
#[test]
fn view_scene_and_weights_are_bounded_and_minus_zero_is_a_number() {
    refused(
        &[
            "view",
            "--generated",
            "grid:8",
            "--scene",
            "18446744073709551615",
        ],
        "outside 1..=1048576",
    );
    refused(
        &["view", "--generated", "grid:8", "--scene", "1000000000"],
        "outside 1..=1048576",
    );
    for (flag, value) in [
        ("--uv-weight", "nan"),
        ("--normal-weight", "inf"),
        ("--color-weight", "-inf"),
    ] {
        refused(
            &[
                "simplify",
                "--generated",
                "grid:8",
                "--ratio",
                "0.5",
                flag,
                value,
            ],
            "not a finite number",
        );
    }
    let (ok, _, err) = mts_cli(&[
        "simplify",
        "--generated",
        "grid:8",
        "--ratio",
        "0.5",
        "--samples",
        "100",
        "--uv-weight",
        "-0",
        "--normal-weight",
        "-0",
        "--color-weight",
        "-0",
    ]);
    assert!(ok, "{err}");
}

/// Issue 31, item 5: a FIFO (or a device) as input is refused at once,
/// not opened (opening a FIFO blocks until a writer comes).
#[cfg(unix)]
#[test]
fn a_fifo_as_input_is_refused_without_blocking() {
    let dir = scratch("fifo");
    let fifo = dir.join("f.obj");
    let made = Command::new("mkfifo").arg(&fifo).status().unwrap();
    assert!(made.success());
    let out = dir.join("x.mts");
    for args in [
        vec!["build", fifo.to_str().unwrap(), "-o", out.to_str().unwrap()],
        vec!["info", fifo.to_str().unwrap()],
        vec!["build", "/dev/zero", "-o", out.to_str().unwrap()],
    ] {
        let (ok, _, err) = mts_cli(&args);
        assert!(!ok, "{args:?}");
        assert!(err.contains("not a regular file"), "{args:?}: {err}");
        assert!(!out.exists());
    }
    std::fs::remove_dir_all(&dir).ok();
}

/// A .glb of one mesh of `n × n` quads placed under `nodes` nodes.
fn instanced_glb(n: u32, nodes: usize) -> Vec<u8> {
    let mut bin = Vec::new();
    for i in 0..=n {
        for j in 0..=n {
            for x in [i as f32, j as f32, 0.0] {
                bin.extend_from_slice(&x.to_le_bytes());
            }
        }
    }
    let positions = bin.len();
    for i in 0..n {
        for j in 0..n {
            let a = i * (n + 1) + j;
            for v in [a, a + 1, a + n + 1, a + 1, a + n + 2, a + n + 1] {
                bin.extend_from_slice(&v.to_le_bytes());
            }
        }
    }
    let vertices = (n + 1) * (n + 1);
    let indices = 6 * n * n;
    let node_list: Vec<String> = (0..nodes)
        .map(|k| format!(r#"{{"mesh":0,"translation":[{},0,0]}}"#, 2 * k * n as usize))
        .collect();
    let roots: Vec<String> = (0..nodes).map(|k| k.to_string()).collect();
    let mut json = format!(
        r#"{{"asset":{{"version":"2.0"}},"scene":0,"scenes":[{{"nodes":[{}]}}],"nodes":[{}],
        "meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}},"indices":1}}]}}],
        "accessors":[{{"bufferView":0,"componentType":5126,"count":{vertices},"type":"VEC3",
        "min":[0,0,0],"max":[{n},{n},0]}},{{"bufferView":1,"componentType":5125,"count":{indices},
        "type":"SCALAR"}}],"bufferViews":[{{"buffer":0,"byteLength":{positions}}},
        {{"buffer":0,"byteOffset":{positions},"byteLength":{}}}],"buffers":[{{"byteLength":{}}}]}}"#,
        roots.join(","),
        node_list.join(","),
        bin.len() - positions,
        bin.len()
    )
    .into_bytes();
    json.resize(json.len().next_multiple_of(4), b' ');
    let mut glb = b"glTF".to_vec();
    glb.extend_from_slice(&2u32.to_le_bytes());
    glb.extend_from_slice(&((12 + 8 + json.len() + 8 + bin.len()) as u32).to_le_bytes());
    glb.extend_from_slice(&(json.len() as u32).to_le_bytes());
    glb.extend_from_slice(b"JSON");
    glb.extend_from_slice(&json);
    glb.extend_from_slice(&(bin.len() as u32).to_le_bytes());
    glb.extend_from_slice(b"BIN\0");
    glb.extend_from_slice(&bin);
    glb
}

/// Issue 31, item 3: a small file that asks for more triangles than the
/// caller allows (2,000 instances of a 20,000-triangle mesh: 40 M) is
/// refused naming the limit and the option that raises it; below the
/// limit it loads, and `--max-triangles` lowers or raises it.
#[test]
fn files_that_amplify_are_refused_at_the_limit() {
    let dir = scratch("amplify");
    let glb = dir.join("many.glb");
    std::fs::write(&glb, instanced_glb(100, 2_000)).unwrap();
    assert!(std::fs::metadata(&glb).unwrap().len() < 500_000);
    let g = glb.to_str().unwrap();
    let (ok, _, err) = mts_cli(&["strips", g, "--repeat", "1"]);
    assert!(!ok);
    assert!(err.contains("many.glb"), "{err}");
    assert!(
        err.contains("more than 16777216 triangles") && err.contains("--max-triangles"),
        "{err}"
    );
    let few = dir.join("few.glb");
    std::fs::write(&few, instanced_glb(10, 3)).unwrap();
    let f = few.to_str().unwrap();
    let (ok, out, err) = mts_cli(&["strips", f, "--repeat", "1", "--json"]);
    assert!(ok, "{err}");
    assert_eq!(common::json(&out)["triangles"], 600);
    let (ok, _, err) = mts_cli(&["strips", f, "--repeat", "1", "--max-triangles", "599"]);
    assert!(!ok && err.contains("more than 599 triangles"), "{err}");
    std::fs::remove_dir_all(&dir).ok();
}

/// Issue 31, item 7: valid input that was refused. A level exported as PLY
/// (which needs every vertex used: the level's own vertices are written),
/// an OBJ whose texture is missing converted with its properties (a
/// warning, as `build` and `render` give), and a scene of meshes whose
/// extent f32 can hardly say.
#[test]
fn valid_inputs_at_the_edges_are_accepted() {
    let dir = scratch("valid");
    let model = dir.join("m.mts");
    let m = model.to_str().unwrap();
    let (ok, _, err) = mts_cli(&["build", "--generated", "torus:2k", "-o", m]);
    assert!(ok, "{err}");
    for ext in ["ply", "obj"] {
        let out = dir.join(format!("x.{ext}"));
        let (ok, json, err) = mts_cli(&[
            "extract",
            m,
            "--ratio",
            "0.5",
            "--json",
            "-o",
            out.to_str().unwrap(),
        ]);
        assert!(ok, "{ext}: {err}");
        let v = common::json(&json);
        // A closed torus: V - E + F = 0 with E = 3F/2, so V = F/2.
        assert_eq!(v["triangles"], 968);
        assert_eq!(v["vertices_written"], 484, "{ext}");
        let (ok, back, err) =
            mts_cli(&["strips", out.to_str().unwrap(), "--repeat", "1", "--json"]);
        assert!(ok, "{ext}: {err}");
        assert_eq!(common::json(&back)["triangles"], 968);
    }
    let obj = dir.join("t.obj");
    std::fs::write(
        &obj,
        "mtllib t.mtl\nusemtl a\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nf 1/1 2/2 3/3\n",
    )
    .unwrap();
    std::fs::write(dir.join("t.mtl"), "newmtl a\nmap_Kd missing.png\n").unwrap();
    let glb = dir.join("t.glb");
    let (ok, _, err) = mts_cli(&[
        "convert",
        obj.to_str().unwrap(),
        "--properties",
        "-o",
        glb.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    assert!(
        err.contains("missing.png") && err.contains("untextured"),
        "{err}"
    );
    for (name, text) in [
        (
            "point",
            "v 100 100 100\nv 100 100 100\nv 100 100 100\nf 1 2 3\n",
        ),
        (
            "huge",
            "v 2.2e38 0 0\nv 0 2.2e38 0\nv -2.2e38 0 0\nf 1 2 3\n",
        ),
        (
            "denormal",
            "v 1e-40 0 0\nv 0 1e-40 0\nv -1e-40 0 0\nf 1 2 3\n",
        ),
    ] {
        let mesh = dir.join(format!("{name}.obj"));
        std::fs::write(&mesh, text).unwrap();
        let png = dir.join(format!("{name}.png"));
        let (ok, _, err) = mts_cli(&[
            "render",
            mesh.to_str().unwrap(),
            "--size",
            "32x32",
            "--scene",
            "3",
            "-o",
            png.to_str().unwrap(),
        ]);
        assert!(ok, "{name}: {err}");
    }
    std::fs::remove_dir_all(&dir).ok();
}

/// Issue 31, item 9: `-o` naming the input is refused and the input left
/// as it was; a command that fails leaves the file it would have replaced
/// as it was, and nothing beside it.
#[test]
fn outputs_never_clobber_the_input_or_the_previous_file() {
    let dir = scratch("outputs");
    let obj = dir.join("a.obj");
    let text = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf 1 2 3\nf 2 4 3\n";
    std::fs::write(&obj, text).unwrap();
    let a = obj.to_str().unwrap();
    let via_dot = dir.join(".").join("a.obj");
    for args in [
        vec!["convert", a, "-o", a],
        vec!["build", a, "-o", a],
        vec![
            "simplify",
            a,
            "--ratio",
            "0.5",
            "-o",
            via_dot.to_str().unwrap(),
        ],
    ] {
        let (ok, _, err) = mts_cli(&args);
        assert!(!ok, "{args:?}");
        assert!(err.contains("the output is the input file"), "{err}");
        assert_eq!(std::fs::read_to_string(&obj).unwrap(), text);
    }
    let good = dir.join("good.mts");
    let (ok, _, err) = mts_cli(&["build", a, "-o", good.to_str().unwrap()]);
    assert!(ok, "{err}");
    let before = std::fs::read(&good).unwrap();
    let bad = dir.join("bad.obj");
    std::fs::write(&bad, "v 0 0 0\nf 1 2 3\n").unwrap();
    let (ok, _, _) = mts_cli(&["build", bad.to_str().unwrap(), "-o", good.to_str().unwrap()]);
    assert!(!ok);
    assert_eq!(std::fs::read(&good).unwrap(), before);
    let mut names: Vec<String> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    assert_eq!(names, ["a.obj", "bad.obj", "good.mts"]);
    std::fs::remove_dir_all(&dir).ok();
}
