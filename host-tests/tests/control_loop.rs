//! The control loop on embedded-hal-mock outputs: exact duty cycles and pin states for
//! golden poses, saturation at the force limit, the safety ramp to zero on a stale or
//! missing pose, an evaluation error or an over-limit force, output errors, and config
//! checks. Expected wrenches come from the golden vectors (the fitter's independent
//! implementation), expected duties from the documented linear map applied to them, so
//! nothing here depends on the fitted coefficients' values.
mod common;

use common::{channel_c, duty_of, golden_in_domain, GoldenRow, Script};
use embedded_hal_mock::eh1::digital::{Mock as PinMock, State, Transaction as PinT};
use embedded_hal_mock::eh1::pwm::{Mock as PwmMock, Transaction as PwmT};
use embedded_hal_mock::eh1::MockError;
use needle_haptics::control::{Channel, ChannelMap, ConfigError, ControlLoop, LoopConfig, LoopFlags, OverLimit, PoseFault, Sample};
use needle_haptics::{Pose, Status};

const GAINS: [[f32; 3]; 3] = [[20.0, 0.0, 0.0], [0.0, -10.0, 0.0], [0.0, 0.0, 20.0]];
const INVERTED: [bool; 3] = [false, false, true];
const MAX_DUTY: [u16; 3] = [1000, 4095, 255];

fn config(limit_n: f32, over_limit: OverLimit, ramp_step_n: f32) -> LoopConfig<3> {
    LoopConfig {
        channels: [0, 1, 2].map(|i| ChannelMap { gains_per_n: GAINS[i], direction_inverted: INVERTED[i] }),
        force_limit_n: limit_n,
        force_limit_max_n: 20.0,
        over_limit,
        ramp_step_n,
    }
}

/// What one tick must write.
#[derive(Clone, Copy, Debug)]
struct Expect {
    duties: [u16; 3],
    dirs: [bool; 3],
    enable: bool,
}

/// The outputs the documented map gives for the commanded force `f_n`, and whether a
/// channel is clipped.
fn expect_for(f_n: [f32; 3], enable: bool) -> (Expect, bool) {
    let mut e = Expect { duties: [0; 3], dirs: [false; 3], enable };
    let mut clipped = false;
    for i in 0..3 {
        let c = channel_c(GAINS[i], f_n);
        clipped |= c.abs() > 1.0;
        e.duties[i] = duty_of(c, MAX_DUTY[i]);
        e.dirs[i] = (c >= 0.0) != INVERTED[i];
    }
    (e, clipped)
}

fn level(b: bool) -> State {
    if b {
        State::High
    } else {
        State::Low
    }
}

/// Runs one loop over mocks that expect exactly `ticks` (plus the constructor's
/// max-duty reads), with `pwm_errors` marking (tick, channel) writes that fail.
fn run(config: LoopConfig<3>, script: Script, ticks: &[Expect], pwm_errors: &[(usize, usize)]) -> Vec<Sample> {
    let channels: [Channel<PwmMock, PinMock>; 3] = [0, 1, 2].map(|i| {
        let mut pwm = vec![PwmT::max_duty_cycle(MAX_DUTY[i])];
        pwm.extend(ticks.iter().enumerate().map(|(t, e)| {
            let tr = PwmT::set_duty_cycle(e.duties[i]);
            if pwm_errors.contains(&(t, i)) {
                tr.with_error(MockError::Io(std::io::ErrorKind::Other))
            } else {
                tr
            }
        }));
        let dir: Vec<PinT> = ticks.iter().map(|e| PinT::set(level(e.dirs[i]))).collect();
        Channel { pwm: PwmMock::new(&pwm), dir: PinMock::new(&dir) }
    });
    let en: Vec<PinT> = ticks.iter().map(|e| PinT::set(level(e.enable))).collect();
    let mut l = ControlLoop::new(config, script, channels, PinMock::new(&en)).expect("valid config");
    assert_eq!(l.max_duty(), &MAX_DUTY);
    let samples: Vec<Sample> = ticks.iter().map(|_| l.tick()).collect();
    let (_, mut channels, mut en) = l.release();
    for ch in &mut channels {
        ch.pwm.done();
        ch.dir.done();
    }
    en.done();
    samples
}

