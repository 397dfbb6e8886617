//! The insertion model's phases on the shipped liver stack: approach, deflection (the
//! scaled FE surrogate), puncture (the axial force drops in one tick, the lateral part
//! stays), cutting, friction that reverses on withdrawal, re-advance in the track
//! without a new puncture, a needle held still that is not pushed out, leaving.
use needle_haptics::insertion::{deflection, stacks, Insertion, InsertionConfig, InsertionError, Phase, FE_NEEDLE_DIAMETER_MM};
use needle_haptics::{wrench, Pose, Status};

const SPEED_MM_PER_S: f32 = 3.0;

fn liver() -> Insertion {
    Insertion::new(&stacks::LIVER, InsertionConfig::DEFAULT_1KHZ).expect("shipped stack")
}

fn pose(depth_mm: f32) -> Pose {
    Pose { depth_mm, ..Pose::default() }
}

/// Advances from `from` to `to` at the test speed; returns the last evaluation and the
/// depth of the first puncture on the way.
fn advance(ins: &mut Insertion, p: Pose, from: f32, to: f32) -> (needle_haptics::insertion::InsertionEvaluation, Option<f32>) {
    let step = SPEED_MM_PER_S * InsertionConfig::DEFAULT_1KHZ.period_s * if to >= from { 1.0 } else { -1.0 };
    let n = ((to - from) / step).abs().ceil() as usize;
    let mut last = ins.step(&Pose { depth_mm: from, ..p });
    let mut punctured = None;
    for k in 1..=n {
        let d = if k == n { to } else { from + step * k as f32 };
        last = ins.step(&Pose { depth_mm: d, ..p });
        if last.punctures > 0 && punctured.is_none() {
            punctured = Some(d);
        }
    }
    (last, punctured)
}

fn first_puncture_depth() -> f32 {
    let mut ins = liver();
    let (_, at) = advance(&mut ins, pose(0.0), -1.0, 40.0);
    at.expect("the liver's capsule punctures within 40 mm")
}

#[test]
fn above_the_surface_there_is_no_force() {
    let mut ins = liver();
    for d in [-5.0, -0.1, 0.0] {
        let e = ins.step(&pose(d));
        assert_eq!(e.wrench.to_array(), [0.0; 6], "depth {d}");
        assert_eq!(e.phase, Phase::Approach);
        assert_eq!(e.status, Status::OK);
    }
}

#[test]
fn the_surface_deflects_with_the_scaled_surrogate() {
    let layer = stacks::LIVER.layers[0];
    let lambda = stacks::LIVER.needle_diameter_mm / FE_NEEDLE_DIAMETER_MM;
    let p = Pose { x_mm: 2.0, z_mm: -1.0, theta_x_deg: 4.0, theta_z_deg: -3.0, depth_mm: 2.5 };
    let mut ins = liver();
    let e = ins.step(&p);
    assert_eq!(e.phase, Phase::Deflecting(0));
    // the surrogate at the similar pose, scaled: forces s λ², moments s λ³
    let fe = wrench(&Pose { x_mm: p.x_mm / lambda, z_mm: p.z_mm / lambda, depth_mm: p.depth_mm / lambda, ..p });
    let w = fe.wrench.to_array();
    let got = e.wrench.to_array();
    for c in 0..6 {
        let factor = if c < 3 { layer.stiffness_scale * lambda * lambda } else { layer.stiffness_scale * lambda * lambda * lambda };
        assert_eq!(got[c].to_bits(), (w[c] * factor).to_bits(), "component {c}");
    }
    assert_eq!(deflection(&p, p.depth_mm, layer.stiffness_scale, lambda).wrench, e.wrench);
    // elastic: back at the same depth, the same force (0.9 mm a tick: within the
    // configuration's largest speed, 1 mm a tick)
    let again = ins.step(&Pose { depth_mm: 1.6, ..p });
    let back = ins.step(&p);
    assert!(again.wrench.fy_n < back.wrench.fy_n);
    assert_eq!(back.wrench, e.wrench);
}

