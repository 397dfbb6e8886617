//! The coupled form's size is chosen per component (crates/fit/src/coupled.rs,
//! coeffs/README.md "The coupled form"): on runs made from the default set's paper form
//! (its centre and sweep runs replaced by the model's values, so the paper part is exactly
//! representable with sweep degree 4) plus, on the training runs, a known cross term in fy
//! and in fx a wiggle whose sign alternates from run to run (no function of the pose), fy gets its term back, fx none, and the joint fit
//! reproduces the paper model.
use needle_fit::contract::COMPONENTS;
use needle_fit::coupled::{scales, select_and_fit};
use needle_fit::data::{load_paper_data, Run};
use needle_fit::eval::float64::{eval, eval_paper};
use needle_set::results::Row;
use needle_set::spec::{PoseSpec, Role};
use std::path::Path;

fn pose_of(p: &PoseSpec, depth_mm: f64) -> [f64; 5] {
    [p.x_mm, p.z_mm, p.theta_x_deg, p.theta_z_deg, depth_mm]
}

#[test]
fn each_component_chooses_its_own_size_and_the_cross_term_is_recovered() {
    // The paper form of the default set, fitted here on its sweeps (the set may ship
    // either form): its deviations are degree 4 in the swept value.
    let set = needle_set::set_folder::SetFolder::open(Path::new(needle_haptics::model_info::SET_DIR)).unwrap_or_else(|e| panic!("{e:#}"));
    let mut data = load_paper_data(&set).unwrap_or_else(|e| panic!("{e:#}"));
    let paper = needle_fit::model::fit(&data).unwrap_or_else(|e| panic!("{e:#}"));
    // The centre and sweep runs become the paper model's own values.
    let exact = |run: &mut Run| {
        for row in &mut run.rows {
            row.wrench = eval_paper(&paper, pose_of(&run.pose, row.depth_mm)).0;
        }
    };
    exact(&mut data.centre);
    for pts in &mut data.sweeps {
        for p in pts.iter_mut() {
            exact(&mut p.run);
        }
    }
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
            let rows = (0..=20)
                .map(|d| {
                    let depth_mm = 0.3 * f64::from(d);
                    let mut wrench = eval_paper(&paper, pose_of(&pose, depth_mm)).0;
                    wrench[1] += 0.004 * (pose.x_mm / 12.0) * (pose.theta_z_deg / 15.0) * (depth_mm / 3.0);
                    wrench[0] += if i % 2 == 0 { 2e-5 } else { -2e-5 } * (7.0 * depth_mm).sin();
                    Row { depth_mm, wrench }
                })
                .collect();
            Run { pose, file_name: String::new(), rows }
        })
        .collect();
    let refs: Vec<&Run> = runs.iter().collect();
    let scale = scales(&refs, 60.0);
    let (sel, model) = select_and_fit(&paper, &data, &refs, scale).unwrap_or_else(|e| panic!("{e:#}"));
    let cross = model.cross.as_ref().unwrap_or_else(|| panic!("the coupled model has cross terms"));
    // fx: cross terms would only fit the wiggle; the paper part needs sweep degree 4.
    assert_eq!((sel.choices[0].sweep_degree, sel.choices[0].cross), (4, None), "fx: {}", sel.choices[0].label());
    // Components without a cross term: exact (cv ~ 0) and any cross coefficient ~ 0.
    for c in [2, 3, 4, 5] {
        assert!(sel.rms_pct[c] < 1e-6, "{}: cv {} % on exact data", COMPONENTS[c], sel.rms_pct[c]);
        let worst = cross.terms.terms[c].iter().flat_map(|(_, p)| p.iter()).fold(0.0f64, |m, v| m.max(v.abs()));
        assert!(worst < 1e-9, "{}: cross coefficient {worst} where there is no cross term", COMPONENTS[c]);
    }
    let fy = sel.choices[1].cross.unwrap_or_else(|| panic!("fy needs its cross term: {}", sel.choices[1].label()));
    assert!(sel.rms_pct[1] < 1e-6 && sel.paper_rms_pct[1] > 0.1, "fy: cv {} %, paper {} %", sel.rms_pct[1], sel.paper_rms_pct[1]);
    // The fitted term: xi * beta with P(u) = 0.004 (u + 1).
    let (_, p) = cross.terms.terms[1].iter().find(|(e, _)| *e == [1, 0, 0, 1]).unwrap_or_else(|| panic!("no xi*beta term in {fy:?}"));
    assert!((p[0] - 0.004).abs() < 1e-9 && (p[1] - 0.004).abs() < 1e-9, "xi*beta: {p:?}");
    // The block's mirror symmetries hold exactly for the fitted model, although every
    // training run has every component nonzero: x -> -x flips (x, theta_z) and fx, my,
    // mz; z -> -z flips (z, theta_x) and fz, mx, my.
    for r in &runs {
        for row in r.rows.iter().step_by(4) {
            let p = pose_of(&r.pose, row.depth_mm);
            let w = eval(&model, p).0;
            let wx = eval(&model, [-p[0], p[1], p[2], -p[3], p[4]]).0;
            let wz = eval(&model, [p[0], -p[1], -p[2], p[3], p[4]]).0;
            assert_eq!(wx, [-w[0], w[1], w[2], w[3], -w[4], -w[5]], "x mirror of {} at {} mm", r.pose.name, row.depth_mm);
            assert_eq!(wz, [w[0], w[1], -w[2], -w[3], -w[4], w[5]], "z mirror of {} at {} mm", r.pose.name, row.depth_mm);
        }
    }
    // The joint fit's paper part is the paper model again (fy, away from the wiggle).
    for r in &runs {
        for row in &r.rows {
            let want = row.wrench[1];
            let got = eval(&model, pose_of(&r.pose, row.depth_mm)).0[1];
            assert!((got - want).abs() < 1e-9, "{} at {} mm: fy {got} N, data {want} N", r.pose.name, row.depth_mm);
        }
    }
}
