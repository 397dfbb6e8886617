//! The FEBio retry ladder's decisions (issue 42, item 2): what the next attempt at a pose
//! changes, given what the earlier attempts did and how far they got.
//!
//! The failed attempts by class (coeffs/default/README.md, "Failed attempts by class")
//! point at two things, and the ladder follows them:
//! - every attempt used to restart from depth 0, so a full-block attempt 2 died at first
//!   contact (0.19-0.49 mm) after attempt 1 had reached 0.98-5.39 mm. Now the attempt
//!   after a fresh attempt that reached a must point *continues* from the furthest
//!   attempt's last converged must point (its FEBio dump, kept as [`FURTHEST_DUMP`]) with
//!   the retry's settings: a first time step of [`RETRY_FIRST_INCREMENT`] of a load step
//!   (every time step of that load step at most that: the restart input caps the
//!   must-point curve there, `restart.rs`; before that fix FEBio took the dump's own
//!   step, and the settings lines of the continuations before it overstate their first
//!   step) and the retry tolerances (`retry_dtol`, `retry_rtol`: FEBio's restart input can set
//!   the Newton solver's parameters). In the failed logs "max nr of reformations" is the
//!   displacement norm stalling while the residual and energy norms have converged (a
//!   contact node chattering), which is what the retry tolerances judge differently;
//!   with the 0.4 mm edge the retry's own micrometre steps then stalled the residual
//!   norm, which `retry_min_residual_n` (an absolute floor, `[solver.febio]`) answers.
//!   FEBio's restart cannot change the contact (`seg_up`, the penalty): a continuation
//!   keeps the contact of the attempt whose dump it continues, and the manifest says so;
//! - `seg_up` 5 with whole first increments inverted elements at first contact in 17 of
//!   its 25 failures (0.19-0.60 mm): once an attempt failed there (before the must point
//!   that ends the first `first_contact_depth_mm`, `[solver.febio]`: that class,
//!   [`failed_at_first_contact`]), a later fresh attempt with whole load steps takes time
//!   steps of at most `first_contact_step_fraction` of a load step until then, whole
//!   steps after. Not on a first attempt: the cap makes the auto stepper climb back to
//!   whole steps slowly (measured: the needle8 centre took 46 time steps and
//!   50 s instead of 35 and 24 s, Fy within 0.17 % of peak; CI's smoke runs 23-24 time
//!   steps instead of 10, and z+02 on the smoke mesh then failed its first attempt).
//!
//! The fresh attempts keep the old ladder's order ([`fresh_order`]); a continuation is
//! inserted after a fresh attempt with whole steps that got further than any attempt
//! before it. When no attempt reaches a must point (a failure in the first load step)
//! the ladder is the old one. A continuation is not itself continued by a later attempt
//! (it already had the retry tolerances and its own continuations, `restart.rs`).
//!
//! The state of a pose's ladder ([`State`]) is kept in its work folder
//! ([`STATE_FILE`], beside the dump), so that each attempt decides from what is on disk.

use super::logs::RigidRecord;
use crate::backend::RETRY_FIRST_INCREMENT;
use anyhow::{Context, Result};
use needle_contract::COMPONENT_COUNT;
use serde::{Deserialize, Serialize};
use std::path::Path;

/// The ladder's state in a pose's work folder.
pub const STATE_FILE: &str = "ladder.toml";
/// The dump of the furthest failed attempt's last converged must point.
pub const FURTHEST_DUMP: &str = "furthest.dmp";

/// Which contact projection rule an attempt uses.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum SegUp {
    /// `seg_up` of the spec.
    Spec,
    /// `retry_seg_up` of the spec.
    Retry,
}

/// The settings of an attempt that starts from depth 0.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct Fresh {
    /// The contact projection rule.
    pub seg_up: SegUp,
    /// The penalty scaled by `last_attempt_penalty_scale`.
    pub softer: bool,
    /// The run's first time step [`RETRY_FIRST_INCREMENT`] of a load step and the retry
    /// tolerances; else whole load steps (after the first-contact steps) and the spec's
    /// tolerances.
    pub quarter: bool,
}

