//! `needle fe verify --punch` end to end on CalculiX (deck -> ccx -> parse) on a coarse
//! mesh, against Sneddon's flat-punch force; and the punch deck's structure without a
//! solve. The solve needs `ccx` (Debian `calculix-ccx`); without it the test fails, it is
//! not skipped.

use needle_fe::verify::{self, PunchElement, VerifyOptions};
use needle_fe::{ccx, spec};
use std::path::{Path, PathBuf};

/// Tolerance of the coarse check, %. The coarse mesh (`punch_mesh_scale = 2`: 4 C3D20R
/// elements across the punch, h = a/2) over-predicts the force by the discretisation error
/// of the punch rim's stress singularity, which is first order in h: measured +5.0% at
/// h = a/2 (+3.35% at a/3, +2.5% at a/4, the verification mesh; about 0% extrapolated to
/// h -> 0). 8% leaves 3 points for solver and platform differences; a wrong modulus,
/// boundary condition, symmetry factor or reaction sum moves the result by far more.
const COARSE_TOLERANCE_PERCENT: f64 = 8.0;

/// A copy of coeffs/default/campaign.toml in a fresh temporary folder: (tempdir, set dir).
fn default_set() -> (tempfile::TempDir, PathBuf) {
    let d = tempfile::tempdir().expect("tempdir");
    let set = d.path().join("set");
    std::fs::create_dir_all(set.join("fe")).expect("mkdir");
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("../coeffs/default/campaign.toml");
    std::fs::copy(&src, set.join("campaign.toml")).expect("copy the default spec");
    (d, set)
}

#[test]
fn coarse_flat_punch_matches_sneddon() {
    let exe = ccx::find_ccx().unwrap_or_else(|e| panic!("{e:#}: this test runs CalculiX"));
    let v = ccx::ccx_version(&exe).unwrap_or_else(|e| panic!("{e:#}"));
    assert!(v.starts_with("2."), "ccx version {v}");
    let (_d, set) = default_set();
    let opts = VerifyOptions {
        set_dir: set.clone(),
        punch: true,
        mesh: None,
        edge: None,
        mirror: false,
        smooth: false,
        scaling: None,
        work_dir: None,
        punch_mesh_scale: 2.0,
        punch_campaign_element: false,
        threads: 1,
        engine: Some(spec::Engine::Ccx),
    };
    let folder = needle_set::set_folder::SetFolder::open(&opts.set_dir).unwrap_or_else(|e| panic!("{e:#}"));
    let (r, ok) = verify::run(&folder, &opts).unwrap_or_else(|e| panic!("{e:#}"));
    let p = r.punch.expect("a punch report");
    assert_eq!(p.check.element, "C3D20R");
    assert!(p.campaign_element.is_none());
    // Sneddon at the set's nu (K0/mu0 = bulk_to_shear, mu = 1): 4 mu a delta / (1 - nu)
    let (c, _) = spec::load(&set).expect("spec");
    let k = c.tissue.bulk_to_shear;
    let nu = (3.0 * k - 2.0) / (2.0 * (3.0 * k + 1.0));
    assert!((p.nu - nu).abs() < 1e-12, "nu {}", p.nu);
    let want = 4.0 * 1.0 * 0.5 * 0.005 / (1.0 - nu);
    assert!((p.force_sneddon_n - want).abs() < 1e-12 * want, "Sneddon {} N, expected {want} N", p.force_sneddon_n);
    // the finite block is stiffer than the half-space, the 2x block less so
    assert!(
        p.check.force_block_n > p.check.force_block_2x_n && p.check.force_block_2x_n > p.check.force_half_space_n,
        "F(1x) {} > F(2x) {} > F(inf) {} expected",
        p.check.force_block_n,
        p.check.force_block_2x_n,
        p.check.force_half_space_n
    );
    assert!(
        p.check.error_percent.abs() <= COARSE_TOLERANCE_PERCENT,
        "coarse flat punch: F(half-space) = {} N against Sneddon {} N: {:+.2}%, tolerance {COARSE_TOLERANCE_PERCENT}%",
        p.check.force_half_space_n,
        p.force_sneddon_n,
        p.check.error_percent
    );
    // the 5% goal is for the verification mesh (+2.5%); on this coarse one (+5.0%) it is
    // only reported
    println!("coarse punch: {:+.2}% (5% goal met on the coarse mesh: {ok})", p.check.error_percent);
    // verify.toml written with the punch table
    let text = std::fs::read_to_string(set.join("fe/verify.toml")).expect("verify.toml");
    let t: toml::Table = text.parse().expect("verify.toml is TOML");
    let punch = t.get("punch").and_then(|v| v.as_table()).expect("[punch] in verify.toml");
    let e = punch.get("error_percent").and_then(toml::Value::as_float).expect("punch.error_percent");
    assert!((e - p.check.error_percent).abs() < 1e-9);
}

