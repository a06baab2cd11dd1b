//! The README's library example is `examples/quickstart.rs`, which CI
//! compiles and runs: this test fails when the two differ.
//!
//! The README's block is the text between its one line that is exactly
//! "```rust" and the next line that is exactly "```" (both fences
//! excluded). The example's body is the file after its leading `//!`
//! lines and the blank lines that follow them. The two must be equal byte
//! for byte, line endings included.

use std::path::Path;

/// The lines between the README's only "```rust" fence and the next "```"
/// line, each with its newline.
fn rust_block(readme: &str) -> Result<String, String> {
    let lines: Vec<&str> = readme.split_inclusive('\n').collect();
    let is = |line: &str, fence: &str| line.trim_end_matches(['\n', '\r']) == fence;
    let opens: Vec<usize> = (0..lines.len())
        .filter(|&i| is(lines[i], "```rust"))
        .collect();
    let &[open] = opens.as_slice() else {
        return Err(format!(
            "the README has {} lines \"```rust\"; the library example needs exactly one",
            opens.len()
        ));
    };
    let close = (open + 1..lines.len())
        .find(|&i| is(lines[i], "```"))
        .ok_or("the README's \"```rust\" block is not closed by a \"```\" line")?;
    Ok(lines[open + 1..close].concat())
}

/// The example without its leading `//!` header and the blank lines after
/// it.
fn example_body(example: &str) -> String {
    let lines: Vec<&str> = example.split_inclusive('\n').collect();
    let start = lines
        .iter()
        .position(|l| !l.starts_with("//!") && !l.trim().is_empty())
        .unwrap_or(lines.len());
    lines[start..].concat()
}

#[test]
fn readme_example_is_the_quickstart_example() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let readme = std::fs::read_to_string(root.join("../../README.md")).unwrap();
    let example = std::fs::read_to_string(root.join("examples/quickstart.rs")).unwrap();
    let block = rust_block(&readme).unwrap_or_else(|e| panic!("{e}"));
    let body = example_body(&example);
    if block != body {
        let line = block
            .lines()
            .zip(body.lines())
            .position(|(a, b)| a != b)
            .unwrap_or_else(|| block.lines().count().min(body.lines().count()));
        panic!(
            "README.md's rust block differs from crates/mts-render/examples/quickstart.rs \
             (after its //! header) at line {} of the block:\n  README:  {:?}\n  example: {:?}\n\
             copy the example's body into the README (or the reverse)",
            line + 1,
            block.lines().nth(line),
            body.lines().nth(line),
        );
    }
}

#[test]
fn the_block_and_the_body_are_delimited_as_documented() {
    let readme = "intro\n```\nshell\n```\n```rust\nfn main() {}\n\n// end\n```\nafter\n";
    assert_eq!(rust_block(readme).unwrap(), "fn main() {}\n\n// end\n");
    assert!(rust_block("```rust\nfn main() {}\n").is_err());
    assert!(rust_block("```rust\na\n```\n```rust\nb\n```\n").is_err());
    let example = "//! header\n//!\n//! more\n\nuse x;\n\nfn main() {}\n";
    assert_eq!(example_body(example), "use x;\n\nfn main() {}\n");
}
