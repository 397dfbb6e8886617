//! The specs of the viscoelastic ramp-and-hold runs (issue 39, item 3): the set's FE
//! tissue with the Prony series of `[viscoelastic]` in `tissue.prony` and the time course
//! in `loading.ramp_hold` ([`apply`]), so a run's hash never equals an elastic run's. The
//! engine (`needle_fe::visco`) solves them into `<set>/fe/visco/`; FEBio's time is then
//! seconds; the must points are [`RampHold::time_s`].

use super::settings::{frictionless_name, run_name, Prony, RampHold, ViscoSettings};

use crate::spec::{Campaign, PoseSpec};

/// Which contact the runs have: the campaign's (`contact.friction`) or friction 0
/// (`[viscoelastic] frictionless`, names with [`FRICTIONLESS_SUFFIX`](super::FRICTIONLESS_SUFFIX)).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Friction {
    /// The campaign's `[contact]` as it is.
    Campaign,
    /// `contact.friction` 0, every other contact setting the campaign's.
    None,
}

impl Friction {
    /// The cases `v` asks for, the campaign's first.
    pub fn cases(v: &ViscoSettings) -> Vec<Friction> {
        if v.frictionless {
            vec![Friction::Campaign, Friction::None]
        } else {
            vec![Friction::Campaign]
        }
    }

    /// `name` as a run of this case.
    pub fn name(self, name: &str) -> String {
        match self {
            Friction::Campaign => name.to_string(),
            Friction::None => frictionless_name(name),
        }
    }

    /// `c` with this case's contact.
    fn apply(self, c: &mut Campaign) {
        if self == Friction::None {
            c.contact.friction = 0.0;
        }
    }
}

/// The campaign as the runs at `speed_mm_per_s` see it (`ramp_steps` must points on the
/// ramp, the contact of `friction`), and their poses (renamed by [`run_name`] and
/// [`Friction::name`]).
pub fn apply(c: &Campaign, v: &ViscoSettings, speed_mm_per_s: f64, ramp_steps: u32, friction: Friction) -> (Campaign, Vec<PoseSpec>) {
    let mut run = c.clone();
    friction.apply(&mut run);
    run.tissue.prony = Some(Prony { g: v.g.clone(), tau_s: v.tau_s.clone() });
    run.loading.steps = ramp_steps + v.hold_steps;
    run.loading.ramp_hold = Some(RampHold {
        speed_mm_per_s,
        ramp_steps,
        hold_s: v.hold_s,
        hold_steps: v.hold_steps,
        hold_first_s: v.hold_first_s,
        min_residual_n: v.min_residual_n,
    });
    (run, renamed(c, v, |p| friction.name(&run_name(p, speed_mm_per_s))))
}

/// The campaign of the frictionless elastic companions (`[viscoelastic] frictionless`):
/// the elastic runs of `v.poses` with friction 0 (`<pose>_mu0`), the filter's input for
/// the frictionless ramp-and-hold runs; `None` when `v` has no frictionless runs.
pub fn apply_frictionless_elastic(c: &Campaign, v: &ViscoSettings) -> Option<(Campaign, Vec<PoseSpec>)> {
    if !v.frictionless {
        return None;
    }
    let mut run = c.clone();
    Friction::None.apply(&mut run);
    Some((run, renamed(c, v, frictionless_name)))
}

/// The poses of `v.poses`, renamed.
fn renamed(c: &Campaign, v: &ViscoSettings, name: impl Fn(&str) -> String) -> Vec<PoseSpec> {
    let every = c.poses();
    v.poses.iter().filter_map(|n| every.iter().find(|p| &p.name == n)).map(|p| PoseSpec { name: name(&p.name), ..p.clone() }).collect()
}

