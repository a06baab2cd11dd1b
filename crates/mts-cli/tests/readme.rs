//! The README's "Latest bench report" section is the committed report's
//! data, as `mts bench summary` writes it: a figure typed by hand, or a
//! report regenerated without the README (or the reverse), fails here.

use std::path::Path;
use std::process::Command;

#[test]
fn readme_bench_section_matches_the_committed_report() {
    let root = Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../.."));
    let out = Command::new(env!("CARGO_BIN_EXE_mts"))
        .args(["bench", "summary"])
        .arg(root.join("docs/report/results.json"))
        .arg("--readme")
        .arg(root.join("README.md"))
        .arg("--check")
        .output()
        .expect("the mts binary runs");
    assert!(
        out.status.success(),
        "{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(String::from_utf8_lossy(&out.stdout).contains("matches"));
}

#[test]
fn summary_check_fails_on_a_hand_edited_figure() {
    let root = Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../.."));
    let readme = std::fs::read_to_string(root.join("README.md")).unwrap();
    // Change one digit inside the generated section.
    let begin = readme
        .find("<!-- BEGIN mts bench summary")
        .expect("a generated section");
    let at = begin
        + readme[begin..]
            .find(|c: char| c.is_ascii_digit())
            .expect("a figure in the section");
    let digit = readme.as_bytes()[at];
    let other = if digit == b'9' {
        '0'
    } else {
        char::from(digit + 1)
    };
    let mut edited = readme.clone();
    edited.replace_range(at..=at, &other.to_string());
    let dir = std::env::temp_dir().join(format!("mts-readme-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let copy = dir.join("README.md");
    std::fs::write(&copy, edited).unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_mts"))
        .args(["bench", "summary"])
        .arg(root.join("docs/report/results.json"))
        .arg("--readme")
        .arg(&copy)
        .arg("--check")
        .output()
        .expect("the mts binary runs");
    let _ = std::fs::remove_dir_all(&dir);
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("differs"));
}
