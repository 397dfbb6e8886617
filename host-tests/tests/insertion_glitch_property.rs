//! Issue 66's goal as a property, per compiled-in stack, in f32 and in fixed point: under
//! random glitch sequences laid over the golden insertion paths (jumps of 1e-3 to 1e9 mm
//! of x, z or depth and of 1e-3 to 1e9 degrees of a tilt, NaN, infinity, earlier poses
//! replayed: time going backwards), no wrench component ever exceeds its documented
//! bound (docs/insertion.md, "Glitches"), a glitch the step rejects punctures nothing,
//! and once every perturbed tick was rejected the ticks after it are the clean run's
//! within the documented recovery on every stack: [`RECOVERY_N`] from
//! [`RECOVERY_TICKS`] after the glitch, plus, where the deflected layer has Prony terms,
//! the filter's share ([`filter_share`]: the filter takes the elastic force's course over
//! a gap as a ramp). A glitch that hid the clean run's puncture or its deepest point (a
//! turn of the depth: the track's end) moves that event to the next accepted pose: such
//! sequences are measured apart. A perturbation small enough to be motion (a jump within
//! the largest speed, a replayed pose) is integrated as motion: only the bound holds for
//! it. `GLITCH_CASES` (default 10,000) sequences per stack.
#[path = "../../examples/common/insertion_paths.rs"]
mod paths;

use needle_contract::insertion_limits::{FORCE_LIMIT_N, MOMENT_LIMIT_NMM};
use needle_haptics::fixed;
use needle_haptics::fixed::insertion::{stacks as fixed_stacks, Insertion as FixedInsertion, InsertionConfig as FixedConfig};
use needle_haptics::insertion::{
    deflection, needle_axis, stacks, Insertion, InsertionConfig, InsertionEvaluation, Phase, Stack, FE_NEEDLE_DIAMETER_MM,
};
use needle_haptics::Pose;
use paths::{depth_scale, for_each_tick, for_each_tick_q16, PATHS};
use proptest::prelude::*;
use proptest::test_runner::{Config, TestRunner};

/// Ticks of a case's window, from a snapshot of the clean run.
const WINDOW: usize = 400;
/// Snapshots of the clean run every this many ticks.
const SNAP: usize = 100;
/// Ticks after the last perturbed tick from which the clean run's wrench is held to
/// [`RECOVERY_N`] plus the filter's share (docs/insertion.md, "Glitches").
const RECOVERY_TICKS: usize = 50;
/// The recovery's largest difference of a wrench component, N and N·mm, beside the
/// filter's share.
const RECOVERY_N: f32 = 1e-3;
/// The tick period of `InsertionConfig::DEFAULT_1KHZ`, s.
const PERIOD_S: f32 = 0.001;

/// One perturbation: at window tick `at`, for `ticks` ticks.
#[derive(Clone, Copy, Debug)]
enum Kind {
    /// Input `input` (0..5: x, z, theta_x, theta_z, depth) plus `sign 10^exp`.
    Jump {
        input: usize,
        exp: f32,
        negative: bool,
    },
    NotANumber {
        input: usize,
    },
    Infinite {
        input: usize,
        negative: bool,
    },
    /// The clean pose of `back` ticks before.
    Back {
        back: usize,
    },
}

#[derive(Clone, Copy, Debug)]
struct Perturbation {
    at: usize,
    ticks: usize,
    kind: Kind,
}

fn kind() -> impl Strategy<Value = Kind> {
    prop_oneof![
        6 => (0..5usize, -3.0f32..9.0, any::<bool>()).prop_map(|(input, exp, negative)| Kind::Jump { input, exp, negative }),
        1 => (0..5usize).prop_map(|input| Kind::NotANumber { input }),
        1 => (0..5usize, any::<bool>()).prop_map(|(input, negative)| Kind::Infinite { input, negative }),
        2 => (1..60usize).prop_map(|back| Kind::Back { back }),
    ]
}

fn perturbations() -> impl Strategy<Value = Vec<Perturbation>> {
    prop::collection::vec(
        (0..WINDOW - 2 * RECOVERY_TICKS, 1..5usize, kind()).prop_map(|(at, ticks, kind)| Perturbation { at, ticks, kind }),
        1..5,
    )
}

