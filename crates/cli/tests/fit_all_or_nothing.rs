//! `needle fit` writes model.toml, golden-f32.csv and golden-fixed.csv all or nothing:
//! when one of them cannot be written, none changes and no temporary is left; stale
//! temporaries of an earlier, killed run are removed by the next one.

use std::path::{Path, PathBuf};
use std::process::Command;

fn copy_set(to: &Path) -> PathBuf {
    let from = needle_stdx::workspace_root().join("coeffs/default");
    let set = to.join("default");
    std::fs::create_dir_all(set.join("fe")).expect("mkdir");
    for f in ["campaign.toml", "model.toml", "golden-f32.csv", "golden-fixed.csv"] {
        std::fs::copy(from.join(f), set.join(f)).expect("copy");
    }
    for e in std::fs::read_dir(from.join("fe")).expect("fe/").flatten() {
        if e.path().is_file() {
            std::fs::copy(e.path(), set.join("fe").join(e.file_name())).expect("copy fe");
        }
    }
    set
}

fn fit(set: &Path) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_needle")).args(["fit", "--set", &set.to_string_lossy()]).output().expect("run needle fit")
}

fn temporaries(set: &Path) -> Vec<String> {
    std::fs::read_dir(set)
        .expect("read set")
        .flatten()
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(".tmp"))
        .collect()
}

#[test]
fn a_failing_output_leaves_every_output_as_it_was() {
    let d = tempfile::tempdir().expect("tempdir");
    let set = copy_set(d.path());
    // an older model.toml than the one the fit will write: any change would show
    std::fs::write(set.join("model.toml"), "# the previous model\n").expect("write");
    let before_golden = std::fs::read(set.join("golden-f32.csv")).expect("golden");
    std::fs::remove_file(set.join("golden-fixed.csv")).expect("rm");
    std::fs::create_dir(set.join("golden-fixed.csv")).expect("a folder where a file must go");
    let o = fit(&set);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains("golden-fixed.csv: is a folder") && err.contains("nothing written"), "{err}");
    assert_eq!(std::fs::read_to_string(set.join("model.toml")).ok().as_deref(), Some("# the previous model\n"), "model.toml unchanged");
    assert_eq!(std::fs::read(set.join("golden-f32.csv")).ok(), Some(before_golden), "golden-f32.csv unchanged");
    assert!(temporaries(&set).is_empty(), "no temporary left: {:?}", temporaries(&set));
}

#[test]
fn stale_temporaries_are_removed_by_the_next_fit() {
    let d = tempfile::tempdir().expect("tempdir");
    let set = copy_set(d.path());
    // pid 4194304 is above Linux's pid_max limit: never a live process
    for f in [".model.toml.4194304.tmp", ".golden-f32.csv.4194304.tmp"] {
        std::fs::write(set.join(f), "half-written").expect("write");
    }
    let o = fit(&set);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(temporaries(&set).is_empty(), "stale temporaries removed: {:?}", temporaries(&set));
}