impl Fresh {
    /// First time step as a fraction of a load step (the manifest's `first_increment`):
    /// 1 for whole steps (their first-contact steps are in the settings line).
    pub fn first_increment(&self) -> f64 {
        if self.quarter {
            RETRY_FIRST_INCREMENT
        } else {
            1.0
        }
    }
}

/// What an attempt does.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(tag = "start", rename_all = "kebab-case")]
pub enum Plan {
    /// From depth 0 with these settings.
    Fresh(Fresh),
    /// From the furthest attempt's last converged must point ([`FURTHEST_DUMP`]), with the
    /// contact of that attempt (`contact`), a first time step of [`RETRY_FIRST_INCREMENT`]
    /// of a load step and the retry tolerances.
    Continue {
        /// The attempt (1-based) whose dump is continued.
        from_attempt: u32,
        /// Its must points reached.
        from_steps: u32,
        /// Its contact settings (the dump carries them).
        contact: Fresh,
    },
}

impl Plan {
    /// The contact settings the attempt runs with.
    pub fn contact(&self) -> Fresh {
        match *self {
            Plan::Fresh(f) => f,
            Plan::Continue { contact, .. } => contact,
        }
    }

    /// First time step as a fraction of a load step.
    pub fn first_increment(&self) -> f64 {
        match self {
            Plan::Fresh(f) => f.first_increment(),
            Plan::Continue { .. } => RETRY_FIRST_INCREMENT,
        }
    }

    /// Whether the attempt converges with the retry tolerances.
    pub fn retry_tolerances(&self) -> bool {
        match self {
            Plan::Fresh(f) => f.quarter,
            Plan::Continue { .. } => true,
        }
    }

    /// One line for the campaign's log: what the attempt changes (`depth_mm` in `steps`
    /// load steps).
    pub fn describe(&self, depth_mm: f64, steps: u32) -> String {
        let rule = |f: &Fresh| {
            let seg = match f.seg_up {
                SegUp::Spec => "seg_up",
                SegUp::Retry => "retry_seg_up",
            };
            format!("{seg}{}", if f.softer { ", softer penalty" } else { "" })
        };
        match self {
            Plan::Fresh(f) if f.quarter => {
                format!("from depth 0: {}, first time step {} of a load step, retry tolerances", rule(f), RETRY_FIRST_INCREMENT)
            }
            Plan::Fresh(f) => format!("from depth 0: {}, whole load steps after the first-contact steps", rule(f)),
            Plan::Continue { from_attempt, from_steps, contact } => format!(
                "continuing attempt {from_attempt} from its last converged must point ({} mm, its contact: {}), first time step {} of a load step, retry tolerances",
                depth_at(depth_mm, steps, *from_steps),
                rule(contact),
                RETRY_FIRST_INCREMENT
            ),
        }
    }
}

/// Depth of must point `k` of `steps` to `depth_mm`, as the campaign's CSV rows have it.
pub fn depth_at(depth_mm: f64, steps: u32, k: u32) -> f64 {
    depth_mm * f64::from(k) / f64::from(steps.max(1))
}

/// The old ladder's attempts from depth 0, in order (`FebioBackend::attempts`): the
/// model's projection rule, the other rule, both again with quarter first steps and the
/// retry tolerances, a softer penalty. The first rule is `seg_up` on half and quarter
/// models and `retry_seg_up` on the full block.
pub fn fresh_order(full_block: bool) -> [Fresh; 5] {
    let (a, b) = if full_block { (SegUp::Retry, SegUp::Spec) } else { (SegUp::Spec, SegUp::Retry) };
    let f = |seg_up, quarter, softer| Fresh { seg_up, softer, quarter };
    [f(a, false, false), f(b, false, false), f(a, true, false), f(b, true, false), f(SegUp::Spec, true, true)]
}

/// One attempt that failed.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Tried {
    /// 1-based.
    pub attempt: u32,
    /// What it did.
    pub plan: Plan,
    /// Must points it reached (from step 1 on, without a gap, a continuation's included).
    pub reached_steps: u32,
}