/// The clean run of one path: its poses (f32 and Q16.16), evaluations and snapshots.
struct Clean {
    poses: Vec<[f32; 5]>,
    poses_q16: Vec<[i32; 5]>,
    evals: Vec<InsertionEvaluation>,
    snaps: Vec<Insertion>,
    fixed_evals: Vec<fixed::insertion::InsertionEvaluation>,
    fixed_snaps: Vec<FixedInsertion<'static>>,
}

fn clean(s: usize, path: usize) -> Clean {
    let (stack, fixed_stack) = (&stacks::ALL[s], &fixed_stacks::ALL[s]);
    let mut poses = Vec::new();
    for_each_tick(PATHS[path], depth_scale(stack), |_, p| poses.push(p));
    let mut poses_q16 = Vec::new();
    for_each_tick_q16(PATHS[path], depth_scale(stack), |_, p| poses_q16.push(p));
    let mut ins = Insertion::new(stack, InsertionConfig::DEFAULT_1KHZ).expect("shipped stack");
    let mut fins = FixedInsertion::new(fixed_stack, FixedConfig::DEFAULT_1KHZ).expect("shipped stack");
    let (mut evals, mut snaps, mut fixed_evals, mut fixed_snaps) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    for (k, (p, q)) in poses.iter().zip(&poses_q16).enumerate() {
        if k % SNAP == 0 {
            snaps.push(ins);
            fixed_snaps.push(fins);
        }
        evals.push(ins.step(&pose(*p)));
        fixed_evals.push(fins.step(&fixed::Pose::new(q[0], q[1], q[2], q[3], q[4])));
    }
    Clean { poses, poses_q16, evals, snaps, fixed_evals, fixed_snaps }
}

fn pose(p: [f32; 5]) -> Pose {
    Pose { x_mm: p[0], z_mm: p[1], theta_x_deg: p[2], theta_z_deg: p[3], depth_mm: p[4] }
}

/// The window's poses with the perturbations laid over them (later ones win), and
/// which ticks are perturbed.
fn perturbed<T: Copy>(clean: &[T], start: usize, ps: &[Perturbation], apply: impl Fn(T, &Kind, Option<T>) -> T) -> (Vec<T>, Vec<bool>) {
    let mut out: Vec<T> = clean[start..start + WINDOW].to_vec();
    let mut hit = vec![false; WINDOW];
    for p in ps {
        for t in p.at..(p.at + p.ticks).min(WINDOW) {
            let back = match p.kind {
                Kind::Back { back } => (start + t).checked_sub(back).map(|i| clean[i]),
                _ => None,
            };
            out[t] = apply(out[t], &p.kind, back);
            hit[t] = true;
        }
    }
    (out, hit)
}

fn apply_f32(mut p: [f32; 5], k: &Kind, back: Option<[f32; 5]>) -> [f32; 5] {
    match *k {
        Kind::Jump { input, exp, negative } => p[input] += if negative { -1.0 } else { 1.0 } * 10f32.powf(exp),
        Kind::NotANumber { input } => p[input] = f32::NAN,
        Kind::Infinite { input, negative } => p[input] = if negative { f32::NEG_INFINITY } else { f32::INFINITY },
        Kind::Back { .. } => p = back.unwrap_or(p),
    }
    p
}

/// The same perturbation in Q16.16 (the value saturated; NaN has no integer: 0).
fn apply_q16(mut p: [i32; 5], k: &Kind, back: Option<[i32; 5]>) -> [i32; 5] {
    let sat = |v: f64| v.clamp(f64::from(i32::MIN), f64::from(i32::MAX)) as i32;
    match *k {
        Kind::Jump { input, exp, negative } => {
            p[input] = sat(f64::from(p[input]) + if negative { -1.0 } else { 1.0 } * 10f64.powf(f64::from(exp)) * 65536.0)
        }
        Kind::NotANumber { input } => p[input] = 0,
        Kind::Infinite { input, negative } => p[input] = if negative { i32::MIN } else { i32::MAX },
        Kind::Back { .. } => p = back.unwrap_or(p),
    }
    p
}

