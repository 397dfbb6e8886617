//! One version for the whole project: the workspace's `[workspace.package] version`, which
//! every member inherits, is the version the crates with their own workspaces state (the
//! Python bindings and their `pyproject.toml`, the board crates) and the newest version of
//! the user changelog (`CHANGELOG.md`, the first `## [x.y.z]` after `[Unreleased]`).
use std::path::{Path, PathBuf};

fn workspace() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

fn read(path: &str) -> String {
    std::fs::read_to_string(workspace().join(path)).unwrap_or_else(|e| panic!("{path}: {e}"))
}

fn toml_at<'a>(value: &'a toml::Value, keys: &[&str], path: &str) -> &'a toml::Value {
    keys.iter().fold(value, |v, k| v.get(k).unwrap_or_else(|| panic!("{path}: no {}", keys.join("."))))
}

fn version_in(path: &str, keys: &[&str]) -> String {
    let value: toml::Value = toml::from_str(&read(path)).unwrap_or_else(|e| panic!("{path}: {e}"));
    toml_at(&value, keys, path).as_str().unwrap_or_else(|| panic!("{path}: {} is not a string", keys.join("."))).to_string()
}

/// The newest released version the changelog names: `## [x.y.z] - date`.
fn changelog_version() -> String {
    let text = read("CHANGELOG.md");
    let line = text.lines().find(|l| l.starts_with("## [") && !l.starts_with("## [Unreleased]")).expect("CHANGELOG.md: no version");
    line.trim_start_matches("## [").split(']').next().unwrap_or_default().to_string()
}

#[test]
fn every_crate_states_the_workspace_version() {
    let want = version_in("Cargo.toml", &["workspace", "package", "version"]);
    let own_workspaces = [
        ("crates/bindings-python/Cargo.toml", &["package", "version"][..]),
        ("crates/bindings-python/pyproject.toml", &["project", "version"][..]),
        ("examples/rtic-lm3s6965/Cargo.toml", &["package", "version"][..]),
        ("examples/nucleo-f401re/Cargo.toml", &["package", "version"][..]),
    ];
    for (path, keys) in own_workspaces {
        assert_eq!(version_in(path, keys), want, "{path}: not the workspace's version");
    }
    assert_eq!(changelog_version(), want, "CHANGELOG.md's newest version is not the workspace's");
    // the members inherit it: `cargo metadata` would show each; here, each says so
    let members = ["Cargo.toml", "host-tests/Cargo.toml"].into_iter().map(String::from).chain(
        std::fs::read_dir(workspace().join("crates"))
            .expect("crates/")
            .flatten()
            .map(|e| format!("crates/{}/Cargo.toml", e.file_name().to_string_lossy()))
            .filter(|p| !p.starts_with("crates/bindings-") && workspace().join(p).exists()),
    );
    for path in members {
        let value: toml::Value = toml::from_str(&read(&path)).unwrap_or_else(|e| panic!("{path}: {e}"));
        let inherits = toml_at(&value, &["package", "version"], &path).get("workspace").and_then(toml::Value::as_bool);
        assert_eq!(inherits, Some(true), "{path}: package.version must be `version.workspace = true`");
    }
}