fn forces(r: &GoldenRow) -> [f32; 3] {
    [r.wrench.fx_n, r.wrench.fy_n, r.wrench.fz_n]
}

#[test]
fn golden_poses_give_the_documented_duties_and_pins() {
    let rows = golden_in_domain(40);
    let mut expects = Vec::new();
    let mut clipped_flags = Vec::new();
    for r in &rows {
        let (e, clipped) = expect_for(forces(r), true);
        expects.push(e);
        clipped_flags.push(clipped);
    }
    let samples = run(config(10.0, OverLimit::Saturate, 0.01), Script::new(rows.iter().map(|r| Ok(r.pose))), &expects, &[]);
    let mut nonzero = 0;
    for (k, ((r, s), clipped)) in rows.iter().zip(&samples).zip(&clipped_flags).enumerate() {
        assert_eq!(s.tick, k as u32 + 1);
        assert_eq!(s.pose, r.pose);
        assert_eq!(s.model, r.status, "golden line {}", r.line);
        assert_eq!(s.wrench.to_array().map(f32::to_bits), r.wrench.to_array().map(f32::to_bits), "golden line {}", r.line);
        assert_eq!(s.force_cmd_n.map(f32::to_bits), forces(r).map(f32::to_bits));
        let want = if *clipped { LoopFlags::DUTY_CLIPPED } else { LoopFlags::OK };
        assert_eq!(s.flags, want, "golden line {}", r.line);
        nonzero += expects[k].duties.iter().filter(|d| **d > 0).count();
    }
    // The poses must exercise the map: most duties are non-zero.
    assert!(nonzero > rows.len(), "only {nonzero} non-zero duties over {} ticks", rows.len());
    println!("{} golden poses: duties and pins as documented ({nonzero} non-zero duties)", rows.len());
}

#[test]
fn force_above_the_limit_saturates_at_the_limit() {
    let rows = golden_in_domain(40);
    let r = rows.iter().max_by(|a, b| a.wrench.fy_n.abs().total_cmp(&b.wrench.fy_n.abs())).copied().expect("rows");
    let f = forces(&r);
    let norm2 = f[0] * f[0] + f[1] * f[1] + f[2] * f[2];
    let limit = norm2.sqrt() * 0.5;
    let scale = limit / norm2.sqrt();
    let cmd = f.map(|c| c * scale);
    let (e, clipped) = expect_for(cmd, true);
    let s = run(config(limit, OverLimit::Saturate, 0.01), Script::new([Ok(r.pose)]), &[e], &[]).remove(0);
    let mut want = LoopFlags::OVER_LIMIT | LoopFlags::FORCE_SATURATED;
    if clipped {
        want |= LoopFlags::DUTY_CLIPPED;
    }
    assert_eq!(s.flags, want);
    assert_eq!(s.force_cmd_n.map(f32::to_bits), cmd.map(f32::to_bits));
    let got = (s.force_cmd_n.iter().map(|c| f64::from(*c).powi(2)).sum::<f64>()).sqrt();
    assert!((got - f64::from(limit)).abs() <= 1e-6 * f64::from(limit), "|cmd| {got} N vs limit {limit} N");
    // Same direction as the model's force.
    for (c, m) in s.force_cmd_n.iter().zip(f) {
        assert!((c * 2.0 - m).abs() <= 1e-6 * m.abs().max(1e-3), "{c} vs {m}");
    }
}

#[test]
fn full_scale_command_is_clipped_and_flagged() {
    let r = golden_in_domain(10)[5];
    let mut cfg = config(10.0, OverLimit::Saturate, 0.01);
    cfg.channels[1].gains_per_n = [0.0, 1000.0, 0.0];
    let c = channel_c([0.0, 1000.0, 0.0], forces(&r));
    assert!(c.abs() > 1.0);
    let (mut e, _) = expect_for(forces(&r), true);
    e.duties[1] = MAX_DUTY[1];
    e.dirs[1] = c >= 0.0;
    let s = run(cfg, Script::new([Ok(r.pose)]), &[e], &[]).remove(0);
    assert!(s.flags.contains(LoopFlags::DUTY_CLIPPED), "{:?}", s.flags);
}

