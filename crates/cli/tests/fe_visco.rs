//! `needle fe run --visco` and `needle fe verify --qlv` end to end on FEBio, on the smoke
//! mesh (CI's budget: about two minutes): the centre's ramp-and-hold runs, with the
//! campaign's friction and without (with the frictionless elastic companion), land in
//! fe/visco/ with a time column and their manifest, are resumed, and the QLV check compares them
//! with the library's filter into verify.toml and the figure. They need `febio4`
//! (`.ci/install-febio`); without it they fail, they are not skipped. The bounds are
//! judged on the campaign's runs (host-tests/tests/fe_qlv_bounds.rs), not on this mesh.

mod common;

use common::{campaign_copy, needle_on, show};
use needle_fe::visco::Friction;
use needle_set::manifest::{read_manifest, MANIFEST};
use std::path::Path;

/// Must points on the ramp (1.2 mm each; the smoke mesh finds the contact at this step).
const RAMP_STEPS: &str = "5";

#[test]
fn centre_ramp_and_hold_on_the_smoke_mesh_against_the_filter() {
    let (_d, set) = campaign_copy();
    let (c, _) = needle_set::spec::load(&set).expect("spec");
    let v = c.viscoelastic.clone().expect("[viscoelastic]");
    let args = ["fe", "verify", "--qlv", "--qlv-poses", "centre", "--qlv-mesh", "smoke", "--qlv-steps", RAMP_STEPS, "--threads", "1"];
    let o = needle_on(&args, &set);
    let out = String::from_utf8_lossy(&o.stdout).to_string();
    // solved and compared (the exit status judges the bounds, which are the campaign's)
    assert!(o.status.code().is_some_and(|c| c <= 1) && out.contains("qlv centre_10mm-s"), "{}", show(&o));
    let m = read_manifest(&set.join("fe/visco").join(MANIFEST)).expect("visco manifest");
    let frictions = Friction::cases(&v);
    assert_eq!(frictions.len(), 2, "the shipped set also runs frictionless");
    for (friction, &speed) in frictions.iter().flat_map(|f| v.speeds_mm_per_s.iter().map(move |s| (f, s))) {
        let run = friction.name(&needle_fe::visco::run_name("centre", speed));
        let text = std::fs::read_to_string(set.join(format!("fe/visco/{run}.csv"))).expect("visco csv");
        let (times, rows) = needle_set::results::parse_timed_csv(&text, Path::new(&run)).expect("timed csv");
        let steps = 5 + v.hold_steps as usize;
        assert_eq!((times.len(), rows.len()), (steps + 1, steps + 1), "{run}");
        let end = c.loading.depth_mm / speed + v.hold_s;
        assert!((times[steps] - end).abs() < 1e-9 * end, "{run}: ends at {} s, not {end} s", times[steps]);
        // the hold relaxes: Fy at the hold's end below Fy at the ramp's end
        let (ramp_end, hold_end) = (rows[5].fy_n(), rows[steps].fy_n());
        assert!(ramp_end > 0.0 && hold_end < ramp_end, "{run}: Fy {ramp_end} N at the ramp's end, {hold_end} N at the hold's");
        let e = &m.pose[&run];
        let mu = if *friction == Friction::None { 0.0 } else { c.contact.friction };
        let line = e.viscoelastic.as_deref().unwrap_or_default();
        assert!(line.contains(&format!("at {speed} mm/s")) && line.ends_with(&format!("Coulomb friction {mu}")), "{run}: {line}");
    }
    // the frictionless runs' input: the elastic companion without friction, beside them
    let companion = needle_fe::visco::frictionless_name("centre");
    assert!(m.pose.contains_key(&companion) && set.join(format!("fe/visco/{companion}.csv")).is_file(), "{companion}");
    let verify = std::fs::read_to_string(set.join("fe/verify.toml")).expect("verify.toml");
    assert_eq!(verify.matches("[[qlv.runs]]").count(), v.speeds_mm_per_s.len() * frictions.len(), "{verify}");
    assert!(set.join("figures").join("qlv-ramp-hold.svg").is_file(), "the figure");
    // resumed, not solved again
    let again =
        needle_on(&["fe", "run", "--visco", "--only", "centre_*", "--mesh", "smoke", "--steps", RAMP_STEPS, "--threads", "1"], &set);
    let out = String::from_utf8_lossy(&again.stdout);
    let runs = v.speeds_mm_per_s.len() * frictions.len() + 1;
    assert!(again.status.success() && out.matches("up to date").count() >= runs, "{}", show(&again));
}
