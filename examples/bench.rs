//! Firmware example `bench`: instructions per 6-axis wrench evaluation and the stack
//! high-water mark of one evaluation, on the core it is compiled for.
//!
//! Run it under QEMU with `-icount shift=0` (the runners in .cargo/config.toml do; so
//! does `needle firmware bench`): QEMU's virtual clock then advances exactly 1 ns per
//! executed instruction, and SysTick, clocked by the core clock (25 MHz on MPS2, 16 MHz
//! on the micro:bit), counts executed instructions in steps of 40 (62.5).
//!
//! - **Calibration**: an assembly loop of exactly 2 instructions per iteration
//!   (`subs; bne`) is timed at two lengths; the difference gives instructions per
//!   SysTick tick without knowing the board's clock, and two runs of the same length
//!   must give the same ticks (else the run is not under `-icount`: `deterministic=no`).
//! - **Instructions per wrench**: `CALLS` calls of [`needle_haptics::wrench`] (f32) or
//!   [`needle_haptics::fixed::wrench`] (fixed point) through an opaque function pointer
//!   on an opaque pose (`core::hint::black_box`, so nothing is hoisted out of the loop or
//!   folded at compile time), minus the same loop without the call, divided by `CALLS`.
//!   The figure includes the call, the return and the evaluator's stores of its result
//!   into the caller's slot; the loop keeps the result where the evaluator wrote it
//!   (`black_box(&result)`), as a caller does, instead of moving it into a second slot
//!   (`black_box(result)`, measured on the M4F: +5.1 instructions for the
//!   28-byte wrench, +121 for the 100-byte wrench and stiffness, whose move is a
//!   `memcpy`: a cost of the harness, not of the evaluator). Both
//!   evaluators run in the same firmware, one after the other, on the same poses (the
//!   fixed-point pose is the f32 one in Q16.16). Evaluator `f32+k` is
//!   [`needle_haptics::wrench_and_stiffness`] (the wrench and its 18 rates; its result is
//!   100 bytes), `fixed+k` [`needle_haptics::fixed::wrench_and_stiffness`] (the same in
//!   integers).
//! - **Insertion** (per compiled-in stack, a tick deflecting the surface and a tick deep
//!   inside, from a state advanced there at 3 mm/s), the stack's layers without Prony
//!   terms (the elastic insertion, also for a shipped layer with terms): evaluator
//!   `insertion` ([`needle_haptics::insertion::Insertion::step`]) and `fixed-insertion`
//!   ([`needle_haptics::fixed::insertion::Insertion::step`], the same poses in Q16.16).
//!   With the viscoelastic filter: `insertion+qlv` and `fixed-insertion+qlv`, the same
//!   stacks and cases with three Prony terms on every layer ([`QLV_TERMS`]: cost inputs,
//!   not a tissue's values; the filter's work does not depend on them), so every tick
//!   filters all six components through three terms.
//! - **Stack**: the 4 KiB below the caller's stack pointer is painted with a pattern,
//!   one evaluation runs, and the deepest overwritten word gives the bytes used.
//!
//! Output (semihosting stdout):
//!
//! ```text
//! needle-bench target=<triple> calls=<CALLS> calibration_instructions=<n> calibration_ticks=<n> deterministic=<yes|no>
//! needle-bench pose=<name> evaluator=<f32|f32+k|fixed|fixed+k|insertion|fixed-insertion|insertion+qlv|fixed-insertion+qlv> instructions_per_wrench=<n.n> stack_bytes=<n> status=0x<ss>
//! ...
//! needle-bench end
//! ```
#![cfg_attr(target_os = "none", no_std, no_main)]

#[cfg(target_os = "none")]
mod common;

