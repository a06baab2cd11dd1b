//! Helpers shared by the command's integration tests.
#![allow(dead_code)]

use std::process::Command;

/// Runs the `mts` binary with `args`: (success, stdout, stderr).
pub fn mts(args: &[&str]) -> (bool, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_mts"))
        .args(args)
        .output()
        .expect("the mts binary runs");
    (
        out.status.success(),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// `text` as JSON, or a panic showing it.
pub fn json(text: &str) -> serde_json::Value {
    serde_json::from_str(text.trim()).unwrap_or_else(|e| panic!("{e}: {text}"))
}

/// Whether a command that failed with `err` failed only for want of a
/// graphics adapter where none is required: then it prints "skipped" and
/// the test returns early. Where `MTS_REQUIRE` names `gpu` (CI sets it),
/// a missing adapter is a failure like any other.
pub fn skipped_without_adapter(ok: bool, err: &str) -> bool {
    let required =
        std::env::var("MTS_REQUIRE").is_ok_and(|v| v.split(',').any(|w| w.trim() == "gpu"));
    let skip = !ok && !required && err.contains("adapter");
    if skip {
        eprintln!("skipped: no graphics adapter ({err})");
    }
    skip
}
