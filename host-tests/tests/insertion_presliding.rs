//! The shaft's presliding (issue 65, the `shaft-presliding` feature): a needle at rest
//! keeps its shaft friction and cutting force, relaxing through the shaft's Prony terms
//! to the long-term share, and a reversal turns the held force over within twice the
//! presliding distance; the tissue's tent builds a withdrawal's pull over millimetres and
//! lifts it; the fixed-point insertion refuses such a stack. Run on the
//! shipped liver with a presliding on every layer (values to exercise the model, not a
//! tissue's), against the same stack without (the Karnopp friction, zero at rest).
use needle_haptics::insertion::{stacks, Insertion, InsertionConfig, InsertionError, Layer, Presliding, Stack};
use needle_haptics::viscoelastic::{PronyTerm, PronyTerms};
use needle_haptics::Pose;

const P_MM: f32 = 1.0;
const SPEED_MM_PER_S: f64 = 5.0;
const G: f32 = 1.0;

fn liver() -> &'static Stack<'static> {
    stacks::by_name("liver").expect("the shipped liver")
}

fn with(presliding: Presliding) -> Vec<Layer> {
    liver().layers.iter().map(|l| Layer { presliding, ..*l }).collect()
}

fn terms() -> PronyTerms {
    PronyTerms::new(&[PronyTerm { g: G, tau_s: 0.5 }]).expect("valid terms")
}

/// The axial force (fy) per tick along: insert to `deep_mm` at the speed, hold `hold_s`,
/// withdraw `back_mm`; with the depth of each tick.
fn run(stack: &Stack<'_>, deep_mm: f64, hold_s: f64, back_mm: f64) -> Vec<(f64, f32)> {
    let mut ins = Insertion::new(stack, InsertionConfig::DEFAULT_1KHZ).expect("a valid stack");
    let dt = 0.001;
    let mut depths = Vec::new();
    let mut d = -1.0;
    while d < deep_mm {
        d = (d + SPEED_MM_PER_S * dt).min(deep_mm);
        depths.push(d);
    }
    depths.extend(std::iter::repeat_n(deep_mm, (hold_s / dt) as usize));
    let end = deep_mm - back_mm;
    while d > end {
        d = (d - SPEED_MM_PER_S * dt).max(end);
        depths.push(d);
    }
    depths.into_iter().map(|d| (d, ins.step(&Pose { depth_mm: d as f32, ..Pose::default() }).wrench.fy_n)).collect()
}

/// In the last layer (no boundary below deflects): the force is the shaft's alone.
const DEEP_MM: f64 = 32.0;
const HOLD_S: f64 = 5.0;

#[test]
fn at_rest_the_shaft_keeps_its_force_and_relaxes_to_its_long_term_share() {
    let karnopp = run(liver(), DEEP_MM, HOLD_S, 0.0);
    let held_layers = with(Presliding { distance_mm: P_MM, relaxation_slip_mm: 0.1, shaft_prony: PronyTerms::NONE, tent_n_per_mm: 0.0 });
    let held = run(&Stack { layers: &held_layers, ..*liver() }, DEEP_MM, HOLD_S, 0.0);
    let relaxing_layers = with(Presliding { distance_mm: P_MM, relaxation_slip_mm: 0.1, shaft_prony: terms(), tent_n_per_mm: 0.0 });
    let relaxing = run(&Stack { layers: &relaxing_layers, ..*liver() }, DEEP_MM, HOLD_S, 0.0);
    let stop = karnopp.iter().position(|(d, _)| *d >= DEEP_MM).expect("the stop");
    let (moving, end) = (stop - 1, karnopp.len() - 1);
    // sliding: the same force with and without presliding (the file's levels are the sliding ones)
    let sliding = karnopp[moving].1;
    assert!(sliding > 0.5, "the liver's shaft slides with friction: {sliding} N");
    assert!((held[moving].1 - sliding).abs() <= 1e-4 * sliding, "sliding {} vs Karnopp {sliding}", held[moving].1);
    assert!((relaxing[moving].1 - sliding).abs() <= 1e-3 * sliding, "sliding {} vs Karnopp {sliding}", relaxing[moving].1);
    // at rest: the Karnopp friction is gone, the presliding keeps it all ...
    let rest = karnopp[end].1;
    assert!(rest.abs() <= 1e-6, "the Karnopp shaft at rest: {rest} N");
    assert!((held[end].1 - sliding).abs() <= 1e-4 * sliding, "held after {HOLD_S} s: {} of {sliding} N", held[end].1);
    // ... or relaxes to 1 / (1 + g) of it after ten time constants
    let share = relaxing[end].1 / sliding;
    let expected = (1.0 + G * (-10.0f32).exp()) / (1.0 + G);
    assert!((share - expected).abs() <= 1e-3, "relaxed to {share} of the sliding force, expected {expected}");
}

