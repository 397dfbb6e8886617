//! The README's C example, as written: its C program, its `gcc` line and its output.
//! The program is written to a scratch folder with the headers `needle header` writes
//! (`include/needle.h`, `include/needle_coeffs.h`) and this build's release
//! `libneedle_capi.a` at the path the README names (`target/release/`, a link in the
//! scratch folder); the README's `gcc` line runs there through `sh -c` unchanged, and the
//! program must print the README's output block byte for byte.
mod common;

use common::{run, staticlib, workspace_root};
use std::path::Path;
use std::process::Command;

/// The body of the first fenced block that starts with the line "```<info>" after the
/// first line of `text` that contains `after`.
fn block_after<'a>(text: &'a str, after: &str, info: &str) -> &'a str {
    let start = text.find(after).unwrap_or_else(|| panic!("README.md: no {after:?}"));
    let fence = format!("```{info}\n");
    let open = start + text[start..].find(&fence).unwrap_or_else(|| panic!("README.md: no {fence:?} after {after:?}")) + fence.len();
    let close = open + text[open..].find("```\n").unwrap_or_else(|| panic!("README.md: block after {after:?} not closed"));
    &text[open..close]
}

#[test]
fn readme_c_example_compiles_links_and_prints_what_the_readme_says() {
    let readme = std::fs::read_to_string(workspace_root().join("README.md")).expect("read README.md");
    let program = block_after(&readme, "## From C", "c");
    let commands = block_after(&readme, "## From C", "sh");
    let expected = block_after(&readme, "./hello_needle", "text");
    let gcc = commands.lines().find(|l| l.starts_with("gcc ")).expect("README.md: no gcc line in the C example's commands");
    assert!(gcc.contains("hello_needle.c") && gcc.contains("target/release/libneedle_capi.a"), "{gcc}");

    let dir = workspace_root().join("target").join("capi-test").join("readme");
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(dir.join("include")).expect("scratch folder");
    std::fs::create_dir_all(dir.join("target").join("release")).expect("scratch target folder");
    std::fs::write(dir.join("hello_needle.c"), program).expect("write hello_needle.c");
    std::fs::write(dir.join("include").join("needle.h"), needle_capi::HEADER).expect("write needle.h");
    std::fs::write(dir.join("include").join("needle_coeffs.h"), needle_haptics::model_info::C_HEADER).expect("write needle_coeffs.h");
    let lib = staticlib(None);
    std::os::unix::fs::symlink(&lib, dir.join("target").join("release").join("libneedle_capi.a")).expect("link the staticlib");

    run(Command::new("sh").current_dir(&dir).args(["-c", gcc]), "the README's gcc line");
    let out = Command::new(Path::new(&dir).join("hello_needle")).output().expect("run hello_needle");
    assert!(out.status.success(), "hello_needle exited {}", out.status);
    assert_eq!(String::from_utf8_lossy(&out.stdout), expected, "hello_needle's output differs from the README's");
}
