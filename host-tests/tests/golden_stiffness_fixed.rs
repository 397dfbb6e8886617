//! The library's fixed-point stiffness against `golden-stiffness-fixed.csv`, which the
//! fitter wrote from its own, independent implementation of the contract
//! (coeffs/README.md, "Fixed-point stiffness"): every rate of every golden pose, exactly;
//! and the wrench of `fixed::wrench_and_stiffness` is `fixed::wrench`'s at every pose.
//!
//! A missing file is a failure, never a skip: `needle fit` writes it with model.toml.
use needle_haptics::{fixed, model_info};
use needle_host::fit::golden_stiffness::rate_columns;
use needle_host::fit::golden_stiffness_fixed::parse_csv;
use needle_host::fit::GOLDEN_STIFFNESS_FIXED_FILE;
use std::path::Path;

#[test]
fn library_fixed_stiffness_matches_golden_vectors_exactly() {
    if !model_info::FITTED {
        panic!("the library was built without a fitted model: run `needle fit --set {}`", model_info::SET_DIR);
    }
    let path = Path::new(model_info::SET_DIR).join(GOLDEN_STIFFNESS_FIXED_FILE);
    let text = std::fs::read_to_string(&path)
        .unwrap_or_else(|e| panic!("{}: cannot read ({e}); `needle fit --set {}` writes it", path.display(), model_info::SET_DIR));
    let rows = parse_csv(&text, &path).unwrap_or_else(|e| panic!("{e:#}"));
    assert!(rows.len() > 4000, "{}: {} rows, expected the golden poses (> 4,000)", path.display(), rows.len());
    let columns = rate_columns(true);
    let mut mismatches = Vec::new();
    let mut nonzero = 0usize;
    for (n, row) in rows.iter().enumerate() {
        let [x, z, tx, tz, d] = row.pose;
        let pose = fixed::Pose::new(x, z, tx, tz, d);
        let got = fixed::wrench_and_stiffness(&pose);
        let plain = fixed::wrench(&pose);
        let mut diffs = Vec::new();
        if got.status.bits() != row.status {
            diffs.push(format!("status want {:#04x} got {:#04x}", row.status, got.status.bits()));
        }
        if got.status != plain.status || got.wrench != plain.wrench {
            diffs.push(format!("wrench {:?} differs from fixed::wrench() {:?}", got.wrench, plain.wrench));
        }
        let s = got.stiffness;
        let have = [s.by_depth.to_array(), s.by_x.to_array(), s.by_z.to_array()];
        for ((name, w), g) in columns.iter().zip(row.rates.iter().flatten()).zip(have.iter().flatten()) {
            nonzero += usize::from(*g != 0);
            if w != g {
                diffs.push(format!("{name} want {w} got {g}"));
            }
        }
        if !diffs.is_empty() {
            mismatches.push(format!("{}:{}: {}", path.display(), n + 2, diffs.join("; ")));
        }
    }
    assert!(nonzero > rows.len(), "only {nonzero} nonzero rates in {} rows: the file checks little", rows.len());
    assert!(
        mismatches.is_empty(),
        "{} of {} rows differ; first:\n{}",
        mismatches.len(),
        rows.len(),
        mismatches[..mismatches.len().min(10)].join("\n")
    );
}