#[test]
fn a_reversal_turns_the_held_force_over_within_twice_the_presliding_distance() {
    let layers = with(Presliding { distance_mm: P_MM, relaxation_slip_mm: P_MM, shaft_prony: PronyTerms::NONE, tent_n_per_mm: 0.0 });
    let stack = Stack { layers: &layers, ..*liver() };
    let back_mm = 4.0 * f64::from(P_MM);
    let ticks = run(&stack, DEEP_MM, 0.5, back_mm);
    let karnopp = run(liver(), DEEP_MM, 0.5, back_mm);
    let reversal = ticks.iter().rposition(|(d, _)| *d >= DEEP_MM).expect("the reversal");
    let held_n = ticks[reversal].1;
    assert!(held_n > 0.5, "held at the reversal: {held_n} N");
    let crossing = ticks[reversal..].iter().find(|(_, f)| *f < 0.0).map(|(d, _)| DEEP_MM - d).expect("the force turns over");
    assert!(crossing <= 2.0 * f64::from(P_MM), "crosses zero after {crossing} mm of travel, presliding {P_MM} mm");
    // past twice the distance it pulls back with the sliding friction, as Karnopp's does
    let at = |t: &[(f64, f32)]| t[reversal..].iter().find(|(d, _)| *d <= DEEP_MM - 3.0 * f64::from(P_MM)).map(|x| x.1).expect("withdrawn");
    let (last, karnopp_last) = (at(&ticks), at(&karnopp));
    assert!(karnopp_last < -0.5, "the Karnopp shaft pulls back: {karnopp_last} N");
    assert!((last - karnopp_last).abs() <= 1e-3 * karnopp_last.abs(), "pulls {last} N, Karnopp {karnopp_last} N");
}

/// Each shaft term's arm is loaded within its own slip distance, `p_r tau_i / tau_min` (at
/// most the presliding distance): a slow term that carries most of the held force turns
/// over on a reversal within twice its distance, not within the shortest term's. Here
/// `p_r` = 0.05 mm (the fast term, 0.05 s) and the slow term (2 s, g 3) loads within
/// `min(0.05 * 40, P_MM)` = 1 mm: the held force crosses zero after about 0.9 mm of travel
/// back (long-term share 0.22 and the slow arm's 0.67 against the fast arm's 0.11), where
/// with every arm at 0.05 mm it would cross within 0.1 mm.
#[test]
fn a_slow_shaft_term_turns_over_within_its_own_slip_distance() {
    let slow_and_fast = PronyTerms::new(&[PronyTerm { g: 0.5, tau_s: 0.05 }, PronyTerm { g: 3.0, tau_s: 2.0 }]).expect("valid terms");
    let layers = with(Presliding { distance_mm: P_MM, relaxation_slip_mm: 0.05, shaft_prony: slow_and_fast, tent_n_per_mm: 0.0 });
    let ticks = run(&Stack { layers: &layers, ..*liver() }, DEEP_MM, 0.0, 3.0 * f64::from(P_MM));
    let reversal = ticks.iter().rposition(|(d, _)| *d >= DEEP_MM).expect("the reversal");
    let held_n = ticks[reversal].1;
    assert!(held_n > 0.5, "held at the reversal: {held_n} N");
    let crossing = ticks[reversal..].iter().find(|(_, f)| *f < 0.0).map(|(d, _)| DEEP_MM - d).expect("the force turns over");
    println!("held {held_n} N at the reversal, crosses zero after {crossing:.3} mm of travel back");
    assert!(
        crossing >= 0.5 && crossing <= 2.0 * f64::from(P_MM),
        "crosses zero after {crossing} mm: expected about 0.9 mm, within 2 x {P_MM} mm"
    );
}

