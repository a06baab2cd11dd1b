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