#[test]
fn a_puncture_drops_the_axial_force_in_one_tick_and_keeps_the_lateral_part() {
    let p = Pose { x_mm: 3.0, z_mm: 2.0, theta_x_deg: 6.0, theta_z_deg: -5.0, depth_mm: 0.0 };
    let mut ins = liver();
    let mut before = ins.step(&Pose { depth_mm: -0.5, ..p });
    let mut prev_change = [0.0f32; 6];
    let step = SPEED_MM_PER_S * 0.001;
    for k in 0..20_000 {
        let e = ins.step(&Pose { depth_mm: step * k as f32, ..p });
        if e.punctures > 0 {
            let a = needle_haptics::insertion::needle_axis(&p);
            let split = |w: [f32; 6]| {
                let axial = w[0] * a[0] + w[1] * a[1] + w[2] * a[2];
                (axial, [w[0] - axial * a[0], w[1] - axial * a[1], w[2] - axial * a[2], w[3], w[4], w[5]])
            };
            let (axial_before, lateral_before) = split(before.wrench.to_array());
            let (axial_after, lateral_after) = split(e.wrench.to_array());
            assert!(before.phase == Phase::Deflecting(0), "{:?}", before.phase);
            assert!(axial_before >= 0.9 * stacks::LIVER.layers[0].puncture_force_n, "puncture near the threshold: {axial_before}");
            assert!(axial_after < 0.5 * axial_before, "the axial force drops: {axial_before} -> {axial_after}");
            for c in 0..6 {
                // the force across the needle and the moments move no more than between
                // two ticks of deflection (the axial force along the needle is what goes)
                let jump = (lateral_after[c] - lateral_before[c]).abs();
                let allowed = 3.0 * prev_change[c].abs() + 1e-6;
                assert!(
                    jump <= allowed,
                    "lateral component {c}: {} -> {} (previous tick's change {})",
                    lateral_before[c],
                    lateral_after[c],
                    prev_change[c]
                );
            }
            return;
        }
        let ax = needle_haptics::insertion::needle_axis(&p);
        let lateral = |w: [f32; 6]| {
            let axial = w[0] * ax[0] + w[1] * ax[1] + w[2] * ax[2];
            [w[0] - axial * ax[0], w[1] - axial * ax[1], w[2] - axial * ax[2], w[3], w[4], w[5]]
        };
        let (b, a) = (lateral(before.wrench.to_array()), lateral(e.wrench.to_array()));
        prev_change = std::array::from_fn(|c| a[c] - b[c]);
        before = e;
    }
    panic!("no puncture within 60 mm");
}

#[test]
fn friction_reverses_on_withdrawal_and_a_held_needle_is_not_pushed_out() {
    let at = first_puncture_depth();
    let mut ins = liver();
    let (inserting, _) = advance(&mut ins, pose(0.0), -1.0, at + 6.0);
    assert!(matches!(inserting.phase, Phase::Cutting(_) | Phase::Deflecting(_)), "{:?}", inserting.phase);
    assert!(inserting.wrench.fy_n > 0.0, "inserting: the tissue resists ({})", inserting.wrench.fy_n);
    // held still: no cutting, no friction (the needle at rest), nothing pushes it out
    let held = ins.step(&pose(at + 6.0));
    assert!(held.wrench.fy_n.abs() < 1e-6, "held: fy {}", held.wrench.fy_n);
    for _ in 0..100 {
        let e = ins.step(&pose(at + 6.0));
        assert!(e.wrench.fy_n.abs() < 1e-6 && !matches!(e.phase, Phase::Cutting(_)), "held: {e:?}");
    }
    // withdrawing: friction pulls the needle in (fy < 0 on the needle)
    let (withdrawing, _) = advance(&mut ins, pose(0.0), at + 6.0, at + 2.0);
    assert!(withdrawing.wrench.fy_n < 0.0, "withdrawing: fy {}", withdrawing.wrench.fy_n);
    assert!(matches!(withdrawing.phase, Phase::InTrack(_)), "{:?}", withdrawing.phase);
}