/// The liver with a presliding of `P_MM` on every layer, the tissue's tent `tent_n_per_mm`
/// and the static level twice the Coulomb one.
fn with_tent(tent_n_per_mm: f32) -> Vec<Layer> {
    liver()
        .layers
        .iter()
        .map(|l| {
            let mut friction = l.friction;
            friction.static_n_per_mm = 2.0 * friction.coulomb_n_per_mm;
            let presliding = Presliding { distance_mm: P_MM, relaxation_slip_mm: P_MM, shaft_prony: PronyTerms::NONE, tent_n_per_mm };
            Layer { friction, presliding, ..*l }
        })
        .collect()
}

#[test]
fn a_tent_leaves_the_insertion_alone_builds_the_pull_over_millimetres_and_lifts_it() {
    let back_mm = 10.0;
    let rigid = run(&Stack { layers: &with_tent(0.0), ..*liver() }, DEEP_MM, 0.5, back_mm);
    let soft = run(&Stack { layers: &with_tent(0.1), ..*liver() }, DEEP_MM, 0.5, back_mm);
    let stiff = run(&Stack { layers: &with_tent(1.0), ..*liver() }, DEEP_MM, 0.5, back_mm);
    let reversal = rigid.iter().rposition(|(d, _)| *d >= DEEP_MM).expect("the reversal");
    // pushed down the tissue rests on the tissue below: insertion and hold bit for bit
    for (r, t) in rigid.iter().zip(&soft).take(reversal + 1) {
        assert_eq!(r.1.to_bits(), t.1.to_bits(), "at {} mm: {} N without a tent, {} N with", r.0, r.1, t.1);
    }
    // the held force unloads as without a tent, then the pull builds through the tent
    let crossing = |t: &[(f64, f32)]| t[reversal..].iter().position(|(_, f)| *f < 0.0).map(|i| i + reversal).expect("turns over");
    let (cr, cs) = (crossing(&rigid), crossing(&soft));
    assert!(cr.abs_diff(cs) <= 1, "the held force crosses zero at tick {cr} without a tent, {cs} with");
    let after = |t: &[(f64, f32)], from: usize, mm: f64| {
        t[from..].iter().find(|(d, _)| *d <= t[from].0 - mm).map(|x| x.1).expect("withdrawn that far")
    };
    let (pull_rigid, pull_soft) = (after(&rigid, cr, 1.0), after(&soft, cs, 1.0));
    assert!(pull_rigid < -0.5, "without a tent the shaft pulls {pull_rigid} N 1 mm past the crossing");
    // each layer the shaft is in has its tent (in parallel): 0.1 N/mm each over 1 mm, in
    // series with the bristles, at most 0.1 N a layer and at least half of it
    let tops: Vec<f32> = liver().layers.iter().scan(0.0, |top, l| Some(std::mem::replace(top, *top + l.thickness_mm))).collect();
    let layers = tops.iter().filter(|&&t| f64::from(t) < soft[cs].0 - 1.0).count() as f32;
    assert!(
        (-0.1 * layers..=-0.05 * layers).contains(&pull_soft),
        "with a 0.1 N/mm tent in each of {layers} layers it pulls {pull_soft} N 1 mm past the crossing"
    );
    // a stiff tent reaches the lifted level: the static level over the lengthened shaft
    let (end_rigid, end_stiff) = (after(&rigid, reversal, back_mm), after(&stiff, reversal, back_mm));
    assert!(end_stiff < 1.5 * end_rigid, "withdrawn {back_mm} mm: {end_stiff} N with a 1 N/mm tent, {end_rigid} N without");
}

