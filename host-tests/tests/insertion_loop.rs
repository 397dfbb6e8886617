//! The whole insertion inside the control loop (`LoopCore::set_insertion`): the loop
//! renders the insertion's wrench bit for bit, its passivity guard takes the deflected
//! boundary's stiffness (`Insertion::step_with_stiffness`: the same ticks as `step`, and
//! the stiffness the derivative of the scaled surrogate), and a puncture clears the
//! guard's offset.
#[path = "../../examples/common/insertion_paths.rs"]
mod paths;

use needle_haptics::control::{ChannelMap, LoopConfig, LoopCore, LoopFlags, OverLimit, Passivity};
use needle_haptics::insertion::{deflection, stacks, Insertion, InsertionConfig, Phase, FE_NEEDLE_DIAMETER_MM};
use needle_haptics::Pose;
use paths::{depth_scale, for_each_tick, PATHS};

fn pose_of(p: [f32; 5]) -> Pose {
    Pose { x_mm: p[0], z_mm: p[1], theta_x_deg: p[2], theta_z_deg: p[3], depth_mm: p[4] }
}

/// Every shipped stack's layers without their Prony terms (the epidural skin has one): the
/// tests of the elastic rule and of the deflection's derivative (with terms the guard's
/// stiffness is `rho K`, docs/insertion.md).
fn elastic_layers() -> Vec<(&'static needle_haptics::insertion::Stack<'static>, Vec<needle_haptics::insertion::Layer>)> {
    stacks::ALL
        .iter()
        .map(|s| {
            (
                s,
                s.layers
                    .iter()
                    .map(|l| needle_haptics::insertion::Layer { prony: needle_haptics::viscoelastic::PronyTerms::NONE, ..*l })
                    .collect(),
            )
        })
        .collect()
}

fn new(stack: &needle_haptics::insertion::Stack<'_>) -> Insertion {
    Insertion::new(stack, InsertionConfig::DEFAULT_1KHZ).expect("shipped stack")
}

/// A one-channel loop whose limit never binds.
fn core() -> LoopCore<1> {
    LoopCore::new(LoopConfig {
        channels: [ChannelMap { gains_per_n: [0.0, 0.01, 0.0], direction_inverted: false }],
        force_limit_n: 100.0,
        force_limit_max_n: 100.0,
        over_limit: OverLimit::Saturate,
        ramp_step_n: 0.01,
    })
    .expect("config")
}

#[test]
fn step_with_stiffness_is_step_and_its_stiffness_is_the_deflections_derivative() {
    for (shipped, layers) in &elastic_layers() {
        let stack = &needle_haptics::insertion::Stack { layers, ..**shipped };
        let lambda = stack.needle_diameter_mm / FE_NEEDLE_DIAMETER_MM;
        for path in PATHS {
            let (mut a, mut b) = (new(stack), new(stack));
            let (mut deflecting, mut checked) = (0, 0);
            for_each_tick(path, depth_scale(stack), |tick, p| {
                let pose = pose_of(p);
                let plain = a.step(&pose);
                let (e, terms) = b.step_with_stiffness(&pose);
                let k = terms.stiffness_n_per_mm;
                assert_eq!(format!("{plain:?}"), format!("{e:?}"), "{} tick {tick}", stack.name);
                match e.phase {
                    Phase::Deflecting(j) if e.punctures == 0 => {
                        deflecting += 1;
                        assert!(k > 0.0 && k.is_finite(), "{} tick {tick}: stiffness {k} while deflecting", stack.name);
                        // the boundary's indentation along the path, and the surrogate's
                        // force change over +-h there (every 50th tick; f32 central
                        // difference: rounding ~1e-7 N / 2h, truncation ~h^2 F''')
                        let layer = b.layers()[usize::from(j)];
                        let above: f32 = b.layers().iter().take(usize::from(j)).map(|l| l.thickness_mm).sum();
                        let a_y = needle_haptics::insertion::needle_axis(&pose)[1];
                        let delta = pose.depth_mm - above / a_y;
                        let h = 0.01f32;
                        // the paper's tissue without softening: the guard's stiffness of a
                        // family member is `k g + |F|₁ |dg/dδ|`, softened with its force (not
                        // the derivative: docs/insertion.md), so the layers of the shaped
                        // `rig_skin` below its skin are checked, its skin is not
                        let paper = layer.family.weight() == 1.0 && layer.softening.fraction == 0.0;
                        if paper && tick % 50 == 0 && delta > 2.0 * h && delta + h < 12.9 * lambda {
                            let f = |d: f32| deflection(&pose, d, layer.stiffness_scale, lambda).wrench.to_array();
                            let (hi, lo) = (f(delta + h), f(delta - h));
                            let diff: f32 = (0..3).map(|c| (hi[c] - lo[c]).powi(2)).sum::<f32>().sqrt() / (2.0 * h);
                            assert!(
                                (k - diff).abs() <= 0.01 * diff + 1e-4,
                                "{} tick {tick}: stiffness {k} N/mm, central difference {diff}",
                                stack.name
                            );
                            checked += 1;
                        }
                    }
                    _ if e.punctures == 0 => assert_eq!(k, 0.0, "{} tick {tick}: stiffness {k} in {:?}", stack.name, e.phase),
                    _ => {}
                }
            });
            assert!(deflecting > 100 && checked > 2, "{}: {deflecting} deflecting ticks, {checked} checked", stack.name);
        }
    }
}