fn within_bound(w: [f32; 6]) -> bool {
    w[0].abs() + w[1].abs() + w[2].abs() <= FORCE_LIMIT_N as f32 && w[3].abs() + w[4].abs() + w[5].abs() <= MOMENT_LIMIT_NMM as f32
}

fn within_bound_fixed(w: [i32; 6]) -> bool {
    let w = w.map(i64::from);
    w[0].abs() + w[1].abs() + w[2].abs() <= i64::from(FORCE_LIMIT_N) * 1_000_000
        && w[3].abs() + w[4].abs() + w[5].abs() <= i64::from(MOMENT_LIMIT_NMM) * 1_000_000
}

/// A run of rejected ticks of a window: its first tick and the accepted tick after it
/// (window ticks).
#[derive(Clone, Copy, Debug)]
struct Gap {
    first: usize,
    accepted: usize,
}

/// The runs of rejected ticks (`rejected`) followed by an accepted tick.
fn gaps(rejected: &[bool]) -> Vec<Gap> {
    let mut out = Vec::new();
    let mut t = 0;
    while t < rejected.len() {
        if !rejected[t] {
            t += 1;
            continue;
        }
        let first = t;
        while t < rejected.len() && rejected[t] {
            t += 1;
        }
        if t < rejected.len() {
            out.push(Gap { first, accepted: t });
        }
    }
    out
}

/// Whether a gap hid the clean run's deepest point: a rejected tick deeper than both the
/// accepted ticks around its gap (the track's end is the deepest accepted pose).
fn hid_a_turn(c: &Clean, start: usize, gaps: &[Gap]) -> bool {
    gaps.iter().any(|g| {
        let depth = |t: usize| c.poses[start + t][4];
        let before = (start + g.first).checked_sub(1).map_or(f32::NEG_INFINITY, |k| c.poses[k][4]);
        let around = before.max(depth(g.accepted));
        (g.first..g.accepted).any(|t| depth(t) > around)
    })
}

/// The elastic force the clean run's deflected boundary gives the filter at (global)
/// tick `k`: the FE deflection of the layer its phase deflects (docs/insertion.md: at
/// `depth - q_j`, `q_j` the thicknesses above over the axis' vertical component), zero
/// when none with Prony terms is deflected.
fn filter_input(stack: &Stack<'_>, c: &Clean, k: usize) -> [f32; 6] {
    let Phase::Deflecting(j) = c.evals[k].phase else { return [0.0; 6] };
    let j = usize::from(j);
    if stack.layers[j].prony.as_slice().is_empty() {
        return [0.0; 6];
    }
    let p = pose(c.poses[k]);
    let above: f32 = stack.layers[..j].iter().map(|l| l.thickness_mm).sum();
    let q = above / needle_axis(&p)[1];
    let lambda = stack.needle_diameter_mm / FE_NEEDLE_DIAMETER_MM;
    deflection(&p, p.depth_mm - q, stack.layers[j].stiffness_scale, lambda).wrench.to_array()
}

/// The filter's share of the recovery at window tick `t` (docs/insertion.md,
/// "Glitches"): per gap of `n - 1` rejected ticks whose accepted tick is at or before
/// `t`, `sum_i g_i (1 - a_i^(n-1)) a_i^(t - accepted)` (`a_i = exp(-T / tau_i)`, the
/// largest over the stack's layers) times the total variation of the filter's input over
/// the gap's `n` ticks (the largest component's change per tick, summed). Zero on a
/// stack without Prony terms.
fn filter_share(stack: &Stack<'_>, c: &Clean, start: usize, gaps: &[Gap], t: usize) -> f32 {
    let input = |k: Option<usize>| k.map_or([0.0; 6], |k| filter_input(stack, c, k));
    let mut share = 0.0f32;
    for g in gaps.iter().filter(|g| g.accepted <= t) {
        let n = (g.accepted - g.first + 1) as i32;
        let mut variation = 0.0f32;
        for t in g.first..=g.accepted {
            let (now, before) = (input(Some(start + t)), input((start + t).checked_sub(1)));
            variation += now.iter().zip(before).map(|(a, b)| (a - b).abs()).fold(0.0, f32::max);
        }
        let weight = stack
            .layers
            .iter()
            .map(|l| {
                l.prony
                    .as_slice()
                    .iter()
                    .map(|p| {
                        let a = (-PERIOD_S / p.tau_s).exp();
                        p.g * (1.0 - a.powi(n - 1)) * a.powi((t - g.accepted) as i32)
                    })
                    .sum::<f32>()
            })
            .fold(0.0, f32::max);
        share += weight * variation;
    }
    share
}