/// The ramp the docs promise: each component towards zero by at most `step` a tick.
fn ramp(f: [f32; 3], step: f32) -> [f32; 3] {
    f.map(|c| {
        if c > step {
            c - step
        } else if c < -step {
            c + step
        } else {
            0.0
        }
    })
}

/// Magnitude of the force command of golden row `r`, N.
fn force_norm_n(r: &GoldenRow) -> f32 {
    let f = forces(r);
    (f[0] * f[0] + f[1] * f[1] + f[2] * f[2]).sqrt()
}

/// The row the ramp cases start from: of `golden_in_domain(10)`, the one with the largest
/// force below `below_n`, so that ramping it to zero takes several ticks whatever the
/// fitted model's magnitudes are.
fn row_to_ramp(below_n: f32) -> GoldenRow {
    golden_in_domain(10)
        .into_iter()
        .filter(|r| force_norm_n(r) < below_n)
        .max_by(|a, b| force_norm_n(a).total_cmp(&force_norm_n(b)))
        .expect("an in-domain golden row below the bound")
}

/// A good tick on golden row `row_to_ramp(below_n)`, then `fault` until the ramp reaches
/// zero (enable low, DISABLED), two more fault ticks, then a good tick that resumes.
fn ramp_case(fault: Result<Pose, PoseFault>, flag: LoopFlags, cfg: LoopConfig<3>, model: Option<Status>, below_n: f32) {
    let r = row_to_ramp(below_n);
    let step = cfg.ramp_step_n;
    let mut cmds = vec![forces(&r)];
    loop {
        let next = ramp(*cmds.last().expect("one"), step);
        cmds.push(next);
        if next == [0.0; 3] {
            break;
        }
    }
    cmds.push([0.0; 3]);
    cmds.push([0.0; 3]);
    let fault_ticks = cmds.len() - 1;
    assert!(fault_ticks >= 4, "the ramp must take several ticks ({fault_ticks})");
    cmds.push(forces(&r));
    let mut expects = Vec::new();
    for (k, c) in cmds.iter().enumerate() {
        let enable = *c != [0.0; 3] || k == 0 || k == cmds.len() - 1;
        expects.push(expect_for(*c, enable).0);
    }
    let mut script = vec![Ok(r.pose)];
    script.extend(std::iter::repeat_n(fault, fault_ticks));
    script.push(Ok(r.pose));
    let samples = run(cfg, Script::new(script), &expects, &[]);
    assert!(samples[0].flags.is_ok(), "{:?}", samples[0].flags);
    for (k, s) in samples.iter().enumerate().skip(1).take(fault_ticks) {
        assert_eq!(s.force_cmd_n.map(f32::to_bits), cmds[k].map(f32::to_bits), "tick {}", s.tick);
        let mut want = flag | LoopFlags::RAMPING;
        if cmds[k] == [0.0; 3] {
            want |= LoopFlags::DISABLED;
        }
        assert!(
            s.flags.contains(want) && s.flags.bits() & !(want | LoopFlags::OVER_LIMIT).bits() == 0,
            "tick {}: {:?}, want {want:?}",
            s.tick,
            s.flags
        );
        if let Some(m) = model {
            assert_eq!(s.model, m);
        }
    }
    let last = samples.last().expect("samples");
    assert!(last.flags.is_ok(), "resumes at once on a good tick: {:?}", last.flags);
    assert_eq!(last.force_cmd_n, forces(&r));
}

#[test]
fn stale_pose_ramps_to_zero_then_disables() {
    ramp_case(Err(PoseFault::Stale), LoopFlags::POSE_STALE, config(10.0, OverLimit::Saturate, 0.01), Some(Status::OK), f32::INFINITY);
}