#[test]
fn the_fixed_point_insertion_refuses_a_presliding_layer() {
    let layers: &'static [Layer] = Box::leak(
        with(Presliding { distance_mm: P_MM, relaxation_slip_mm: P_MM, shaft_prony: PronyTerms::NONE, tent_n_per_mm: 0.0 })
            .into_boxed_slice(),
    );
    let stack: &'static Stack<'static> = Box::leak(Box::new(Stack { layers, ..*liver() }));
    let fixed: &'static needle_haptics::fixed::insertion::Stack =
        Box::leak(Box::new(needle_haptics::fixed::insertion::Stack::from_f32(stack)));
    let e = needle_haptics::fixed::insertion::Insertion::new(fixed, needle_haptics::fixed::insertion::InsertionConfig::DEFAULT_1KHZ)
        .expect_err("a presliding layer");
    assert_eq!(e, InsertionError::FloatOnly);
    assert!(e.to_string().contains("f32 insertion"), "{e}");
    // and the f32 insertion refuses a presliding out of its range
    let bad = with(Presliding { distance_mm: 0.001, relaxation_slip_mm: 0.001, shaft_prony: PronyTerms::NONE, tent_n_per_mm: 0.0 });
    assert_eq!(Insertion::new(&Stack { layers: &bad, ..*liver() }, InsertionConfig::DEFAULT_1KHZ).err(), Some(InsertionError::Value));
}

/// The depths of `run`'s path: insert to `deep_mm` at the speed, hold `hold_s`,
/// withdraw `back_mm`.
fn path(deep_mm: f64, hold_s: f64, back_mm: f64) -> Vec<f64> {
    let dt = 0.001;
    let mut depths = Vec::new();
    let mut d = -1.0;
    while d < deep_mm {
        d = (d + SPEED_MM_PER_S * dt).min(deep_mm);
        depths.push(d);
    }
    depths.extend(std::iter::repeat_n(deep_mm, (hold_s / dt) as usize));
    let end = deep_mm - back_mm;
    while d > end {
        d = (d - SPEED_MM_PER_S * dt).max(end);
        depths.push(d);
    }
    depths
}

/// Per tick of `depths` through the control loop with the passivity guard for a device
/// of damping `damping_n_s_per_mm` at 1 kHz: the depth, the insertion's fy and the
/// commanded fy.
fn guarded(stack: &Stack<'_>, depths: &[f64], damping_n_s_per_mm: f32) -> Vec<(f64, f32, f32)> {
    use needle_haptics::control::{ChannelMap, LoopConfig, LoopCore, OverLimit, Passivity};
    let config = LoopConfig {
        channels: [ChannelMap { gains_per_n: [0.0, 0.01, 0.0], direction_inverted: false }],
        force_limit_n: 100.0,
        force_limit_max_n: 100.0,
        over_limit: OverLimit::Saturate,
        ramp_step_n: 0.01,
    };
    let mut core = LoopCore::new(config).expect("config");
    core.set_passivity(Some(Passivity { damping_n_s_per_mm, period_s: 0.001 })).expect("guard");
    core.set_insertion(Some(Insertion::new(stack, InsertionConfig::DEFAULT_1KHZ).expect("a valid stack")));
    depths
        .iter()
        .map(|&d| {
            let s = core.step(Ok(Pose { depth_mm: d as f32, ..Pose::default() }));
            (d, s.wrench.fy_n, s.force_cmd_n[1])
        })
        .collect()
}

