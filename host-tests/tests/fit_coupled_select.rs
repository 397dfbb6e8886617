//! The coupled form's size is chosen per component (crates/fit/src/coupled.rs,
//! coeffs/README.md "The coupled form"): on training runs made from the default set's
//! paper model with a known cross term in fy and an unrepresentable wiggle in fx, fy
//! gets its term back and every other component none.
use needle_fe::results::Row;
use needle_fe::spec::{PoseSpec, Role};
use needle_fit::contract::COMPONENTS;
use needle_fit::coupled::{scales, select_and_fit};
use needle_fit::data::Run;
use needle_fit::eval_f64::eval_paper;
use std::path::Path;

/// Training runs whose FE rows are the default set's paper model plus, for fy, a known
/// cross term `0.004 N * xi * beta * (1 + u)` and, for fx, a deterministic wiggle no
/// cross term represents: cross-validation must give fy cross terms that recover the
/// term, and fx (where cross terms would only fit the wiggle) and the exact
/// components none.
#[test]
fn each_component_chooses_its_own_size_and_none_when_the_paper_form_is_better() {
    let path = Path::new(needle_haptics::model_info::SET_DIR).join("model.toml");
    let paper = needle_fit::model_file::read(&path).unwrap_or_else(|e| panic!("{e:#}"));
    // 16 combined poses from a fixed low-discrepancy rule (golden-ratio steps).
    let runs: Vec<Run> = (0..16)
        .map(|i| {
            let f = |k: f64| ((f64::from(i) + 0.5) * k).fract() * 2.0 - 1.0;
            let pose = PoseSpec {
                name: format!("train-{i:02}"),
                role: Role::Train,
                x_mm: 11.0 * f(0.618_034),
                z_mm: 11.0 * f(0.754_878),
                theta_x_deg: 14.0 * f(0.569_840),
                theta_z_deg: 14.0 * f(0.437_016),
            };
            let rows = (1..=20)
                .map(|d| {
                    let depth_mm = 0.3 * f64::from(d);
                    let p = [pose.x_mm, pose.z_mm, pose.theta_x_deg, pose.theta_z_deg, depth_mm];
                    let mut wrench = eval_paper(&paper, p).0;
                    wrench[1] += 0.004 * (pose.x_mm / 12.0) * (pose.theta_z_deg / 15.0) * (depth_mm / 3.0);
                    wrench[0] += 2e-5 * (7.0 * depth_mm + f64::from(i)).sin();
                    Row { depth_mm, wrench }
                })
                .collect();
            Run { pose, file_name: String::new(), rows }
        })
        .collect();
    let refs: Vec<&Run> = runs.iter().collect();
    let scale = scales(&refs, 60.0);
    let (sel, terms) = select_and_fit(&paper, &refs, scale).unwrap_or_else(|e| panic!("{e:#}"));
    assert_eq!(sel.choices[0], None, "fx: cross terms only fit the wiggle: {sel:?}");
    for c in [0, 2, 3, 4, 5] {
        assert_eq!(sel.choices[c], None, "{}: no cross term there", COMPONENTS[c]);
        assert!(terms.terms[c].iter().all(|(_, p)| p.iter().all(|v| *v == 0.0)), "{}: written as zeros", COMPONENTS[c]);
    }
    let fy = sel.choices[1].unwrap_or_else(|| panic!("fy needs its cross term: {sel:?}"));
    assert!(sel.rms_pct[1] < 1e-6 && sel.paper_rms_pct[1] > 0.1, "fy: cv {} %, paper {} %", sel.rms_pct[1], sel.paper_rms_pct[1]);
    // The fitted term: xi * beta with P(u) = 0.004 (u + 1).
    let (_, p) = terms.terms[1].iter().find(|(e, _)| *e == [1, 0, 0, 1]).unwrap_or_else(|| panic!("no xi*beta term in {fy:?}"));
    assert!((p[0] - 0.004).abs() < 1e-9 && (p[1] - 0.004).abs() < 1e-9, "xi*beta: {p:?}");
}
