//! The material check run before any FE solve (crates/fe/src/material.rs).

use needle_fe::material::{self, Mode};
use needle_set::spec::{self, Tissue};
use std::path::{Path, PathBuf};

fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

fn tissue(mu: &[f64], alpha: &[f64]) -> Tissue {
    Tissue { mu_n_per_mm2: mu.to_vec(), alpha: alpha.to_vec(), bulk_to_shear: 100.0, stretch_min: 0.4, stretch_max: 2.5, prony: None }
}

/// Spacing of the log-spaced stretch grid of the check, as a ratio.
fn grid_ratio(t: &Tissue) -> f64 {
    ((t.stretch_max / t.stretch_min).ln() / (material::SAMPLES - 1) as f64).exp()
}

/// Uniaxial nominal stress T(l) = sum 2 mu_i / alpha_i (l^(a-1) - l^(-a/2-1)), written
/// out independently of the module.
fn uniaxial_nominal(t: &Tissue, l: f64) -> f64 {
    t.mu_n_per_mm2.iter().zip(&t.alpha).map(|(&mu, &a)| 2.0 * mu / a * (l.powf(a - 1.0) - l.powf(-a / 2.0 - 1.0))).sum()
}

/// d(sigma)/d(ln l) with sigma = l T(l), by central differences.
fn uniaxial_true_tangent_fd(t: &Tissue, l: f64) -> f64 {
    let e: f64 = 1e-6;
    let s = |x: f64| x * uniaxial_nominal(t, x);
    (s(l * e.exp()) - s(l * (-e).exp())) / (2.0 * e)
}

#[test]
fn shipped_default_set_passes() {
    let (campaign, _) = spec::load(&repo().join("coeffs/default")).unwrap();
    let r = material::check(&campaign.tissue).unwrap_or_else(|e| panic!("{e:#}"));
    eprintln!("{r}\n{}", serde_json::to_string_pretty(&r).unwrap());
    assert!((r.mu0_n_per_mm2 - 0.517e-3).abs() < 1e-12, "mu0 = {}", r.mu0_n_per_mm2);
    assert!((r.k0_n_per_mm2 - 100.0 * 0.517e-3).abs() < 1e-12);
    assert!((r.d1_mm2_per_n - 2.0 / (100.0 * 0.517e-3)).abs() < 1e-9);
    assert!(r.is_stable());
    assert_eq!(r.modes.len(), 3);
    for m in &r.modes {
        assert!(m.failure.is_none(), "{m:?}");
        assert!(m.min_tangent_n_per_mm2 > 0.0 && m.min_drucker_n_per_mm2 > 0.0, "{m:?}");
    }
    assert_eq!((r.stretch_min, r.stretch_max), (0.4, 2.5));
    // The uniaxial path tangent agrees with the nominal-stress formula.
    let t = &campaign.tissue;
    for l in [0.5, 0.92, 1.0, 1.7, 2.4] {
        let (fd, min) = (uniaxial_true_tangent_fd(t, l), r.mode(Mode::Uniaxial).unwrap().min_tangent_n_per_mm2);
        assert!(fd >= min * (1.0 - 1e-6), "tangent at {l}: {fd} below the reported minimum {min}");
    }
}

#[test]
fn table1_as_printed_is_refused_on_initial_shear_modulus() {
    let dir = repo().join("host-tests/tests/data/table1-as-printed");
    let (campaign, _) = spec::load(&dir).unwrap();
    assert_eq!(campaign.tissue.mu_n_per_mm2, vec![-0.288, 0.162, 0.067]);
    assert_eq!(campaign.tissue.alpha, vec![11.085, 11.265, 10.996]);
    assert_eq!(campaign.pose.len(), 1);
    let err = material::check(&campaign.tissue).expect_err("Table 1 as printed must be refused");
    let msg = format!("{err:#}");
    eprintln!("{msg}");
    assert!(msg.starts_with("tissue is unstable: initial shear modulus mu0 = sum mu_i = -0.059 N/mm^2 <= 0"), "{msg}");
    assert!(msg.contains("term 1: mu_1 = -0.288 N/mm^2, alpha_1 = 11.085"), "{msg}");
    assert!(!msg.contains("term 2") && !msg.contains("term 3"), "{msg}");
    assert!(!msg.contains("Drucker"), "the first failed check only: {msg}");
}