#[test]
fn missing_pose_ramps_to_zero_then_disables() {
    ramp_case(Err(PoseFault::Missing), LoopFlags::POSE_MISSING, config(10.0, OverLimit::Saturate, 0.01), Some(Status::OK), f32::INFINITY);
}

#[test]
fn evaluation_error_ramps_to_zero_then_disables() {
    let nan = Pose::new(f32::NAN, 0.0, 0.0, 0.0, 3.0);
    ramp_case(Ok(nan), LoopFlags::EVAL_ERROR, config(10.0, OverLimit::Saturate, 0.01), Some(Status::ERROR), f32::INFINITY);
}

#[test]
fn over_limit_in_ramp_mode_ramps_to_zero() {
    // A pose whose force is far above a tiny limit: the deepest centred pose.
    let deep = Pose::new(0.0, 0.0, 0.0, 0.0, 6.0);
    let deep_f = needle_haptics::wrench(&deep).wrench;
    let deep_n = (deep_f.fx_n.powi(2) + deep_f.fy_n.powi(2) + deep_f.fz_n.powi(2)).sqrt();
    let below_n = deep_n / 1.01;
    let r = row_to_ramp(below_n);
    let n = force_norm_n(&r);
    assert!(deep_n > n * 1.01, "the deep pose must push harder than golden line {}", r.line);
    // The limit lets the good ticks through and stops the deep one.
    let limit = n * 1.005;
    ramp_case(Ok(deep), LoopFlags::OVER_LIMIT, config(limit, OverLimit::RampToZero, 0.005), None, below_n);
}

#[test]
fn first_tick_without_a_pose_disables_at_once() {
    let e = Expect { duties: [0; 3], dirs: [true, true, false], enable: false };
    let s = run(config(10.0, OverLimit::Saturate, 0.01), Script::new([Err(PoseFault::Missing)]), &[e], &[]).remove(0);
    assert_eq!(s.flags, LoopFlags::POSE_MISSING | LoopFlags::RAMPING | LoopFlags::DISABLED);
    assert_eq!(s.wrench, needle_haptics::Wrench::ZERO);
}

#[test]
fn failed_pwm_write_is_flagged_and_the_other_outputs_still_written() {
    let rows = golden_in_domain(10);
    let expects: Vec<Expect> = rows.iter().take(2).map(|r| expect_for(forces(r), true).0).collect();
    let samples = run(config(10.0, OverLimit::Saturate, 0.01), Script::new(rows.iter().take(2).map(|r| Ok(r.pose))), &expects, &[(0, 1)]);
    assert!(samples[0].flags.contains(LoopFlags::OUTPUT_ERROR));
    assert!(!samples[1].flags.contains(LoopFlags::OUTPUT_ERROR), "the flag is per tick");
}

#[test]
fn invalid_configurations_are_refused() {
    let ok = config(1.0, OverLimit::Saturate, 0.01);
    assert_eq!(ok.validate(), Ok(()));
    let mut c = ok;
    c.channels[2].gains_per_n[1] = f32::NAN;
    assert_eq!(c.validate(), Err(ConfigError::Gain));
    for limit in [0.0, -1.0, 20.5, f32::NAN, f32::INFINITY] {
        let c = LoopConfig { force_limit_n: limit, ..ok };
        assert_eq!(c.validate(), Err(ConfigError::ForceLimit), "{limit}");
    }
    for step in [0.0, -0.1, f32::NAN, f32::INFINITY, f32::NEG_INFINITY] {
        let c = LoopConfig { ramp_step_n: step, ..ok };
        assert_eq!(c.validate(), Err(ConfigError::RampStep), "{step}");
    }
    assert_eq!(LoopConfig { ramp_step_n: f32::MAX, ..ok }.validate(), Ok(()), "a finite step above the limit cuts at once");
}

#[test]
fn flags_print_their_names() {
    let f = LoopFlags::POSE_STALE | LoopFlags::RAMPING;
    assert_eq!(format!("{f}"), "POSE_STALE | RAMPING");
    assert_eq!(format!("{f:?}"), "LoopFlags(0x0021: POSE_STALE | RAMPING)");
    assert_eq!(format!("{}", LoopFlags::OK), "OK");
}
