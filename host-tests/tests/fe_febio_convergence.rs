//! FEBio's convergence settings in `[solver.febio]` reach the input file and the run hash
//! (crates/fe/src/spec.rs `FebioSettings`, crates/fe/src/febio/feb.rs): the residual
//! floor `min_residual_n2` is written as FEBio's `min_residual` (FEBio's own 1e-20 when
//! 0), changes the hash of a FEBio run only when set, and a negative floor is refused.
use needle_fe::febio::feb;
use needle_fe::spec::{self, Campaign, PoseSpec};
use std::path::Path;

fn default_campaign() -> Campaign {
    let set = Path::new(env!("CARGO_MANIFEST_DIR")).join("../coeffs/default");
    spec::load(&set).unwrap_or_else(|e| panic!("{e:#}")).0
}

fn centre(c: &Campaign) -> PoseSpec {
    c.poses().into_iter().find(|p| p.name == "centre").expect("the default set has a centre pose")
}

/// The `<min_residual>` line of the centre pose's first-attempt input.
fn min_residual_line(c: &Campaign) -> String {
    let level = c.mesh_level("smoke").unwrap_or_else(|e| panic!("{e:#}"));
    let f = feb::write(c, &centre(c), level, 2, 1.0).unwrap_or_else(|e| panic!("{e:#}"));
    f.text.lines().find(|l| l.contains("<min_residual>")).expect("a min_residual line").trim().to_string()
}

#[test]
fn the_residual_floor_reaches_the_input_and_the_hash_only_when_set() {
    let mut c = default_campaign();
    c.solver.engine = spec::Engine::Febio;
    c.solver.febio.min_residual_n2 = 0.0;
    let pose = centre(&c);
    let unset = c.run_hash(&pose, "smoke");
    assert_eq!(min_residual_line(&c), "<min_residual>1e-20</min_residual>");

    c.solver.febio.min_residual_n2 = 6.25e-8;
    assert_eq!(min_residual_line(&c), "<min_residual>6.25e-8</min_residual>");
    assert_ne!(c.run_hash(&pose, "smoke"), unset, "a floor changes what FEBio accepts: the runs must be redone");
}

#[test]
fn a_negative_residual_floor_is_refused() {
    let dir = tempfile::tempdir().expect("tempdir");
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("../coeffs/default/campaign.toml");
    let text = std::fs::read_to_string(src).expect("read the default spec");
    let text = text.replacen("[solver.febio]\n", "[solver.febio]\nmin_residual_n2 = -1e-8\n", 1);
    std::fs::write(dir.path().join("campaign.toml"), text).expect("write spec");
    let e = spec::load(dir.path()).expect_err("a negative floor");
    let msg = format!("{e:#}");
    assert!(msg.contains("solver.febio.min_residual_n2 = -0.00000001") || msg.contains("solver.febio.min_residual_n2 = -1e-8"), "{msg}");
}