#[test]
fn the_loop_renders_the_insertions_wrench_bit_for_bit() {
    for stack in &stacks::ALL {
        for path in PATHS {
            let mut alone = new(stack);
            let mut l = core();
            l.set_insertion(Some(new(stack)));
            for_each_tick(path, depth_scale(stack), |tick, p| {
                let pose = pose_of(p);
                let want = alone.step(&pose);
                let s = l.step(Ok(pose));
                assert_eq!(s.wrench.to_array().map(f32::to_bits), want.wrench.to_array().map(f32::to_bits), "{} tick {tick}", stack.name);
                assert_eq!(s.force_cmd_n.map(f32::to_bits), [want.wrench.fx_n, want.wrench.fy_n, want.wrench.fz_n].map(f32::to_bits));
                assert_eq!(s.model, want.status);
                assert_eq!(l.insertion_evaluation(), Some(&want), "{} tick {tick}", stack.name);
            });
            assert_eq!(l.insertion(), Some(&alone), "the loop's insertion state is the one stepped alone");
        }
    }
}

#[test]
fn a_puncture_clears_the_guards_offset() {
    // a weak device (0.05 N·s/m): the guard's stiffness b / T = 0.05 N/mm is below the
    // deflection's, so it limits while the boundary deflects and builds an offset
    let guard = Passivity { damping_n_s_per_mm: 0.00005, period_s: 0.001 };
    for stack in &stacks::ALL {
        let mut l = core();
        l.set_passivity(Some(guard)).expect("guard");
        l.set_insertion(Some(new(stack)));
        let (mut limited, mut punctures) = (0, 0);
        for_each_tick(PATHS[0], depth_scale(stack), |tick, p| {
            let s = l.step(Ok(pose_of(p)));
            limited += usize::from(s.flags.contains(LoopFlags::STIFFNESS_LIMITED));
            let e = *l.insertion_evaluation().expect("stepped");
            if e.punctures > 0 {
                punctures += 1;
                // the guard's offset is gone: the command is the model's force, up to the
                // f32 rounding of taking friction out and adding it back (an ulp or two)
                let f = [e.wrench.fx_n, e.wrench.fy_n, e.wrench.fz_n];
                for (c, w) in s.force_cmd_n.iter().zip(f) {
                    assert!(
                        (c - w).abs() <= 1e-6 * w.abs() + 1e-9,
                        "{} tick {tick}: at a puncture the command {:?} is the model's force {f:?}",
                        stack.name,
                        s.force_cmd_n
                    );
                }
            }
        });
        assert!(limited > 100 && punctures >= 1, "{}: {limited} limited ticks, {punctures} punctures", stack.name);
    }
}

/// The guard's rule as it was before the viscoelastic filter had its own share
/// (issue 39), written again here in f32 with the same operations: the reference the
/// loop must give bit for bit for everything without Prony terms.
#[derive(Default)]
struct RuleBefore {
    offset_n: [f32; 3],
    last_n: Option<[f32; 3]>,
}