#[test]
fn negative_high_exponent_term_is_refused_in_uniaxial_tension() {
    // mu0 = 0.55e-3 N/mm^2 > 0: stable at small strain. The negative term grows as
    // l^6 and the positive one as l^2, so the principal tangent
    // h(l) = 2 (0.6e-3 l^2 - 0.05e-3 l^6) turns negative for l^4 > 12 (l > 1.86): the
    // uniaxial true stress stops rising at l = 1.895 (the lateral stretches l^-1/2 are
    // still stiff, so a bit later than 1.86), and equibiaxial compression loses
    // stability where its thickness stretch l^-2 reaches the same range.
    let t = tissue(&[0.6e-3, -0.05e-3], &[2.0, 6.0]);
    let err = material::check(&t).expect_err("must be refused");
    let msg = format!("{err:#}");
    eprintln!("{msg}");
    assert!(msg.starts_with("tissue is unstable: Drucker check fails in uniaxial tension at stretch 1.89"), "{msg}");
    assert!(msg.contains("also in equibiaxial compression"), "{msg}");
    assert!(msg.contains("term 2: mu_2 = -5e-5 N/mm^2"), "{msg}");

    // The onset agrees with the root of d(sigma)/d(ln l) of the nominal-stress formula.
    let (mut a, mut b) = (1.0, 2.5);
    assert!(uniaxial_true_tangent_fd(&t, a) > 0.0 && uniaxial_true_tangent_fd(&t, b) < 0.0);
    for _ in 0..60 {
        let m = 0.5 * (a + b);
        if uniaxial_true_tangent_fd(&t, m) > 0.0 {
            a = m;
        } else {
            b = m;
        }
    }
    let r = material::evaluate(&t).unwrap();
    assert!(!r.is_stable());
    let f = r.mode(Mode::Uniaxial).unwrap().failure.unwrap();
    assert!(f.stretch >= a && f.stretch <= a * grid_ratio(&t) * (1.0 + 1e-12), "onset {a}, reported {}", f.stretch);
    assert!(f.tangent_n_per_mm2 <= 0.0 && f.drucker_n_per_mm2 <= 0.0);
}

#[test]
fn transverse_loss_is_caught_although_the_path_tangent_is_positive() {
    // mu = (1.0e-3, -0.6e-3), alpha = (2, -2): h(l) = 2 (1.0e-3 l^2 - 0.6e-3 l^-2) < 0
    // for l < 0.6^(1/4). In uniaxial tension the lateral stretches l^-1/2 reach that at
    // l = 0.6^(-1/2) = 1.291: the lateral directions soften first, while
    // d(sigma)/d(ln l) along the test is still positive there.
    let t = tissue(&[1.0e-3, -0.6e-3], &[2.0, -2.0]);
    let msg = format!("{:#}", material::check(&t).expect_err("must be refused"));
    eprintln!("{msg}");
    assert!(msg.starts_with("tissue is unstable: Drucker check fails in uniaxial tension at stretch 1.29"), "{msg}");
    let r = material::evaluate(&t).unwrap();
    let f = r.mode(Mode::Uniaxial).unwrap().failure.unwrap();
    let onset = 0.6f64.powf(-0.5);
    assert!(f.stretch >= onset && f.stretch <= onset * grid_ratio(&t), "onset {onset}, reported {}", f.stretch);
    assert!(f.tangent_n_per_mm2 > 0.0 && uniaxial_true_tangent_fd(&t, f.stretch) > 0.0);
    assert!(f.drucker_n_per_mm2 <= 0.0);
}

#[test]
fn neo_hookean_like_term_passes() {
    let t = tissue(&[0.5e-3], &[2.0]);
    let r = material::check(&t).unwrap_or_else(|e| panic!("{e:#}"));
    eprintln!("{r}");
    assert!((r.mu0_n_per_mm2 - 0.5e-3).abs() < 1e-15);
    let (k0, mu0): (f64, f64) = (100.0 * 0.5e-3, 0.5e-3);
    let nu0 = (3.0 * k0 - 2.0 * mu0) / (2.0 * (3.0 * k0 + mu0));
    assert!((nu0 - 298.0 / 602.0).abs() < 1e-15);
    assert!((r.nu0 - nu0).abs() < 1e-9, "nu0 = {}", r.nu0);
    assert!((r.nu0 - 0.495).abs() < 1e-4);
    // Neo-Hookean uniaxial: d(sigma)/d(ln l) = mu (2 l^2 + 1/l), smallest at l = 4^(-1/3).
    let u = r.mode(Mode::Uniaxial).unwrap();
    let lmin = 4f64.powf(-1.0 / 3.0);
    let expect = 0.5e-3 * (2.0 * lmin * lmin + 1.0 / lmin);
    assert!((u.min_tangent_n_per_mm2 - expect).abs() < 1e-6 * expect, "{} vs {expect}", u.min_tangent_n_per_mm2);
    assert!((u.min_tangent_at_stretch / lmin - 1.0).abs() < 2e-3);
    // Planar: d(sigma)/d(ln l) = 2 mu (l^2 + l^-2), smallest (4 mu) at l = 1.
    let p = r.mode(Mode::Planar).unwrap();
    assert!((p.min_tangent_n_per_mm2 - 4.0 * 0.5e-3).abs() < 1e-8);
}

#[test]
fn nonpositive_bulk_modulus_is_refused() {
    let mut t = tissue(&[0.5e-3], &[2.0]);
    t.bulk_to_shear = -1.0;
    let msg = format!("{:#}", material::check(&t).unwrap_err());
    assert!(msg.starts_with("tissue is unstable: initial bulk modulus K0 = bulk_to_shear * mu0"), "{msg}");
    assert!(msg.contains("<= 0"), "{msg}");
}

#[test]
fn malformed_tissue_is_refused() {
    let mut t = tissue(&[0.5e-3, 0.1e-3], &[2.0]);
    assert!(format!("{:#}", material::check(&t).unwrap_err()).contains("must match"));
    t.alpha = vec![2.0, 0.0];
    assert!(format!("{:#}", material::check(&t).unwrap_err()).contains("alpha != 0"));
    t.alpha = vec![2.0, 4.0];
    t.stretch_min = 3.0;
    assert!(format!("{:#}", material::check(&t).unwrap_err()).contains("stretch range"));
}
