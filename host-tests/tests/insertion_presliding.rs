//! The shaft's presliding (issue 65, the `shaft-presliding` feature): a needle at rest
//! keeps its shaft friction and cutting force, relaxing through the shaft's Prony terms
//! to the long-term share, and a reversal turns the held force over within twice the
//! presliding distance; the fixed-point insertion refuses such a stack. Run on the
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
    let held_layers = with(Presliding { distance_mm: P_MM, relaxation_slip_mm: 0.1, shaft_prony: PronyTerms::NONE });
    let held = run(&Stack { layers: &held_layers, ..*liver() }, DEEP_MM, HOLD_S, 0.0);
    let relaxing_layers = with(Presliding { distance_mm: P_MM, relaxation_slip_mm: 0.1, shaft_prony: terms() });
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
    let layers = with(Presliding { distance_mm: P_MM, relaxation_slip_mm: P_MM, shaft_prony: PronyTerms::NONE });
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

#[test]
fn the_fixed_point_insertion_refuses_a_presliding_layer() {
    let layers: &'static [Layer] =
        Box::leak(with(Presliding { distance_mm: P_MM, relaxation_slip_mm: P_MM, shaft_prony: PronyTerms::NONE }).into_boxed_slice());
    let stack: &'static Stack<'static> = Box::leak(Box::new(Stack { layers, ..*liver() }));
    let fixed: &'static needle_haptics::fixed::insertion::Stack =
        Box::leak(Box::new(needle_haptics::fixed::insertion::Stack::from_f32(stack)));
    let e = needle_haptics::fixed::insertion::Insertion::new(fixed, needle_haptics::fixed::insertion::InsertionConfig::DEFAULT_1KHZ)
        .expect_err("a presliding layer");
    assert_eq!(e, InsertionError::FloatOnly);
    assert!(e.to_string().contains("f32 insertion"), "{e}");
    // and the f32 insertion refuses a presliding out of its range
    let bad = with(Presliding { distance_mm: 0.001, relaxation_slip_mm: 0.001, shaft_prony: PronyTerms::NONE });
    assert_eq!(Insertion::new(&Stack { layers: &bad, ..*liver() }, InsertionConfig::DEFAULT_1KHZ).err(), Some(InsertionError::Value));
}
