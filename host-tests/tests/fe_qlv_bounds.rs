//! The shipped set's viscoelastic verification (`needle fe verify --qlv`, issue 39): every
//! ramp-and-hold run of `[viscoelastic]` (each pose at each speed, with the campaign's
//! friction and without) that FEBio solved, in whole or in part, is in
//! `coeffs/default/fe/verify.toml` `[qlv]` and within the bounds: RMS <= 5 % (must) and
//! largest <= 6 % of peak |Fy|, every component, over what it solved. The numbers are
//! FEBio's and the library's filter's, written by the tool (never typed in).
//!
//! Which runs must be whole: without friction every pose at every speed (the filter's
//! verification proper: the QLV law alone); with the campaign's friction (0.5) the
//! centre and x+04 ([`WHOLE_WITH_FRICTION`]): FEBio inverts elements in the hold of the
//! z+04 runs at every speed (stopped at 19.0, 4.9 and 7.7 s with the current retry
//! ladder), which this test lists, not fails.

use needle_fe::visco::qlv::{QLV_MAX_PERCENT, QLV_MUST_RMS_PERCENT};
use needle_fe::visco::{run_name, Friction};
use std::path::Path;

/// Poses whose ramp-and-hold runs with the campaign's friction are solved through the
/// hold at every speed.
const WHOLE_WITH_FRICTION: [&str; 2] = ["centre", "x+04"];

#[test]
fn every_ramp_and_hold_run_is_within_the_bounds() {
    let set = Path::new(env!("CARGO_MANIFEST_DIR")).join("../coeffs/default");
    let (c, _) = needle_set::spec::load(&set).expect("the shipped spec");
    let v = c.viscoelastic.expect("coeffs/default has [viscoelastic]");
    assert!(v.frictionless, "the shipped set verifies the filter without friction too");
    let path = set.join("fe/verify.toml");
    let text = std::fs::read_to_string(&path).expect("fe/verify.toml");
    let t: toml::Table = text.parse().expect("verify.toml is TOML");
    let qlv = t.get("qlv").and_then(toml::Value::as_table).unwrap_or_else(|| panic!("{}: no [qlv]", path.display()));
    if let Some(missing) = qlv.get("missing").and_then(toml::Value::as_array) {
        println!("not solved by FEBio (no comparison): {missing:?}");
    }
    let runs = qlv.get("runs").and_then(toml::Value::as_array).unwrap_or_else(|| panic!("{}: no [[qlv.runs]]", path.display()));
    let num = |r: &toml::Value, k: &str| r.get(k).and_then(toml::Value::as_float).unwrap_or(f64::NAN);
    let mut whole = [0usize; 2];
    for (f, friction) in Friction::cases(&v).into_iter().enumerate() {
        let mu = if friction == Friction::None { 0.0 } else { c.contact.friction };
        for pose in &v.poses {
            let must_be_whole = friction == Friction::None || WHOLE_WITH_FRICTION.contains(&pose.as_str());
            for &speed in &v.speeds_mm_per_s {
                let name = friction.name(&run_name(pose, speed));
                let Some(r) = runs.iter().find(|r| r.get("run").and_then(toml::Value::as_str) == Some(name.as_str())) else {
                    assert!(!must_be_whole, "{name}: no comparison, but it was solved through its hold");
                    println!("{name}: no comparison (not solved)");
                    continue;
                };
                assert_eq!(num(r, "friction"), mu, "{name}: the run's friction");
                let is_whole = r.get("partial").and_then(toml::Value::as_bool) == Some(false);
                assert!(is_whole || !must_be_whole, "{name}: only partly solved, but it was solved through its hold");
                if is_whole {
                    whole[f] += 1;
                }
                let (rms, max) = (num(r, "worst_rms_percent"), num(r, "worst_max_percent"));
                assert!(rms <= QLV_MUST_RMS_PERCENT, "{name}: RMS {rms} % of peak |Fy| > {QLV_MUST_RMS_PERCENT} %");
                assert!(max <= QLV_MAX_PERCENT, "{name}: largest error {max} % of peak |Fy| > {QLV_MAX_PERCENT} %");
                assert!(num(r, "peak_fy_n") > 0.0, "{name}: no force measured");
            }
        }
    }
    let speeds = v.speeds_mm_per_s.len();
    assert!(
        whole[0] >= WHOLE_WITH_FRICTION.len() * speeds,
        "{}: {} runs with friction solved through their hold",
        path.display(),
        whole[0]
    );
    assert_eq!(whole[1], v.poses.len() * speeds, "{}: every frictionless run solved through its hold", path.display());
}
