//! Regenerating model.toml and the golden vectors (`FitOutput::files`) from the committed FE
//! data of the shipped set reproduces the committed files byte for byte (unicode-ident style). Never skipped:
//! a missing file is a failure that says how to make it.

use needle_fit::fit_set;
use std::path::PathBuf;

fn set_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../coeffs/default")
}

fn first_difference(a: &str, b: &str) -> usize {
    a.lines().zip(b.lines()).position(|(x, y)| x != y).unwrap_or_else(|| a.lines().count().min(b.lines().count())) + 1
}

#[test]
fn committed_model_and_golden_vectors_are_reproducible() {
    let set = set_dir();
    let out = match needle_set::set_folder::SetFolder::open(&set).and_then(|s| fit_set(&s)) {
        Ok(o) => o,
        Err(e) => panic!("regenerating the fit of {} failed: {e:#}", set.display()),
    };
    for (name, want) in out.files() {
        let path = set.join(name);
        let have = match std::fs::read_to_string(&path) {
            Ok(t) => t,
            Err(e) => panic!(
                "{}: cannot read ({e}). Run `cargo run --release -p needle-cli -- fit --set coeffs/default` \
                 and commit every file it writes ({:?}).",
                path.display(),
                out.files().into_iter().map(|(n, _)| n).collect::<Vec<_>>()
            ),
        };
        if have != want {
            panic!(
                "coeffs/default/{name} differs from what `needle fit` regenerates from coeffs/default/fe \
                 (first difference at line {}); rerun `needle fit --set coeffs/default` and commit the result, \
                 or find what made the fit non-reproducible",
                first_difference(&have, want)
            );
        }
    }
}
