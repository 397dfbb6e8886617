//! The library's fixed-point evaluator against the golden vectors the fitter wrote from its
//! own, independent implementation of the fixed-point contract (coeffs/README.md): every
//! row, every integer, exactly. The golden file is `<set>/golden-fixed.csv` of the set
//! compiled into the library. A missing file is a failure, never a skip.
use needle_fit::golden::fixed::parse_csv;
use needle_haptics::{fixed, model_info};
use std::path::Path;

#[test]
fn library_matches_fixed_golden_vectors_exactly() {
    if !model_info::FITTED {
        panic!("the library was built without a fitted model: run `needle fit --set {}`", model_info::SET_DIR);
    }
    let path = Path::new(model_info::SET_DIR).join("golden-fixed.csv");
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| {
        panic!("{}: cannot read ({e}); `needle fit --set {}` writes it; this test never skips", path.display(), model_info::SET_DIR)
    });
    let rows = parse_csv(&text, &path).unwrap_or_else(|e| panic!("{e:#}"));
    assert!(rows.len() >= 2000, "{}: only {} rows", path.display(), rows.len());
    let mut mismatches = Vec::new();
    for (n, row) in rows.iter().enumerate() {
        let [x, z, tx, tz, d] = row.pose;
        let got = fixed::wrench(&fixed::Pose::new(x, z, tx, tz, d));
        if got.status.bits() != row.status || got.wrench.to_array() != row.wrench {
            mismatches.push(format!(
                "line {}: pose {:?}: want status {:#04x} {:?}, got {:#04x} {:?}",
                n + 2,
                row.pose,
                row.status,
                row.wrench,
                got.status.bits(),
                got.wrench.to_array()
            ));
        }
    }
    assert!(
        mismatches.is_empty(),
        "{} of {} rows of {} differ from the library; first ones:\n{}",
        mismatches.len(),
        rows.len(),
        path.display(),
        mismatches.iter().take(10).cloned().collect::<Vec<_>>().join("\n")
    );
    println!("{} fixed-point golden rows of {} match exactly", rows.len(), path.display());
}