/// The attempt whose dump is kept.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Furthest {
    /// 1-based.
    pub attempt: u32,
    /// Must points reached; the dump is the state at the last of them.
    pub steps: u32,
    /// FEBio's rigid-body record at each must point 1..=steps (as logged: before the
    /// reaction sign and the mirror expansion).
    pub records: Vec<[f64; COMPONENT_COUNT]>,
    /// The manifest's settings line of that attempt (how the must points were reached).
    pub settings: String,
}

impl Furthest {
    /// The records as the rigid-body log's, at the solver's time of each must point.
    pub fn rigid_records(&self, loading: &crate::spec::Loading) -> Vec<RigidRecord> {
        (1u32..).zip(&self.records).map(|(k, v)| RigidRecord { time: loading.time_at(k), values: *v }).collect()
    }
}

/// A pose's ladder so far.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct State {
    /// The failed attempts, in order.
    #[serde(default)]
    pub tried: Vec<Tried>,
    /// The furthest failed attempt whose dump is kept ([`FURTHEST_DUMP`]).
    pub furthest: Option<Furthest>,
}

impl State {
    /// Read [`STATE_FILE`] in `work_dir`; none yet: the empty state.
    ///
    /// # Errors
    /// The file exists but cannot be read or parsed.
    pub fn read(work_dir: &Path) -> Result<State> {
        let p = work_dir.join(STATE_FILE);
        match std::fs::read_to_string(&p) {
            Ok(t) => toml::from_str(&t).with_context(|| format!("{}: not the retry ladder's state", p.display())),
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(State::default()),
            Err(e) => Err(e).with_context(|| format!("{}: cannot read", p.display())),
        }
    }

    /// Write [`STATE_FILE`] in `work_dir` atomically (a campaign killed while writing it
    /// leaves the earlier state, which its resumed attempt reads: `crate::resume`).
    ///
    /// # Errors
    /// It cannot be written.
    pub fn write(&self, work_dir: &Path) -> Result<()> {
        let p = work_dir.join(STATE_FILE);
        let text = format!(
            "# the FEBio retry ladder's state of this pose (fe/febio/ladder.rs); removed with the work folder\n{}",
            toml::to_string(self).context("cannot serialise the ladder's state")?
        );
        needle_stdx::fs::write_atomic(&p, text.as_bytes())
    }

    /// Whether a failed attempt that reached `steps` must points is further than the kept
    /// one (then its dump replaces the kept one).
    pub fn is_further(&self, steps: u32) -> bool {
        steps > 0 && self.furthest.as_ref().is_none_or(|f| steps > f.steps)
    }
}

/// Whether an earlier attempt from depth 0 failed at first contact: before must point
/// `first_contact_steps` (the load steps that start within `first_contact_depth_mm`).
/// A later fresh attempt with whole steps then takes the first-contact steps.
pub fn failed_at_first_contact(state: &State, first_contact_steps: u32) -> bool {
    state.tried.iter().any(|t| matches!(t.plan, Plan::Fresh(_)) && t.reached_steps < first_contact_steps)
}

/// Whether attempt `attempt`, a fresh one with whole load steps, ran with the first-contact
/// steps: an attempt before it failed at first contact ([`failed_at_first_contact`] of the
/// attempts before it, as when it was decided). Its dump carries that must-point curve,
/// which a continuation of it redefines (`restart.rs`); a spec whose first-contact
/// settings changed since is read as it is now.
pub fn had_first_contact_steps(state: &State, attempt: u32, first_contact_steps: u32) -> bool {
    let before = State { tried: state.tried.iter().filter(|t| t.attempt < attempt).cloned().collect(), furthest: None };
    failed_at_first_contact(&before, first_contact_steps)
}

/// The load steps (of `steps` to `depth_mm`) that start within `first_contact_depth_mm`.
pub fn first_contact_steps(first_contact_depth_mm: f64, depth_mm: f64, steps: u32) -> u32 {
    (1..=steps).take_while(|&k| depth_at(depth_mm, steps, k - 1) < first_contact_depth_mm - 1e-9 * depth_mm).count() as u32
}