/// The manifest's line of a ramp-and-hold run (`None`: not one): its Prony series and
/// time course, with units.
pub fn describe(c: &Campaign) -> Option<String> {
    let (p, r) = (c.tissue.prony.as_ref()?, c.loading.ramp_hold.as_ref()?);
    let terms: Vec<String> = p.g.iter().zip(&p.tau_s).map(|(g, t)| format!("g {g} tau {t} s")).collect();
    Some(format!(
        "uncoupled viscoelastic (FEBio normalisation, g0 = 1) {}; ramp to {} mm at {} mm/s ({} s, {} must points), hold {} s ({} must points from {} s); Newton's residual floor {} N; Coulomb friction {}",
        terms.join(", "),
        c.loading.depth_mm,
        r.speed_mm_per_s,
        r.ramp_s(c.loading.depth_mm),
        r.ramp_steps,
        r.hold_s,
        r.hold_steps,
        r.hold_first_s,
        r.min_residual_n,
        c.contact.friction
    ))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spec::key_line;
    use std::path::Path;

    fn shipped() -> String {
        std::fs::read_to_string(needle_stdx::workspace_root().join("coeffs/default/campaign.toml")).expect("campaign.toml")
    }

    fn error_of(text: &str) -> String {
        crate::spec::parse(text, Path::new("campaign.toml")).err().map(|e| e.to_string()).unwrap_or_default()
    }

    #[test]
    fn the_shipped_section_makes_runs_that_never_pass_for_elastic_ones() {
        let c = crate::spec::parse(&shipped(), Path::new("campaign.toml")).expect("the shipped spec");
        let v = c.viscoelastic.clone().expect("coeffs/default has [viscoelastic]");
        assert_eq!(v.poses.first().map(String::as_str), Some("centre"), "the quarter model first");
        let (run, poses) = apply(&c, &v, 10.0, c.loading.steps, Friction::Campaign);
        assert_eq!(run.loading.steps, c.loading.steps + v.hold_steps);
        assert_eq!(poses.first().map(|p| p.name.as_str()), Some("centre_10mm-s"));
        let centre = c.poses().into_iter().find(|p| p.name == "centre").expect("centre");
        assert_ne!(run.run_hash(&centre, &v.mesh), c.run_hash(&centre, &v.mesh));
        // the ramp's must points are the elastic run's depths; the last is the hold's end
        assert_eq!(run.loading.depth_at(c.loading.steps), c.loading.depth_mm);
        assert_eq!(run.loading.time_at(run.loading.steps), c.loading.depth_mm / 10.0 + v.hold_s);
        let text = describe(&run).expect("a ramp-and-hold run");
        assert!(text.contains("at 10 mm/s (0.6 s") && text.contains("tau 0.5 s"), "{text}");
        assert_eq!(run_name("x+04", 1.5), "x+04_1p5mm-s");
    }

    #[test]
    fn frictionless_runs_and_their_elastic_companions_have_their_own_names_and_hashes() {
        let mut c = crate::spec::parse(&shipped(), Path::new("campaign.toml")).expect("the shipped spec");
        assert!(c.contact.friction > 0.0, "the shipped contact has friction");
        let mut v = c.viscoelastic.clone().expect("coeffs/default has [viscoelastic]");
        v.frictionless = false;
        assert_eq!(Friction::cases(&v), [Friction::Campaign]);
        assert!(apply_frictionless_elastic(&c, &v).is_none());
        v.frictionless = true;
        c.viscoelastic = Some(v.clone());
        assert_eq!(Friction::cases(&v), [Friction::Campaign, Friction::None]);
        let (with, with_poses) = apply(&c, &v, 3.0, c.loading.steps, Friction::Campaign);
        let (without, poses) = apply(&c, &v, 3.0, c.loading.steps, Friction::None);
        assert_eq!(with.contact.friction, c.contact.friction);
        assert_eq!(without.contact.friction, 0.0);
        assert_eq!(without.contact.penalty_slope_n_per_mm3, c.contact.penalty_slope_n_per_mm3);
        assert_eq!(poses.first().map(|p| p.name.as_str()), Some("centre_3mm-s_mu0"));
        let (w, f) = (&with_poses[0], &poses[0]);
        assert_ne!(with.run_hash(w, &v.mesh), without.run_hash(f, &v.mesh));
        assert!(describe(&without).is_some_and(|t| t.ends_with("Coulomb friction 0")));
        let (elastic, names) = apply_frictionless_elastic(&c, &v).expect("frictionless companions");
        assert_eq!(elastic.contact.friction, 0.0);
        assert!(elastic.tissue.prony.is_none() && elastic.loading.ramp_hold.is_none(), "elastic");
        assert_eq!(
            names.iter().map(|p| p.name.as_str()).collect::<Vec<_>>(),
            v.poses.iter().map(|p| frictionless_name(p)).collect::<Vec<_>>()
        );
        let centre = c.poses().into_iter().find(|p| p.name == "centre").expect("centre");
        assert_ne!(elastic.run_hash(&names[0], &v.mesh), c.run_hash(&centre, &v.mesh));
    }

    #[test]
    fn bad_sections_are_refused_with_file_line_and_field() {
        let text = shipped();
        let line = |key: &str| key_line(&text, "viscoelastic", key);
        // the section's own line replaced (`mesh = ...` is in [campaign] too)
        let with = |key: &str, bad: &str| -> String {
            let n = line(key);
            text.lines().enumerate().map(|(i, l)| if i + 1 == n { format!("{bad}\n") } else { format!("{l}\n") }).collect()
        };
        let cases = [
            ("g", "g = [-0.1, 0.4]", "every g_i must be finite and >= 0"),
            ("g", "g = [0.1, 0.1, 0.1, 0.1]", "must be 1 ..= 3"),
            ("g", "g = [5.0, 4.5]", "sums to 9.5: must be <= 9"),
            ("tau_s", "tau_s = [0.0, 5.0]", "must be finite and > 0 s"),
            ("tau_s", "tau_s = [1.0]", "one tau_s per g"),
            ("speeds_mm_per_s", "speeds_mm_per_s = [1.0, 1.0]", "listed twice"),
            ("speeds_mm_per_s", "speeds_mm_per_s = [0.0]", "must be finite and > 0"),
            ("hold_s", "hold_s = -1.0", "must be finite and > 0"),
            ("hold_first_s", "hold_first_s = 40.0", "must be in (0, hold_s"),
            ("mesh", "mesh = \"nope\"", "no [mesh.nope] level"),
            ("poses", "poses = [\"centre\", \"nope\"]", "not a pose of this campaign"),
        ];
        for (key, bad, want) in cases {
            let msg = error_of(&with(key, bad));
            assert!(msg.starts_with(&format!("campaign.toml:{}: viscoelastic.", line(key))) && msg.contains(want), "{key}: {msg}");
        }
        let msg = error_of(&text.replacen("stretch_max = 2.5\n", "stretch_max = 2.5\nprony = { g = [0.1], tau_s = [1.0] }\n", 1));
        assert!(msg.contains("tissue.prony: set by [viscoelastic]"), "{msg}");
    }
}
