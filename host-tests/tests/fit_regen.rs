//! Regenerating model.toml, golden-f32.csv and golden-fixed.csv from the committed FE data of the shipped
//! set reproduces the committed files byte for byte (unicode-ident style). Never skipped:
//! a missing file is a failure that says how to make it.

use needle_fit::{fit_set, GOLDEN_FILE, GOLDEN_FIXED_FILE, GOLDEN_STIFFNESS_FILE, MODEL_FILE};
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
    let mut committed = Vec::new();
    for name in [MODEL_FILE, GOLDEN_FILE, GOLDEN_FIXED_FILE, GOLDEN_STIFFNESS_FILE] {
        let path = set.join(name);
        match std::fs::read_to_string(&path) {
            Ok(t) => committed.push(t),
            Err(e) => panic!(
                "{}: cannot read ({e}). The shipped set has no fitted model yet: once the FE campaign \
                 is complete, run `cargo run --release -p needle-cli -- fit --set coeffs/default` and commit \
                 coeffs/default/{MODEL_FILE}, {GOLDEN_FILE}, {GOLDEN_FIXED_FILE} and {GOLDEN_STIFFNESS_FILE}.",
                path.display()
            ),
        }
    }
    let out = match fit_set(&set) {
        Ok(o) => o,
        Err(e) => panic!("regenerating the fit of {} failed: {e:#}", set.display()),
    };
    let regenerated = [&out.model_toml, &out.golden_csv, &out.golden_fixed_csv, &out.golden_stiffness_csv];
    for ((name, have), want) in [MODEL_FILE, GOLDEN_FILE, GOLDEN_FIXED_FILE, GOLDEN_STIFFNESS_FILE].iter().zip(&committed).zip(regenerated)
    {
        if have != want {
            panic!(
                "coeffs/default/{name} differs from what `needle fit` regenerates from coeffs/default/fe \
                 (first difference at line {}); rerun `needle fit --set coeffs/default` and commit the result, \
                 or find what made the fit non-reproducible",
                first_difference(have, want)
            );
        }
    }
}