/// The next attempt's plan (module docs): continue the furthest attempt when it started
/// from depth 0 with whole steps and has not been continued yet; else the first fresh
/// attempt of [`fresh_order`] not tried yet (the last one again when all were).
pub fn next(state: &State, full_block: bool) -> Plan {
    if let Some(f) = &state.furthest {
        let was = state.tried.iter().find(|t| t.attempt == f.attempt).map(|t| t.plan);
        let continued = state.tried.iter().any(|t| matches!(t.plan, Plan::Continue { from_attempt, .. } if from_attempt == f.attempt));
        if let Some(Plan::Fresh(contact)) = was {
            if !contact.quarter && !continued {
                return Plan::Continue { from_attempt: f.attempt, from_steps: f.steps, contact };
            }
        }
    }
    let order = fresh_order(full_block);
    let tried = |fr: &Fresh| state.tried.iter().any(|t| t.plan == Plan::Fresh(*fr));
    Plan::Fresh(order.iter().find(|fr| !tried(fr)).copied().unwrap_or(order[order.len() - 1]))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tried(attempt: u32, plan: Plan, reached_steps: u32) -> Tried {
        Tried { attempt, plan, reached_steps }
    }

    fn furthest(attempt: u32, steps: u32) -> Option<Furthest> {
        Some(Furthest { attempt, steps, records: vec![[0.0; COMPONENT_COUNT]; steps as usize], settings: String::new() })
    }

    /// Without a must point reached the ladder is the old one, on either model.
    #[test]
    fn attempts_that_reach_no_must_point_climb_the_old_ladder() {
        for full in [false, true] {
            let mut s = State::default();
            let mut plans = Vec::new();
            for attempt in 1..=5 {
                let p = next(&s, full);
                plans.push(p);
                s.tried.push(tried(attempt, p, 0));
            }
            let want: Vec<Plan> = fresh_order(full).iter().map(|f| Plan::Fresh(*f)).collect();
            assert_eq!(plans, want, "full block {full}");
        }
        let o = fresh_order(true);
        assert_eq!((o[0].seg_up, o[1].seg_up, o[4].seg_up), (SegUp::Retry, SegUp::Spec, SegUp::Spec), "the full block swaps the rules");
        assert_eq!(fresh_order(false)[0].seg_up, SegUp::Spec);
        assert!(o[4].softer && o[4].quarter && !o[0].quarter && !o[1].quarter && o[2].quarter);
    }

    /// A fresh attempt with whole steps that reached must points is continued by the next
    /// attempt (not restarted from 0), with its contact; the attempt after that goes back
    /// to the fresh ladder where it was.
    #[test]
    fn the_attempt_after_one_that_got_somewhere_continues_it() {
        let a = fresh_order(true);
        let mut s = State { tried: vec![tried(1, Plan::Fresh(a[0]), 6)], furthest: furthest(1, 6) };
        let p = next(&s, true);
        assert_eq!(p, Plan::Continue { from_attempt: 1, from_steps: 6, contact: a[0] });
        assert!(p.retry_tolerances() && p.first_increment() == RETRY_FIRST_INCREMENT);
        assert!(
            p.describe(6.0, 20).contains("continuing attempt 1 from its last converged must point (1.8 mm, its contact: retry_seg_up)"),
            "{}",
            p.describe(6.0, 20)
        );
        // the continuation got to 9 must points: its dump is the furthest now, but a
        // continuation is not continued again: the other rule from depth 0
        s.tried.push(tried(2, p, 9));
        s.furthest = furthest(2, 9);
        assert_eq!(next(&s, true), Plan::Fresh(a[1]));
        // that fresh attempt got further still: continue it
        s.tried.push(tried(3, Plan::Fresh(a[1]), 12));
        s.furthest = furthest(3, 12);
        assert_eq!(next(&s, true), Plan::Continue { from_attempt: 3, from_steps: 12, contact: a[1] });
        s.tried.push(tried(4, next(&s, true), 12));
        // attempt 3 was continued: the next fresh attempt not tried yet
        assert_eq!(next(&s, true), Plan::Fresh(a[2]));
    }

    /// A fresh attempt that did not get further than the kept one is not continued (the
    /// kept one already was), and an attempt with quarter steps and the retry tolerances
    /// is not continued with the same settings.
    #[test]
    fn only_a_further_whole_step_attempt_is_continued() {
        let a = fresh_order(false);
        let s = State {
            tried: vec![
                tried(1, Plan::Fresh(a[0]), 4),
                tried(2, Plan::Continue { from_attempt: 1, from_steps: 4, contact: a[0] }, 4),
                tried(3, Plan::Fresh(a[1]), 2),
            ],
            furthest: furthest(1, 4),
        };
        assert_eq!(next(&s, false), Plan::Fresh(a[2]), "attempt 1 was continued already; attempt 3 got less far");
        let q = State { tried: vec![tried(1, Plan::Fresh(a[2]), 5)], furthest: furthest(1, 5) };
        assert_eq!(next(&q, false), Plan::Fresh(a[0]), "a quarter-step attempt is not continued with its own settings");
        assert!(State::default().is_further(1) && !State::default().is_further(0));
        assert!(!s.is_further(4) && s.is_further(5));
    }

    /// The first-contact steps follow a failure at first contact only.
    #[test]
    fn first_contact_steps_follow_a_failure_there() {
        assert_eq!(first_contact_steps(0.6, 6.0, 20), 2, "0-0.3 and 0.3-0.6 mm");
        assert_eq!(first_contact_steps(0.6, 6.0, 10), 1);
        assert_eq!(first_contact_steps(0.0, 6.0, 20), 0, "off");
        assert_eq!(first_contact_steps(0.61, 6.0, 20), 3);
        let a = fresh_order(true);
        let at = |reached: u32| State { tried: vec![tried(1, Plan::Fresh(a[0]), reached)], furthest: None };
        assert!(!failed_at_first_contact(&State::default(), 2), "not on a first attempt");
        assert!(failed_at_first_contact(&at(0), 2) && failed_at_first_contact(&at(1), 2));
        assert!(!failed_at_first_contact(&at(2), 2), "past 0.6 mm: another class");
        let cont = State { tried: vec![tried(2, Plan::Continue { from_attempt: 1, from_steps: 1, contact: a[0] }, 1)], furthest: None };
        assert!(!failed_at_first_contact(&cont, 2), "a continuation starts past the surface");
        // the attempts before attempt 2 failed at first contact: it had the steps, attempt 1 not
        let mut s = at(0);
        s.tried.push(tried(2, Plan::Fresh(fresh_order(false)[1]), 7));
        assert!(had_first_contact_steps(&s, 2, 2) && !had_first_contact_steps(&s, 1, 2));
        assert!(!had_first_contact_steps(&s, 2, 0), "off");
    }

    #[test]
    fn the_state_survives_its_file() {
        let d = tempfile::tempdir().expect("tempdir");
        assert_eq!(State::read(d.path()).expect("none yet"), State::default());
        let a = fresh_order(true);
        let s = State {
            tried: vec![tried(1, Plan::Fresh(a[0]), 3), tried(2, Plan::Continue { from_attempt: 1, from_steps: 3, contact: a[0] }, 3)],
            furthest: Some(Furthest { attempt: 1, steps: 2, records: vec![[1.0, -2.5e-3, 0.0, 0.0, 4.0, 1e-9]; 2], settings: "x".into() }),
        };
        s.write(d.path()).expect("write");
        assert_eq!(State::read(d.path()).expect("read"), s);
        let r = s
            .furthest
            .as_ref()
            .map(|f| f.rigid_records(&crate::spec::Loading { depth_mm: 6.0, steps: 20, ramp_hold: None }))
            .unwrap_or_default();
        assert_eq!(r.iter().map(|r| r.time).collect::<Vec<_>>(), [0.3, 0.6]);
        std::fs::write(d.path().join(STATE_FILE), "tried = 3").expect("write");
        assert!(State::read(d.path()).is_err(), "a corrupt state is an error, not a fresh ladder");
    }
}
