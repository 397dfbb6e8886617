//! The fixed-point insertion against the f32 one, tick by tick, on the golden paths of
//! every shipped stack (`examples/common/insertion_paths.rs`): the same phases and
//! punctures except for a few ticks where a puncture lands one tick apart (the two
//! compare the axial force with the threshold in different arithmetic), and wherever
//! the phases agree a wrench within the fixed-point model's error bound carried through
//! the insertion's gains (the bound is derived below, not fitted to the result).
#[path = "../../examples/common/insertion_paths.rs"]
mod paths;

use needle_haptics::fixed;
use needle_haptics::fixed::insertion as fx;
use needle_haptics::insertion::{stacks, Insertion, InsertionConfig};
use needle_haptics::Pose;
use paths::{depth_scale, for_each_tick, for_each_tick_q16, PATHS};

/// The fixed-point stack's largest force and moment gains (`s λ²`, `s λ³`) and the depth
/// extension's largest ratio `R` (at its deepest point, or 1 without it).
fn gains(stack: &fx::Stack) -> (f64, f64) {
    let [l2, l3] = stack.similarity_pow_q16.map(|v| v as f64 / 65536.0);
    let s = stack.layers().iter().map(|l| l.stiffness_scale_q16 as f64 / 65536.0).fold(0.0, f64::max);
    (s * l2, s * l3)
}

fn ratio_max() -> f64 {
    use needle_haptics::depth_extension::tables::{COEFFS, FITTED};
    if !FITTED {
        return 1.0;
    }
    // R(v) over v in [0, 1], sampled finely: the extension's largest magnification
    (0..=1000)
        .map(|i| {
            let v = f64::from(i) / 1000.0;
            let [c1, c2, c3, c4] = COEFFS.map(f64::from);
            1.0 + v * (c1 + v * (c2 + v * (c3 + v * c4)))
        })
        .fold(1.0, f64::max)
}

#[test]
fn fixed_point_insertion_follows_the_f32_one_on_every_golden_path() {
    assert!(!stacks::ALL.is_empty());
    let r_max = ratio_max();
    for (stack, fstack) in stacks::ALL.iter().zip(&fx::stacks::ALL) {
        assert_eq!(stack.name, fstack.name);
        let (gf, gm) = gains(fstack);
        // Per component, µN or µN·mm: the fixed-point model's bound against f64, through
        // the gain and the extension's ratio (the surrogate's error is scaled with its
        // value), plus the f32 model's own error against f64 (below 1e-6 of the value,
        // taken as 1e-6 of the largest f32 value seen on the path) and 1 µN of rounding
        // per term of the wrench (deflection, preload, friction, cutting, hold per layer:
        // at most 2 + 2 * MAX_LAYERS terms).
        let bound: Vec<f64> = fixed::tables::ERROR_BOUND_MICRO
            .iter()
            .enumerate()
            .map(|(c, &b)| f64::from(b) * if c < 3 { gf } else { gm } * r_max + 2.0 + 2.0 * fx::MAX_LAYERS as f64)
            .collect();
        for (i, path) in PATHS.iter().enumerate() {
            let mut ins = Insertion::new(stack, InsertionConfig::DEFAULT_1KHZ).expect("shipped stack");
            let mut fins = fx::Insertion::new(fstack, fx::InsertionConfig::DEFAULT_1KHZ).expect("shipped stack in fixed point");
            let mut f32_out = Vec::new();
            for_each_tick(path, depth_scale(stack), |_, p| {
                let e = ins.step(&Pose { x_mm: p[0], z_mm: p[1], theta_x_deg: p[2], theta_z_deg: p[3], depth_mm: p[4] });
                f32_out.push(e);
            });
            let mut fixed_out = Vec::new();
            for_each_tick_q16(path, depth_scale(stack), |_, p| fixed_out.push(fins.step(&fixed::Pose::new(p[0], p[1], p[2], p[3], p[4]))));
            assert_eq!(f32_out.len(), fixed_out.len());
            let peak: f64 = f32_out.iter().flat_map(|e| e.wrench.to_array()).map(|c| f64::from(c).abs() * 1e6).fold(0.0, f64::max);
            let (mut phase_differs, mut worst, mut worst_rel, mut saturated) = (0usize, [0.0f64; 6], 0.0f64, 0usize);
            let punctures = |v: &dyn Fn(usize) -> u8| (0..f32_out.len()).map(|k| u64::from(v(k))).sum::<u64>();
            let (pf, px) = (punctures(&|k| f32_out[k].punctures), punctures(&|k| fixed_out[k].punctures));
            for (k, (a, b)) in f32_out.iter().zip(&fixed_out).enumerate() {
                if a.phase != b.phase {
                    phase_differs += 1;
                    continue;
                }
                for (c, (x, y)) in a.wrench.to_array().iter().zip(b.wrench.to_array()).enumerate() {
                    // a fixed-point component is an i32 (µN, µN·mm): a moment beyond
                    // ±2,147 N·mm saturates by its type (`fixed::insertion`'s module docs),
                    // where the f32 one is bounded only by the sum's 10,000 N·mm; the
                    // shipped `rig_skin` reaches -2,150.7 N·mm on path 2 (a tilted needle
                    // drifting sideways in its stiff bottom layer): compared in the type's range
                    let want = (f64::from(*x) * 1e6).clamp(f64::from(i32::MIN), f64::from(i32::MAX));
                    saturated += usize::from(want != f64::from(*x) * 1e6);
                    let d = (want - f64::from(y)).abs();
                    worst[c] = worst[c].max(d);
                    let allowed = bound[c] + 1e-6 * peak;
                    worst_rel = worst_rel.max(d / allowed);
                    assert!(
                        d <= allowed,
                        "{} path {i} tick {k} component {c}: f32 {x} N(mm), fixed {y} µN(mm), differ by {d:.1} > {allowed:.1}",
                        stack.name
                    );
                }
            }
            println!(
                "{} path {i}: {} ticks, punctures f32 {pf} fixed {px}, phase differs in {phase_differs} ticks, largest difference {:?} µN(mm) (bound {:?}), worst/bound {worst_rel:.3}, f32 components beyond i32 {saturated}",
                stack.name,
                f32_out.len(),
                worst.map(|w| w.round()),
                bound.iter().map(|b| b.round()).collect::<Vec<_>>()
            );
            assert_eq!(pf, px, "{} path {i}: the same punctures", stack.name);
            // a puncture one tick apart makes the phases differ in that tick, and the
            // cutting phase's start depends on the filtered velocity's sign (one more)
            assert!(phase_differs <= 2 * pf as usize + 2, "{} path {i}: phases differ in {phase_differs} ticks", stack.name);
        }
    }
}

