//! The library's fixed-point stiffness against `golden-stiffness-fixed.csv`, which the
//! fitter wrote from its own, independent implementation of the contract
//! (coeffs/README.md, "Fixed-point stiffness"): every rate of every golden pose, exactly;
//! and the wrench of `fixed::wrench_and_stiffness` is `fixed::wrench`'s at every pose.
//!
//! A missing file is a failure, never a skip: `needle fit` writes it with model.toml.
use needle_fit::golden::stiffness_fixed::parse_csv;
use needle_fit::golden::stiffness_float32::rate_columns;
use needle_fit::GOLDEN_STIFFNESS_FIXED_FILE;
use needle_haptics::{fixed, model_info};
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

/// The fixed-point rates approximate the f64 model's exact derivatives (eval::rate_float64,
/// itself checked against central differences in stiffness_f64.rs) at every golden pose
/// inside the domain (x, z != 0: at 0 the rates are one-sided by rule): within
/// `1e-4 * max|rate| + 3 µN/mm` per rate and component. Why that tolerance: the contract
/// computes rates on coefficients shifted right by 3 and rounds each to whole µN/mm; no
/// bound is generated for the rates (unlike the wrench's ERROR_BOUND_MICRO). The measured
/// errors are printed (`-- --nocapture`; figures in coeffs/README.md, "Fixed-point
/// stiffness"); a wrong sign or scale in the contract shows as 100 % or more.
#[test]
fn fixed_rates_follow_the_f64_derivatives() {
    let path = Path::new(model_info::SET_DIR).join("model.toml");
    let model = needle_fit::model_file::read(&path).unwrap_or_else(|e| panic!("{e:#}"));
    let mut rows = Vec::new();
    for p in needle_fit::golden::fixed::poses(&[]) {
        let exact = p.map(|v| f64::from(v) / 65536.0);
        let (want, status) = needle_fit::eval::rate_float64::eval_rates(&model, exact);
        if status != 0 || exact[0] == 0.0 || exact[1] == 0.0 {
            continue;
        }
        let s = fixed::wrench_and_stiffness(&fixed::Pose::new(p[0], p[1], p[2], p[3], p[4])).stiffness;
        rows.push((p, want, [s.by_depth.to_array(), s.by_x.to_array(), s.by_z.to_array()]));
    }
    assert!(rows.len() > 3000, "only {} golden poses inside the domain", rows.len());
    let columns = rate_columns(true);
    let mut max_rate = [[0.0f64; needle_contract::COMPONENT_COUNT]; 3];
    for (_, want, _) in &rows {
        for (m, w) in max_rate.iter_mut().flatten().zip(want.iter().flatten()) {
            *m = m.max((w * 1e6).abs());
        }
    }
    let mut worst = 0.0f64;
    // largest absolute error of the force rates (µN/mm) and of the moment rates (µN·mm/mm)
    let mut worst_abs = [0.0f64; 2];
    for (p, want, have) in &rows {
        for (k, (((name, w), h), m)) in
            columns.iter().zip(want.iter().flatten()).zip(have.iter().flatten()).zip(max_rate.iter().flatten()).enumerate()
        {
            let err = (f64::from(*h) - w * 1e6).abs();
            let tol = 1e-4 * m + 3.0;
            worst = worst.max(err / tol);
            let class = usize::from(!needle_contract::is_force(k % needle_contract::COMPONENT_COUNT));
            worst_abs[class] = worst_abs[class].max(err);
            assert!(err <= tol, "{name} at {p:?}: fixed {h} vs f64 {:.3} (error {err:.3} > {tol:.3})", w * 1e6);
        }
    }
    let largest = max_rate.iter().flatten().copied().fold(0.0, f64::max);
    println!(
        "{} poses: worst error {:.3} of the tolerance; forces {:.1} µN/mm, moments {:.1} µN·mm/mm ({:.1e} of the largest rate, {:.2e})",
        rows.len(),
        worst,
        worst_abs[0],
        worst_abs[1],
        worst_abs[1] / largest,
        largest
    );
}