#[cfg(target_os = "none")]
mod firmware {
    use crate::common::icount::{elapsed, Calibration};
    use crate::common::{exit, target_name, Out};
    use core::arch::asm;
    use core::hint::black_box;
    use cortex_m::peripheral::SYST;
    use needle_haptics::fixed::insertion::Insertion as FixedInsertion;
    use needle_haptics::insertion::{stacks, Insertion, InsertionConfig, InsertionEvaluation};
    use needle_haptics::insertion::{Layer, MAX_LAYERS};
    #[cfg(feature = "viscoelastic")]
    use needle_haptics::viscoelastic::PronyTerm;
    use needle_haptics::viscoelastic::PronyTerms;
    use needle_haptics::{fixed, wrench, wrench_and_stiffness, Pose};

    /// Evaluations per timed loop.
    const CALLS: u32 = 256;

    /// Three Prony terms for the `+qlv` rows (built with the `viscoelastic` feature, as
    /// `needle firmware bench` does) (weights and time constants of the
    /// host-tests' filter tests: cost inputs, the step's work is the same for any).
    #[cfg(feature = "viscoelastic")]
    const QLV_TERMS: [PronyTerm; 3] =
        [PronyTerm { g: 0.8, tau_s: 0.05 }, PronyTerm { g: 0.5, tau_s: 1.0 }, PronyTerm { g: 0.3, tau_s: 20.0 }];

    /// `stack`'s layers with `terms` on each (the first `count` used): [`QLV_TERMS`] for
    /// the `+qlv` rows, none for the plain rows (the elastic insertion, whatever terms a
    /// shipped layer has, so that `+qlv` minus plain is the filter's cost).
    fn with_terms(stack: &needle_haptics::insertion::Stack<'_>, terms: PronyTerms) -> Option<([Layer; MAX_LAYERS], usize)> {
        let mut layers = [*stack.layers.first()?; MAX_LAYERS];
        for (slot, l) in layers.iter_mut().zip(stack.layers) {
            *slot = Layer { prony: terms, ..*l };
        }
        Some((layers, stack.layers.len()))
    }
    /// Bytes of stack painted below the caller's stack pointer.
    const STACK_WINDOW: usize = 4096;
    const PAINT: u32 = 0xa5c3_5a3c;

    /// The poses timed: in the domain with mixed signs (the typical case), all
    /// positive, every input saturated, and a NaN input (the error path).
    const POSES: [(&str, Pose); 4] = [
        ("typical", Pose::new(3.0, -2.0, 5.0, -7.0, 4.5)),
        ("positive", Pose::new(6.0, 4.0, 10.0, 2.0, 3.0)),
        ("saturated", Pose::new(20.0, -20.0, 30.0, -30.0, 9.0)),
        ("nan-input", Pose::new(f32::NAN, 0.0, 0.0, 0.0, 1.0)),
    ];

    /// The same poses in Q16.16 for the fixed-point evaluator (no NaN in integers).
    const ONE: i32 = fixed::Pose::ONE;
    const POSES_FIXED: [(&str, fixed::Pose); 3] = [
        ("typical", fixed::Pose::new(3 * ONE, -2 * ONE, 5 * ONE, -7 * ONE, 9 * ONE / 2)),
        ("positive", fixed::Pose::new(6 * ONE, 4 * ONE, 10 * ONE, 2 * ONE, 3 * ONE)),
        ("saturated", fixed::Pose::new(20 * ONE, -20 * ONE, 30 * ONE, -30 * ONE, 9 * ONE)),
    ];

    #[inline(never)]
    fn loop_wrench<P, E>(f: fn(&P) -> E, pose: &P, calls: u32) -> u32 {
        let start = SYST::get_current();
        for _ in 0..calls {
            black_box(&f(black_box(pose)));
        }
        elapsed(start, SYST::get_current())
    }

    #[inline(never)]
    fn loop_empty<P>(pose: &P, calls: u32) -> u32 {
        let start = SYST::get_current();
        for _ in 0..calls {
            black_box(black_box(pose));
        }
        elapsed(start, SYST::get_current())
    }

    /// An insertion model the bench ticks: the f32 one or the fixed-point one.
    trait Ticks: Copy {
        type Pose: Copy;
        type Out;
        fn tick(&mut self, pose: &Self::Pose) -> Self::Out;
        fn status_bits(out: &Self::Out) -> u8;
    }