#[test]
fn the_compiled_stacks_convert_to_integers() {
    for (stack, f) in stacks::ALL.iter().zip(&fx::stacks::ALL) {
        assert_eq!(f.count, stack.layers.len(), "{}: every layer converted", stack.name);
        for (l, q) in stack.layers.iter().zip(f.layers()) {
            assert!((q.thickness_q16 as f64 / 65536.0 - f64::from(l.thickness_mm)).abs() <= 0.5 / 65536.0);
            // µN Q16: a resolution of 1.5e-11 N; 1e-10 N leaves room for the f64 products
            assert!((q.puncture_force_q16 as f64 / 65536.0 / 1e6 - f64::from(l.puncture_force_n)).abs() <= 1e-10);
            assert!(q.puncture_force_q16 > 0, "{}: a positive puncture force stays positive", stack.name);
            assert!((q.stiffness_scale_q16 as f64 / 65536.0 - f64::from(l.stiffness_scale)).abs() <= 0.5 / 65536.0);
        }
        assert!(fx::Insertion::new(f, fx::InsertionConfig::DEFAULT_1KHZ).is_ok());
    }
}

#[test]
fn bad_configurations_and_scales_are_refused() {
    use needle_haptics::insertion::InsertionError;
    let stack = &fx::stacks::ALL[0];
    let zero = fx::InsertionConfig { period_us: 0, velocity_time_constant_us: 0, ..fx::InsertionConfig::DEFAULT_1KHZ };
    assert_eq!(fx::Insertion::new(stack, zero).err(), Some(InsertionError::Config));
    let empty = fx::Stack { count: 0, ..*stack };
    let empty = &empty;
    assert_eq!(fx::Insertion::new(empty, fx::InsertionConfig::DEFAULT_1KHZ).err(), Some(InsertionError::LayerCount));
    let mut ins = fx::Insertion::new(stack, fx::InsertionConfig::DEFAULT_1KHZ).expect("stack");
    assert_eq!(
        ins.set_scales(&[1 << 16]).err().filter(|_| stack.count != 1),
        if stack.count != 1 { Some(InsertionError::Scales) } else { None }
    );
    let zeros = vec![0; stack.count];
    assert_eq!(ins.set_scales(&zeros).err(), Some(InsertionError::Scales));
    let ones = vec![1 << 16; stack.count];
    assert_eq!(ins.set_scales(&ones), Ok(()));
    assert!(ins.scales_q16().iter().all(|&s| s == 1 << 16));
    assert_eq!(ins.scales_q16().len(), stack.count);
}