impl RuleBefore {
    fn apply(&mut self, k_g: f32, f: [f32; 3], k: f32, d: [f32; 3]) -> [f32; 3] {
        if d == [0.0; 3] {
            return self.elastic(k_g, f, k);
        }
        let g = self.elastic(k_g, [f[0] - d[0], f[1] - d[1], f[2] - d[2]], k);
        [g[0] + d[0], g[1] + d[1], g[2] + d[2]]
    }

    fn elastic(&mut self, k_g: f32, f: [f32; 3], k: f32) -> [f32; 3] {
        if let (Some(last), true) = (self.last_n, k > k_g) {
            let keep = 1.0 - k_g / k;
            for ((o, f), l) in self.offset_n.iter_mut().zip(f).zip(last) {
                *o += keep * (f - l);
            }
        }
        if f == [0.0; 3] {
            self.offset_n = [0.0; 3];
        }
        self.last_n = Some(f);
        [f[0] - self.offset_n[0], f[1] - self.offset_n[1], f[2] - self.offset_n[2]]
    }
}

/// The elastic insertion (every shipped stack, every golden path) and the block
/// surrogate through the guarded loop give the bits of the rule before issue 39's change
/// (`RuleBefore`, driven by a copy of the insertion's `step_with_stiffness` and by
/// `wrench_and_depth_rate`), with the guard limiting (a weak device).
#[test]
fn without_prony_terms_the_guarded_loop_gives_the_rules_bits_as_before() {
    let guard = Passivity { damping_n_s_per_mm: 0.00005, period_s: 0.001 };
    let k_g = guard.guard_stiffness_n_per_mm();
    for (shipped, layers) in &elastic_layers() {
        let stack = &needle_haptics::insertion::Stack { layers, ..**shipped };
        for path in PATHS {
            let mut l = core();
            l.set_passivity(Some(guard)).expect("guard");
            l.set_insertion(Some(new(stack)));
            let (mut model, mut rule, mut limited) = (new(stack), RuleBefore::default(), 0);
            for_each_tick(path, depth_scale(stack), |tick, p| {
                let s = l.step(Ok(pose_of(p)));
                let (e, terms) = model.step_with_stiffness(&pose_of(p));
                if e.punctures > 0 {
                    rule = RuleBefore::default();
                }
                let want = rule.apply(k_g, [e.wrench.fx_n, e.wrench.fy_n, e.wrench.fz_n], terms.stiffness_n_per_mm, terms.dissipative_n);
                limited += usize::from(s.flags.contains(LoopFlags::STIFFNESS_LIMITED));
                assert_eq!(s.force_cmd_n.map(f32::to_bits), want.map(f32::to_bits), "{} tick {tick}", stack.name);
            });
            assert!(limited > 100, "{}: the guard limited only {limited} ticks", stack.name);
        }
    }
    // the block surrogate: the whole force guarded, its stiffness |dF/d depth|; a device
    // of 0.001 N·s/m (k_g = 0.001 N/mm), below the block's stiffness over the motion
    let guard = Passivity { damping_n_s_per_mm: 0.000001, period_s: 0.001 };
    let k_g = guard.guard_stiffness_n_per_mm();
    let mut l = core();
    l.set_passivity(Some(guard)).expect("guard");
    let (mut rule, mut limited) = (RuleBefore::default(), 0);
    for k in 0..6000 {
        let t = k as f32 * 0.001;
        let pose = Pose { x_mm: 2.0, z_mm: -1.0, theta_x_deg: 3.0, theta_z_deg: -2.0, depth_mm: 3.0 + 2.5 * (1.3 * t).sin() };
        let s = l.step(Ok(pose));
        let (e, [dx, dy, dz]) = needle_haptics::wrench_and_depth_rate(&pose);
        let want = rule.apply(k_g, [e.wrench.fx_n, e.wrench.fy_n, e.wrench.fz_n], (dx * dx + dy * dy + dz * dz).sqrt(), [0.0; 3]);
        limited += usize::from(s.flags.contains(LoopFlags::STIFFNESS_LIMITED));
        assert_eq!(s.force_cmd_n.map(f32::to_bits), want.map(f32::to_bits), "block surrogate tick {k}");
    }
    assert!(limited > 100, "block surrogate: the guard limited only {limited} ticks");
}