    impl Ticks for Insertion {
        type Pose = Pose;
        type Out = InsertionEvaluation;
        fn tick(&mut self, pose: &Pose) -> InsertionEvaluation {
            self.step(pose)
        }
        fn status_bits(out: &InsertionEvaluation) -> u8 {
            out.status.bits()
        }
    }

    impl Ticks for FixedInsertion<'_> {
        type Pose = fixed::Pose;
        type Out = fixed::insertion::InsertionEvaluation;
        fn tick(&mut self, pose: &fixed::Pose) -> fixed::insertion::InsertionEvaluation {
            self.step(pose)
        }
        fn status_bits(out: &fixed::insertion::InsertionEvaluation) -> u8 {
            out.status.bits()
        }
    }

    /// `calls` insertion ticks at `pose` from the state `ins` (each from the same state:
    /// the state is restored from `start` before each tick, which the empty loop does too).
    #[inline(never)]
    fn loop_insertion<T: Ticks>(start: &T, pose: &T::Pose, calls: u32, tick: bool) -> u32 {
        let t0 = SYST::get_current();
        for _ in 0..calls {
            let mut ins = *black_box(start);
            if tick {
                black_box(&ins.tick(black_box(pose)));
            } else {
                black_box(&mut ins);
            }
        }
        elapsed(t0, SYST::get_current())
    }

    /// One insertion model's line: instructions per step from the state `ins` at `pose`
    /// (the timed loop minus the empty one), the stack of one step and its status,
    /// labelled `<stack>-<case>` with the evaluator's name (`what`).
    fn bench_insertion<T: Ticks>(out: &mut Out, cal: &Calibration, ins: &T, pose: &T::Pose, what: (&str, &str, &str)) {
        let (stack, case, evaluator) = what;
        let tenths = cal.tenths_per_call(
            loop_insertion(ins, pose, black_box(CALLS), true),
            loop_insertion(ins, pose, black_box(CALLS), false),
            CALLS,
        );
        let step: fn(&(T, T::Pose)) -> T::Out = |p| {
            let mut i = p.0;
            i.tick(&p.1)
        };
        let stack_bytes = stack_use(step, &(*ins, *pose));
        let mut label = [0u8; 24];
        let n = label_of(&mut label, stack, case);
        let status = T::status_bits(&step(&(*ins, *pose)));
        report(
            out,
            label.get(..n).and_then(|l| core::str::from_utf8(l).ok()).unwrap_or("insertion"),
            evaluator,
            tenths,
            stack_bytes,
            status,
        );
    }

    /// The fixed-point state of a needle advanced at 3 mm/s along `pose`'s axis to its
    /// depth.
    fn advanced_fixed<'a>(stack: &'a fixed::insertion::Stack, pose: &fixed::Pose) -> Option<FixedInsertion<'a>> {
        let mut ins = FixedInsertion::new(stack, fixed::insertion::InsertionConfig::DEFAULT_1KHZ).ok()?;
        let mut d = -fixed::Pose::ONE / 2;
        while d < pose.depth_mm_q16 {
            ins.step(&fixed::Pose { depth_mm_q16: d, ..*pose });
            d += 197; // 3 µm in Q16.16 (196.6)
        }
        Some(ins)
    }

    /// The state of a needle advanced at 3 mm/s along `pose`'s axis to its depth.
    fn advanced(stack: &needle_haptics::insertion::Stack<'_>, pose: &Pose) -> Option<Insertion> {
        let mut ins = Insertion::new(stack, InsertionConfig::DEFAULT_1KHZ).ok()?;
        let mut d = -0.5f32;
        while d < pose.depth_mm {
            ins.step(&Pose { depth_mm: d, ..*pose });
            d += 0.003;
        }
        Some(ins)
    }

    /// Bytes of stack one call of `f` uses below this function's stack pointer.
    #[inline(never)]
    fn stack_use<P, E>(f: fn(&P) -> E, pose: &P) -> usize {
        let top: usize;
        // SAFETY: reads the stack pointer.
        unsafe { asm!("mov {}, sp", out(reg) top, options(nomem, nostack, preserves_flags)) };
        let bottom = top - STACK_WINDOW;
        let mut a = bottom;
        while a < top {
            // SAFETY: the window lies below the live stack (nothing else runs: no
            // interrupts are enabled) and inside RAM (4 KiB of the 16 KiB or 4 MiB).
            unsafe { (a as *mut u32).write_volatile(PAINT) };
            a += 4;
        }
        black_box(f(black_box(pose)));
        let mut a = bottom;
        // SAFETY: as above.
        while a < top && unsafe { (a as *const u32).read_volatile() } == PAINT {
            a += 4;
        }
        top - a
    }

    /// `<stack>-<case>` into `buf` (truncated to fit), its length.
    fn label_of(buf: &mut [u8; 24], stack: &str, case: &str) -> usize {
        let mut n = 0;
        for b in stack.bytes().chain(*b"-").chain(case.bytes()) {
            if let Some(slot) = buf.get_mut(n) {
                *slot = b;
                n += 1;
            }
        }
        n
    }

    /// One `needle-bench pose=...` line.
    fn report(out: &mut Out, pose: &str, evaluator: &str, tenths: u64, stack: usize, status: u8) {
        out.str("needle-bench pose=");
        out.str(pose);
        out.str(" evaluator=");
        out.str(evaluator);
        out.str(" instructions_per_wrench=");
        out.tenths(tenths);
        out.str(" stack_bytes=");
        if stack >= STACK_WINDOW {
            out.str(">=");
        }
        out.dec(stack as u64);
        out.str(" status=");
        out.hex(u32::from(status), 2);
        out.nl();
    }

    #[cortex_m_rt::entry]
    fn main() -> ! {
        let mut out = Out::new();
        let Some(p) = cortex_m::Peripherals::take() else {
            out.str("needle-bench error: core peripherals taken\n");
            out.flush();
            exit(false)
        };
        let mut syst = p.SYST;
        let cal = Calibration::start(&mut syst);
        out.str("needle-bench target=");
        out.str(target_name());
        out.str(" calls=");
        out.dec(u64::from(CALLS));
        out.str(" calibration_instructions=");
        out.dec(cal.instructions);
        out.str(" calibration_ticks=");
        out.dec(cal.ticks);
        out.str(" deterministic=");
        out.str(if cal.deterministic { "yes" } else { "no" });
        out.nl();
        if cal.ticks == 0 {
            out.str("needle-bench error: SysTick does not count\n");
            out.flush();
            exit(false)
        }

        let eval: fn(&Pose) -> needle_haptics::Evaluation = black_box(wrench);
        let eval_fixed: fn(&fixed::Pose) -> fixed::Evaluation = black_box(fixed::wrench);
        let eval_stiffness: fn(&Pose) -> needle_haptics::StiffnessEvaluation = black_box(wrench_and_stiffness);
        let eval_fixed_k: fn(&fixed::Pose) -> fixed::StiffnessEvaluation = black_box(fixed::wrench_and_stiffness);
        let per_call = |tw: u32, te: u32| -> u64 { cal.tenths_per_call(tw, te, CALLS) };
        for (name, pose) in POSES.iter() {
            let tenths = per_call(loop_wrench(eval, pose, black_box(CALLS)), loop_empty(pose, black_box(CALLS)));
            let stack = stack_use(eval, pose);
            report(&mut out, name, "f32", tenths, stack, eval(pose).status.bits());
            let tenths = per_call(loop_wrench(eval_stiffness, pose, black_box(CALLS)), loop_empty(pose, black_box(CALLS)));
            let stack = stack_use(eval_stiffness, pose);
            report(&mut out, name, "f32+k", tenths, stack, eval_stiffness(pose).status.bits());
            if let Some((_, q)) = POSES_FIXED.iter().find(|(n, _)| n == name) {
                let tenths = per_call(loop_wrench(eval_fixed, q, black_box(CALLS)), loop_empty(q, black_box(CALLS)));
                let stack = stack_use(eval_fixed, q);
                report(&mut out, name, "fixed", tenths, stack, eval_fixed(q).status.bits());
                let tenths = per_call(loop_wrench(eval_fixed_k, q, black_box(CALLS)), loop_empty(q, black_box(CALLS)));
                let stack = stack_use(eval_fixed_k, q);
                report(&mut out, name, "fixed+k", tenths, stack, eval_fixed_k(q).status.bits());
            }
        }
        // The insertion model, per stack: a tick deflecting the surface (the surrogate),
        // and a tick deep inside after the punctures (friction over every layer passed,
        // the track's hold, cutting or the next boundary's deflection), the tilted pose.
        for stack in &stacks::ALL {
            let total: f32 = stack.layers.iter().map(|l| l.thickness_mm).sum();
            let cases = [("surface", Pose::new(3.0, -2.0, 5.0, -7.0, 4.5)), ("deep", Pose::new(3.0, -2.0, 5.0, -7.0, total + 2.0))];
            let Some((elastic_layers, count)) = with_terms(stack, PronyTerms::NONE) else {
                continue;
            };
            let elastic = needle_haptics::insertion::Stack { layers: elastic_layers.get(..count).unwrap_or(&[]), ..*stack };
            #[cfg(feature = "viscoelastic")]
            let Some((qlv_layers, count)) = PronyTerms::from_array(QLV_TERMS, 3).and_then(|t| with_terms(stack, t)) else {
                continue;
            };
            #[cfg(feature = "viscoelastic")]
            let qlv = needle_haptics::insertion::Stack { layers: qlv_layers.get(..count).unwrap_or(&[]), ..*stack };
            for (name, pose) in cases {
                let Some(ins) = advanced(&elastic, &pose) else { continue };
                bench_insertion(&mut out, &cal, &ins, &pose, (stack.name, name, "insertion"));
                #[cfg(feature = "viscoelastic")]
                {
                    let Some(ins) = advanced(&qlv, &pose) else { continue };
                    bench_insertion(&mut out, &cal, &ins, &pose, (stack.name, name, "insertion+qlv"));
                }
            }
        }
        // The fixed-point insertion, the same cases in Q16.16.
        for stack in &fixed::insertion::stacks::ALL {
            let total: i32 = stack.layers().iter().map(|l| l.thickness_q16 as i32).sum();
            let tilted = |depth| fixed::Pose::new(3 * ONE, -2 * ONE, 5 * ONE, -7 * ONE, depth);
            // without the feature the fixed-point layers carry no terms: the stack is elastic
            #[cfg_attr(not(feature = "viscoelastic"), allow(unused_mut))]
            let mut elastic = *stack;
            #[cfg(feature = "viscoelastic")]
            for l in &mut elastic.layers {
                l.prony = fixed::viscoelastic::PronyTerms::NONE;
            }
            #[cfg(feature = "viscoelastic")]
            let mut qlv = *stack;
            #[cfg(feature = "viscoelastic")]
            if let Some(t) = PronyTerms::from_array(QLV_TERMS, 3) {
                for l in &mut qlv.layers {
                    l.prony = fixed::viscoelastic::PronyTerms::from_f32(&t);
                }
            }
            for (name, pose) in [("surface", tilted(9 * ONE / 2)), ("deep", tilted(total + 2 * ONE))] {
                let Some(ins) = advanced_fixed(&elastic, &pose) else { continue };
                bench_insertion(&mut out, &cal, &ins, &pose, (stack.name, name, "fixed-insertion"));
                #[cfg(feature = "viscoelastic")]
                {
                    let Some(ins) = advanced_fixed(&qlv, &pose) else { continue };
                    bench_insertion(&mut out, &cal, &ins, &pose, (stack.name, name, "fixed-insertion+qlv"));
                }
            }
        }
        out.str("needle-bench end\n");
        out.flush();
        exit(true)
    }
}

/// On the host this example does nothing: it is firmware.
#[cfg(not(target_os = "none"))]
fn main() {
    eprintln!(
        "`bench` is firmware: cargo run --release --example bench --target thumbv7em-none-eabihf \
         (the runner adds -icount shift=0), or `needle firmware bench`"
    );
}