/// Through the control loop's passivity guard (`control::held_bristle`), the liver with a
/// presliding and a shaft term on every layer along `run`'s path (insert, hold 1 s,
/// withdraw 12 mm), in the last layer (from the stop on: no boundary deflects, and on the
/// vertical axis the track holds nothing, so the command is the held force alone).
///
/// On a device whose guard leaves the held stiffness alone (10 N·s/m: `HELD_SHARE k_g` =
/// 5 N/mm against the bristles' `level / p` of about 1.5 N/mm) the command is the
/// insertion's force: sliding, relaxing at rest, pulling back past the reversal (within
/// 1e-5 of it: f32 rounding of the force taken apart and put together again), and it
/// turns over within twice the presliding distance. On the weakly damped device of the
/// energy tests (0.1 N·s/m: 0.05 N/mm) it holds a force at rest, never more than the
/// insertion's nor of the other sign, and grows away from zero no faster than its
/// stiffness allows.
#[test]
fn the_guarded_loop_renders_the_held_force_within_its_stiffness() {
    use needle_haptics::control::{Passivity, HELD_SHARE};
    let layers = with(Presliding { distance_mm: P_MM, relaxation_slip_mm: P_MM, shaft_prony: terms(), tent_n_per_mm: 0.0 });
    let stack = Stack { layers: &layers, ..*liver() };
    let depths = path(DEEP_MM, 1.0, 12.0);
    let stop = depths.iter().position(|d| *d >= DEEP_MM).expect("the stop");
    let reversal = depths.iter().rposition(|d| *d >= DEEP_MM).expect("the reversal");
    let close = |a: f32, b: f32| (a - b).abs() <= 1e-5 * b.abs().max(1e-3);
    let ticks = guarded(&stack, &depths, 0.01);
    for k in [stop - 1, reversal] {
        let (_, model, cmd) = ticks[k];
        assert!(model > 0.5 && close(cmd, model), "tick {k}: command {cmd} N, insertion {model} N");
    }
    let (_, relaxed, _) = ticks[reversal];
    assert!(relaxed < 0.9 * ticks[stop].1, "the held force relaxes at rest: {relaxed} N");
    let crossing = ticks[reversal..].iter().find(|(_, _, c)| *c < 0.0).map(|(d, _, _)| DEEP_MM - d).expect("the command turns over");
    assert!(crossing <= 2.0 * f64::from(P_MM), "the command crosses zero after {crossing} mm, presliding {P_MM} mm");
    let back = ticks[reversal..].iter().find(|(d, _, _)| *d <= DEEP_MM - 3.0 * f64::from(P_MM)).expect("withdrawn");
    assert!(back.1 < -0.5 && close(back.2, back.1), "pulling back: command {} N, insertion {} N", back.2, back.1);

    let weak = Passivity { damping_n_s_per_mm: 0.0001, period_s: 0.001 };
    let ticks = guarded(&stack, &depths, weak.damping_n_s_per_mm);
    let held_at_rest = ticks[reversal].2;
    assert!(held_at_rest > 0.5, "the weak device's command holds at rest: {held_at_rest} N");
    let kappa = f64::from(HELD_SHARE * weak.guard_stiffness_n_per_mm());
    let mut turned = 0.0f64;
    for (k, w) in ticks[stop..].windows(2).enumerate() {
        let [(d0, _, c0), (d1, model, c1)] = [w[0], w[1]];
        assert!(c1 * model >= 0.0 && c1.abs() <= model.abs(), "tick {}: command {c1} N, insertion {model} N", stop + k + 1);
        // away from zero it grows by at most its stiffness times the step (towards zero it
        // may fall at once: a slip, the insertion's relaxation or its turning over)
        let from = if c0 * c1 > 0.0 { f64::from(c0.abs()) } else { 0.0 };
        let grown = f64::from(c1.abs()) - from;
        assert!(
            grown <= kappa * (d1 - d0).abs() * (1.0 + 1e-4) + 1e-6,
            "tick {}: the command grew {grown} N over {} mm",
            stop + k + 1,
            d1 - d0
        );
        turned = turned.max(f64::from(held_at_rest - c1));
    }
    assert!(turned > 0.5, "the weak device's command turns over on the way out: by {turned} N");
}