fn cases() -> u32 {
    std::env::var("GLITCH_CASES").ok().and_then(|v| v.parse().ok()).unwrap_or(10_000)
}

/// What the sequences of one stack measured.
#[derive(Default)]
struct Tally {
    /// Sequences whose every perturbed tick was rejected and that hid no puncture or turn.
    recovered_cases: u32,
    /// Their ticks held to the recovery.
    recovered_ticks: u64,
    /// The largest difference from the clean run after recovery, N, and the largest of
    /// it over its bound.
    worst: f32,
    worst_ratio: f32,
    /// The largest difference where a glitch hid a puncture or a turn, N.
    worst_hidden: f32,
}

/// One window's perturbed run (f32 or fixed point): per tick whether it was perturbed,
/// whether the step rejected it, and its largest component's difference from the clean
/// run in `unit` (1 for N, 1e6 for µN).
struct Window {
    /// Whether the clean run (of the same precision) punctured in the tick.
    clean_punctures: Vec<bool>,
    hit: Vec<bool>,
    rejected: Vec<bool>,
    differences: Vec<f32>,
    unit: f32,
}

/// The recovery of one window's run: from [`RECOVERY_TICKS`] after the last perturbed
/// tick, each difference within `RECOVERY_N` plus the filter's share; nothing to hold
/// when a perturbed tick was integrated (then only the bound holds). `Err` names the
/// tick beyond.
fn recovery(stack: &Stack<'_>, c: &Clean, start: usize, w: &Window, tally: &mut Tally) -> Result<(), String> {
    let Window { clean_punctures, hit, rejected, differences, unit } = w;
    let unit = *unit;
    if hit.iter().zip(rejected).any(|(&h, &r)| h && !r) {
        return Ok(());
    }
    let last_hit = hit.iter().rposition(|&h| h).unwrap_or(0);
    let gaps = gaps(rejected);
    // a rejected tick that hid the clean run's puncture moves it to the next accepted
    // tick, whose pose sets the preload and the track; one that hid its deepest point
    // lowers the track's end: measured apart
    let hidden = hit.iter().zip(clean_punctures).any(|(&h, &p)| h && p) || hid_a_turn(c, start, &gaps);
    for (t, &d) in differences.iter().enumerate().skip(last_hit + RECOVERY_TICKS) {
        if hidden {
            tally.worst_hidden = tally.worst_hidden.max(d / unit);
            continue;
        }
        let bound = (RECOVERY_N + filter_share(stack, c, start, &gaps, t)) * unit;
        tally.worst = tally.worst.max(d / unit);
        tally.worst_ratio = tally.worst_ratio.max(d / bound);
        tally.recovered_ticks += 1;
        if d > bound {
            return Err(format!("tick {}: {d} from the clean run after recovery, beyond {bound}", start + t));
        }
    }
    if !hidden {
        tally.recovered_cases += 1;
    }
    Ok(())
}