/// The deck without a solve: 20-node elements, the punch's nodes on and inside its rim
/// (mid-side nodes of the rim on the circle), boundary sets present.
#[test]
fn punch_deck_structure() {
    let (_d, set) = default_set();
    let (c, _) = spec::load(&set).expect("spec");
    let a = c.needle.diameter_mm / 2.0;
    let mesh = verify::punch_mesh(a, verify::PUNCH_CORE_ELEMENTS_C3D20R, 2.0);
    assert_eq!(mesh.core_elements, 4);
    let d = verify::punch_deck(&c, &mesh, PunchElement::C3D20R, a, a / 100.0, 1.0).expect("deck");
    assert!(d.text.contains("*ELEMENT, TYPE=C3D20R, ELSET=BLOCK"));
    let d1 = format!("*HYPERELASTIC, NEO HOOKE\n5e-1, {:e}", 2.0 / c.tissue.bulk_to_shear);
    assert!(d.text.contains(&d1), "neo-Hookean C10 = mu/2, D1 = 2/K0: {d1}");
    for set in ["PUNCH", "BBOTTOM", "BSIDES", "SYMX", "SYMZ"] {
        assert!(d.text.contains(&format!("*NSET, NSET={set}\n")), "set {set}");
    }
    // nodes under the punch: read them back from the deck
    let coords: std::collections::HashMap<usize, [f64; 3]> = d
        .text
        .lines()
        .skip_while(|l| !l.starts_with("*NODE"))
        .skip(1)
        .take_while(|l| !l.starts_with('*'))
        .map(|l| {
            let f: Vec<&str> = l.split(',').collect();
            (f[0].parse().unwrap(), [f[1].parse().unwrap(), f[2].parse().unwrap(), f[3].parse().unwrap()])
        })
        .collect();
    let punch: Vec<usize> = d
        .text
        .lines()
        .skip_while(|l| *l != "*NSET, NSET=PUNCH")
        .skip(1)
        .take_while(|l| !l.starts_with('*'))
        .flat_map(|l| l.split(',').filter(|s| !s.is_empty()).map(|s| s.trim().parse::<usize>().unwrap()).collect::<Vec<_>>())
        .collect();
    assert_eq!(punch.len(), d.punch_nodes);
    let r: Vec<f64> = punch.iter().map(|i| coords[i]).map(|p| (p[0] * p[0] + p[2] * p[2]).sqrt()).collect();
    assert!(r.iter().all(|&x| x <= a * (1.0 + 1e-6)));
    // 4 elements across the diameter: the quarter rim has 4 edges, 5 corner and 4 mid-side nodes on the circle
    let on_rim = r.iter().filter(|&&x| (x - a).abs() < 1e-6).count();
    assert_eq!(on_rim, 9, "nodes on the punch rim");
    // C3D8 deck: 8-node elements, same corner mesh
    let d8 = verify::punch_deck(&c, &mesh, PunchElement::C3D8, a, a / 100.0, 1.0).expect("deck");
    assert!(d8.text.contains("*ELEMENT, TYPE=C3D8, ELSET=BLOCK"));
    assert_eq!(d8.elements, d.elements);
    assert!(d8.nodes < d.nodes);
}
