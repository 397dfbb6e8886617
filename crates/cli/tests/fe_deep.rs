//! `needle fe run --deep` and `needle fe verify --scaling` end to end on FEBio, on the
//! smoke mesh (seconds): the deep run lands in fe/deep/ at the deep depth with its own
//! manifest; the scaled runs reproduce s x the s = 1 wrench. They need `febio4`
//! (`.ci/install-febio`); without it they fail, they are not skipped.

mod common;
use common::{campaign_copy, needle_on, show};

use needle_set::manifest::{read_manifest, MANIFEST};
use needle_set::results;

/// Load steps of the deep smoke run: about 0.6 mm each (with steps of 2.6 mm the smoke
/// mesh's contact is never found: Fy = 0 at every depth).
const STEPS: u32 = 22;

/// The centre to the deep depth on the smoke mesh in [`STEPS`] steps: fe/deep/centre.csv from 0 to
/// deep.depth_mm with Fy growing, its manifest entry at that depth, nothing in fe/.
#[test]
fn deep_centre_run_on_the_smoke_mesh() {
    let (_d, set) = campaign_copy();
    let o = needle_on(&["fe", "run", "--deep", "--only", "centre", "--mesh", "smoke", "--steps", "22", "--threads", "1"], &set);
    assert!(o.status.success(), "{}", show(&o));
    let (c, _) = needle_set::spec::load(&set).expect("spec");
    let depth_mm = c.deep.as_ref().map(|d| d.depth_mm).expect("a [deep] section");
    let rows = results::read_csv(&set.join("fe/deep/centre.csv")).expect("deep csv");
    let want: Vec<f64> = (0..=STEPS).map(|k| depth_mm * f64::from(k) / f64::from(STEPS)).collect();
    assert_eq!(rows.iter().map(|r| r.depth_mm).collect::<Vec<_>>(), want);
    let fy: Vec<f64> = rows.iter().map(results::Row::fy_n).collect();
    assert!(fy.windows(2).all(|w| w[1] > w[0]), "Fy grows with depth: {fy:?}");
    let m = read_manifest(&set.join("fe/deep").join(MANIFEST)).expect("deep manifest");
    assert_eq!((m.pose["centre"].depth_mm, m.pose["centre"].steps, m.pose["centre"].mesh.as_str()), (depth_mm, STEPS, "smoke"));
    assert!(!set.join("fe/centre.csv").exists(), "the shallow folder is not written");
    // resumed, not solved again
    let again = needle_on(&["fe", "run", "--deep", "--only", "centre", "--mesh", "smoke", "--steps", "22", "--threads", "1"], &set);
    assert!(again.status.success() && String::from_utf8_lossy(&again.stdout).contains("up to date"), "{}", show(&again));
}

/// The centre on the smoke mesh at s = 1 (the set's fe/), then `verify --scaling`: the
/// runs at s = 0.5 and 2 equal s x the s = 1 wrench within the goal, in verify.toml.
#[test]
fn scaling_check_on_the_smoke_mesh() {
    let (_d, set) = campaign_copy();
    let base = needle_on(&["fe", "run", "--only", "centre", "--mesh", "smoke", "--steps", "5", "--threads", "1"], &set);
    assert!(base.status.success(), "{}", show(&base));
    let args =
        ["fe", "verify", "--scaling", "--scaling-poses", "centre", "--scaling-mesh", "smoke", "--scaling-steps", "5", "--threads", "1"];
    let o = needle_on(&args, &set);
    assert!(o.status.success(), "{}", show(&o));
    let text = std::fs::read_to_string(set.join("fe/verify.toml")).expect("verify.toml");
    let runs: Vec<&str> = text.split("[[scaling.runs]]").skip(1).collect();
    assert_eq!(runs.len(), 2, "{text}");
    for r in runs {
        let value = |key: &str| -> f64 {
            let line = r.lines().find(|l| l.starts_with(&format!("{key} = "))).unwrap_or_else(|| panic!("no {key} in {r}"));
            line[key.len() + 3..].trim().parse().unwrap_or_else(|e| panic!("{line}: {e}"))
        };
        let (s, worst, ratio) = (value("scale"), value("worst_percent"), value("fy_ratio_at_full_depth"));
        assert!(worst <= 0.5 && (ratio / s - 1.0).abs() < 0.005, "s = {s}: {worst} %, ratio {ratio}\n{text}");
    }
    assert!(set.join("fe/.work/verify/scaling-s0.5/centre.csv").exists(), "the scaled runs are kept for resuming");
    // a scaled run that is there is read, not solved again
    let again = needle_on(&args, &set);
    assert!(again.status.success() && String::from_utf8_lossy(&again.stdout).contains("up to date"), "{}", show(&again));
}