#[test]
fn random_glitch_sequences_stay_bounded_and_recover() {
    for s in 0..stacks::ALL.len() {
        let stack = &stacks::ALL[s];
        let name = stack.name;
        let runs: Vec<Clean> = (0..PATHS.len()).map(|p| clean(s, p)).collect();
        let tally = std::cell::RefCell::new(Tally::default());
        let fixed_tally = std::cell::RefCell::new(Tally::default());
        let started = std::time::Instant::now();
        let mut runner = TestRunner::new(Config { cases: cases(), failure_persistence: None, ..Config::default() });
        let strategy = (0..PATHS.len(), any::<prop::sample::Index>(), perturbations());
        let result = runner.run(&strategy, |(path, start, ps)| {
            let c = &runs[path];
            let starts = (c.poses.len() - WINDOW) / SNAP;
            let snap = start.index(starts.max(1));
            let start = snap * SNAP;
            // f32
            let (poses, hit) = perturbed(&c.poses, start, &ps, apply_f32);
            let mut ins = c.snaps[snap];
            let evals: Vec<InsertionEvaluation> = poses.iter().map(|p| ins.step(&pose(*p))).collect();
            for (t, e) in evals.iter().enumerate() {
                let w = e.wrench.to_array();
                prop_assert!(within_bound(w), "{name} path {path} tick {}: {w:?} beyond the bound ({:?})", start + t, poses[t]);
                if e.flags.is_glitch() {
                    prop_assert_eq!(e.punctures, 0, "{} path {} tick {}: a glitch punctured", name, path, start + t);
                }
            }
            let rejected: Vec<bool> = evals.iter().map(|e| e.flags.is_glitch()).collect();
            let differences: Vec<f32> = evals
                .iter()
                .enumerate()
                .map(|(t, e)| {
                    let want = c.evals[start + t].wrench.to_array();
                    want.iter().zip(e.wrench.to_array()).map(|(a, b)| (a - b).abs()).fold(0.0, f32::max)
                })
                .collect();
            let r = recovery(
                stack,
                c,
                start,
                &Window {
                    clean_punctures: (start..start + WINDOW).map(|k| c.evals[k].punctures > 0).collect(),
                    hit,
                    rejected,
                    differences,
                    unit: 1.0,
                },
                &mut tally.borrow_mut(),
            );
            prop_assert!(r.is_ok(), "{} path {} ({:?}): {}", name, path, ps, r.unwrap_err());
            // fixed point: the same checks in µN
            let (poses, hit) = perturbed(&c.poses_q16, start, &ps, apply_q16);
            let mut ins = c.fixed_snaps[snap];
            let evals: Vec<_> = poses.iter().map(|p| ins.step(&fixed::Pose::new(p[0], p[1], p[2], p[3], p[4]))).collect();
            for (t, e) in evals.iter().enumerate() {
                prop_assert!(within_bound_fixed(e.wrench.to_array()), "{name} (fixed) path {path} tick {}: {:?}", start + t, e.wrench);
                if e.flags.is_glitch() {
                    prop_assert_eq!(e.punctures, 0, "{} (fixed) path {} tick {}: a glitch punctured", name, path, start + t);
                }
            }
            let rejected: Vec<bool> = evals.iter().map(|e| e.flags.is_glitch()).collect();
            let differences: Vec<f32> = evals
                .iter()
                .enumerate()
                .map(|(t, e)| {
                    let want = c.fixed_evals[start + t].wrench.to_array();
                    want.iter().zip(e.wrench.to_array()).map(|(a, b)| (i64::from(*a) - i64::from(b)).abs()).max().unwrap_or(0) as f32
                })
                .collect();
            let r = recovery(
                stack,
                c,
                start,
                &Window {
                    clean_punctures: (start..start + WINDOW).map(|k| c.fixed_evals[k].punctures > 0).collect(),
                    hit,
                    rejected,
                    differences,
                    unit: 1e6,
                },
                &mut fixed_tally.borrow_mut(),
            );
            prop_assert!(r.is_ok(), "{} (fixed) path {} ({:?}): {}", name, path, ps, r.unwrap_err());
            Ok(())
        });
        if let Err(e) = result {
            panic!("{name}: {e}");
        }
        let (t, f) = (tally.into_inner(), fixed_tally.into_inner());
        println!(
            "{name}: {} sequences in {:.1} s; recovered with every perturbed tick rejected: {} ({} ticks after recovery), largest difference from the clean run {:.3e} N, {:.2} of its bound; fixed point {} ({} ticks), {:.3e} N, {:.2} of its bound; where a glitch hid a puncture or a turn {:.3e} N (fixed point {:.3e} N)",
            cases(),
            started.elapsed().as_secs_f64(),
            t.recovered_cases,
            t.recovered_ticks,
            t.worst,
            t.worst_ratio,
            f.recovered_cases,
            f.recovered_ticks,
            f.worst,
            f.worst_ratio,
            t.worst_hidden,
            f.worst_hidden
        );
    }
}
