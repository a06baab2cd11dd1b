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
