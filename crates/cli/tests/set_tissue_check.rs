//! Issue 66 item 14: the tissue files of a `--set` are checked against the stacks
//! compiled into the build by every command that checks its model.toml (`eval`,
//! `fixed-error`, `calibrate`, `calibrate-published`): an edited, broken, extra or
//! missing tissue file is refused, not silently replaced by the compiled-in copy.
use std::path::Path;
use std::process::Output;

mod common;
use common::{needle, set_copy, show};

fn eval_pose(set: &Path) -> Output {
    let set = set.to_str().expect("utf-8");
    needle(&["eval", "--set", set, "--x-mm", "0", "--z-mm", "0", "--theta-x-deg", "0", "--theta-z-deg", "0", "--depth-mm", "5"])
}

fn refused_naming(o: &Output, want: &[&str]) {
    assert_eq!(o.status.code(), Some(2), "{}", show(o));
    let e = String::from_utf8_lossy(&o.stderr);
    for w in want {
        assert!(e.contains(w), "stderr lacks {w:?}: {}", show(o));
    }
}

#[test]
fn issue66_14_the_shipped_set_copy_passes_the_tissue_check() {
    let (_d, set) = set_copy();
    let o = eval_pose(&set);
    assert!(o.status.success(), "{}", show(&o));
}

#[test]
fn issue66_14_an_edited_liver_toml_is_refused_by_eval() {
    let (_d, set) = set_copy();
    let path = set.join("tissue/liver.toml");
    let text = std::fs::read_to_string(&path).expect("liver");
    let line = text.lines().find(|l| l.starts_with("puncture_force_n")).expect("a puncture force").to_string();
    std::fs::write(&path, text.replacen(&line, "puncture_force_n = 99.5", 1)).expect("write");
    refused_naming(&eval_pose(&set), &["tissue/liver.toml", "other values than the compiled-in stack \"liver\""]);
}

#[test]
fn issue66_14_a_broken_tissue_file_is_refused_by_eval_and_fixed_error() {
    let (_d, set) = set_copy();
    std::fs::write(set.join("tissue/broken.toml"), "format = 1\nname = \"broken\"\nthis is not toml\n").expect("write");
    refused_naming(&eval_pose(&set), &["broken.toml", "a broken tissue file in the set"]);
    let o = needle(&["fixed-error", "--set", set.to_str().expect("utf-8")]);
    refused_naming(&o, &["broken.toml"]);
}

#[test]
fn issue66_14_a_missing_or_extra_stack_is_refused() {
    let (_d, set) = set_copy();
    let epidural = set.join("tissue/epidural.toml");
    let text = std::fs::read_to_string(&epidural).expect("epidural");
    std::fs::remove_file(&epidural).expect("remove");
    refused_naming(&eval_pose(&set), &["epidural.toml: missing"]);
    // the same stack under another name: not compiled in
    std::fs::write(&epidural, &text).expect("restore");
    std::fs::write(set.join("tissue/epi3.toml"), text.replacen("name = \"epidural\"", "name = \"epi3\"", 1)).expect("write");
    refused_naming(&eval_pose(&set), &["epi3.toml", "is not compiled into this build"]);
}