#[test]
fn re_advance_in_the_track_neither_punctures_nor_cuts_until_past_the_deepest_point() {
    let at = first_puncture_depth();
    let mut ins = liver();
    let deepest = at + 3.0;
    advance(&mut ins, pose(0.0), -1.0, deepest);
    advance(&mut ins, pose(0.0), deepest, at - 2.0);
    let (inside, again) = advance(&mut ins, pose(0.0), at - 2.0, deepest - 0.1);
    assert_eq!(again, None, "no new puncture in the cut track");
    assert!(matches!(inside.phase, Phase::InTrack(_)), "{:?}", inside.phase);
    // past the deepest point the tip cuts again (checked a tick at a time: a tick whose
    // step is zero, as a script's last one can be, neither cuts nor rubs)
    let mut cut_again = false;
    let mut d = deepest - 0.1;
    while d < deepest + 0.5 {
        d += SPEED_MM_PER_S * InsertionConfig::DEFAULT_1KHZ.period_s;
        let e = ins.step(&pose(d));
        assert_eq!(e.punctures, 0, "no puncture in the cut track");
        cut_again |= d > deepest && matches!(e.phase, Phase::Cutting(_));
        if d <= deepest - 0.01 {
            assert!(matches!(e.phase, Phase::InTrack(_)), "at {d} mm, behind the deepest point {deepest}: {:?}", e.phase);
        }
    }
    assert!(cut_again, "past the deepest point the tip cuts again");
}

#[test]
fn leaving_the_tissue_ends_the_path() {
    let at = first_puncture_depth();
    let mut ins = liver();
    advance(&mut ins, pose(0.0), -1.0, at + 1.0);
    let (out, _) = advance(&mut ins, pose(0.0), at + 1.0, -0.5);
    assert_eq!(out.phase, Phase::Approach);
    assert_eq!(out.wrench.to_array(), [0.0; 6]);
    let (_, again) = advance(&mut ins, pose(0.0), -0.5, at + 1.0);
    assert!(again.is_some(), "a new insertion punctures again");
}

#[test]
fn a_pose_that_is_not_finite_gives_an_error_and_keeps_the_state() {
    let mut ins = liver();
    advance(&mut ins, pose(0.0), -1.0, 3.0);
    let saved = ins;
    for bad in [f32::NAN, f32::INFINITY] {
        let e = ins.step(&Pose { x_mm: bad, ..pose(3.0) });
        assert!(e.status.is_error());
        assert_eq!(e.wrench.to_array(), [0.0; 6]);
    }
    // the state is unchanged but for the time since the last accepted pose (the velocity
    // filter's step): before the first puncture the next tick's wrench is the same
    let (mut glitched, mut clean) = (ins, saved);
    let (g, c) = (glitched.step(&pose(3.0)), clean.step(&pose(3.0)));
    assert_eq!((g.wrench, g.phase, g.punctures), (c.wrench, c.phase, c.punctures), "the state is unchanged");
}

#[test]
fn scales_are_overridden_at_run_time() {
    let mut ins = liver();
    let base = ins.step(&pose(2.0)).wrench.fy_n;
    let n = stacks::LIVER.layers.len();
    assert_eq!(ins.set_scales(&vec![1.0; n + 1]), Err(InsertionError::Scales));
    assert_eq!(ins.set_scales(&vec![0.0; n]), Err(InsertionError::Scales));
    assert_eq!(ins.set_scales(&vec![f32::NAN; n]), Err(InsertionError::Scales));
    let doubled: Vec<f32> = stacks::LIVER.layers.iter().map(|l| 2.0 * l.stiffness_scale).collect();
    ins.set_scales(&doubled).expect("valid scales");
    ins.reset();
    let twice = ins.step(&pose(2.0)).wrench.fy_n;
    assert!((twice / base - 2.0).abs() < 1e-6, "{base} -> {twice}");
}

#[test]
fn the_needle_axis_follows_the_orientation_convention() {
    // the insertion's own sine and cosine (no libm: f32 polynomials) against f64
    for k in -890..=890 {
        let deg = k as f32 * 0.1;
        let p = Pose { theta_x_deg: deg, theta_z_deg: -0.5 * deg, ..pose(5.0) };
        let a = needle_haptics::insertion::needle_axis(&p);
        let (tx, tz) = (f64::from(deg).to_radians(), f64::from(-0.5 * deg).to_radians());
        let want = [-tz.sin() * tx.cos(), tz.cos() * tx.cos(), tx.sin()];
        for c in 0..3 {
            assert!((f64::from(a[c]) - want[c]).abs() < 3e-7, "{deg} deg: component {c}: {} vs {}", a[c], want[c]);
        }
    }
    // beyond ±89 degrees the tilt is clamped (a needle at 90 degrees does not enter the top surface)
    let at = |deg: f32| needle_haptics::insertion::needle_axis(&Pose { theta_x_deg: deg, ..pose(1.0) });
    assert_eq!(at(120.0), at(89.0));
    assert_eq!(at(-95.0), at(-89.0));
}
