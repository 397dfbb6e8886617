//! The library's f32 stiffness against `golden-stiffness-f32.csv`, which the fitter wrote
//! from its own, independent implementation of the contract (coeffs/README.md,
//! "Stiffness"): every rate of every golden pose, bit for bit; and the wrench of
//! `wrench_and_stiffness` has the bits of `wrench` at every golden pose.
//!
//! A missing file is a failure, never a skip: `needle fit` writes it with model.toml.
use needle_fit::golden::stiffness_float32::{parse_csv, rate_columns};
use needle_fit::GOLDEN_STIFFNESS_FILE;
use needle_haptics::{model_info, wrench, wrench_and_stiffness, Pose};
use std::path::Path;

/// Equal as the contract demands: NaN matches NaN, anything else by bits (+0.0 and -0.0
/// differ).
fn same(want: f32, got: f32) -> bool {
    if want.is_nan() {
        got.is_nan()
    } else {
        got.to_bits() == want.to_bits()
    }
}

#[test]
fn library_stiffness_matches_golden_vectors_bit_for_bit() {
    if !model_info::FITTED {
        panic!("the library was built without a fitted model: run `needle fit --set {}`", model_info::SET_DIR);
    }
    let path = Path::new(model_info::SET_DIR).join(GOLDEN_STIFFNESS_FILE);
    let text = std::fs::read_to_string(&path)
        .unwrap_or_else(|e| panic!("{}: cannot read ({e}); `needle fit --set {}` writes it", path.display(), model_info::SET_DIR));
    let rows = parse_csv(&text, &path).unwrap_or_else(|e| panic!("{e:#}"));
    assert!(rows.len() > 4000, "{}: {} rows, expected the golden poses (> 4,000)", path.display(), rows.len());
    let mut mismatches = Vec::new();
    let mut nonzero = 0usize;
    for (n, row) in rows.iter().enumerate() {
        let [x, z, tx, tz, d] = row.pose;
        let pose = Pose::new(x, z, tx, tz, d);
        let got = wrench_and_stiffness(&pose);
        let plain = wrench(&pose);
        let mut diffs = Vec::new();
        if got.status.bits() != row.status {
            diffs.push(format!("status want {:#04x} got {:#04x}", row.status, got.status.bits()));
        }
        if got.status != plain.status || got.wrench.to_array().iter().zip(plain.wrench.to_array()).any(|(a, b)| !same(b, *a)) {
            diffs.push(format!("wrench {:?} differs from wrench() {:?}", got.wrench, plain.wrench));
        }
        let s = got.stiffness;
        let have = [s.by_depth.to_array(), s.by_x.to_array(), s.by_z.to_array()];
        for ((name, w), g) in rate_columns(false).iter().zip(row.rates.iter().flatten()).zip(have.iter().flatten()) {
            nonzero += usize::from(*g != 0.0);
            if !same(*w, *g) {
                diffs.push(format!("{name} want {:#010x} ({w:e}) got {:#010x} ({g:e})", w.to_bits(), g.to_bits()));
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
