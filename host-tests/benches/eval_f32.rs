//! Host benchmark of the library's f32 paper model: wrench evaluations per second over a
//! fixed pseudo-random pose set, next to the paper's 5.12 s per evaluation in MATLAB.
//!
//! `cargo bench -p needle-host-tests --bench eval_f32` (plain `std::time`, no harness). Timings
//! on shared machines are noisy: the best of several rounds is reported, and the ratio
//! matters more than the absolute figure.
use needle_haptics::{model_info, wrench, Pose};
use std::hint::black_box;
use std::time::Instant;

/// The paper's figure: seconds per evaluation of the parametric model in MATLAB.
const PAPER_MATLAB_S: f64 = 5.12;
const POSES: usize = 4096;
const ROUNDS: usize = 15;

/// xorshift32: a fixed, dependency-free pose set (same on every run and machine).
fn poses() -> Vec<Pose> {
    let mut s: u32 = 0x9e37_79b9;
    let mut next = move |lo: f32, hi: f32| {
        s ^= s << 13;
        s ^= s >> 17;
        s ^= s << 5;
        lo + (hi - lo) * (s >> 8) as f32 / (1u32 << 24) as f32
    };
    (0..POSES)
        .map(|_| Pose {
            x_mm: next(-12.0, 12.0),
            z_mm: next(-12.0, 12.0),
            theta_x_deg: next(-15.0, 15.0),
            theta_z_deg: next(-15.0, 15.0),
            depth_mm: next(0.0, 6.0),
        })
        .collect()
}

fn main() {
    // `cargo bench` passes `--bench`; `cargo test --benches` runs us without it: one quick round.
    let quick = !std::env::args().any(|a| a == "--bench");
    let poses = poses();
    let rounds = if quick { 1 } else { ROUNDS };
    let per_round = if quick { 1 } else { 50 };
    if !model_info::FITTED {
        println!(
            "warning: no fitted model compiled in ({} has no model.toml): this measures the NO_MODEL early return",
            model_info::SET_DIR
        );
    }
    let mut sink = 0.0f32;
    // warm-up
    for p in &poses {
        sink += wrench(black_box(p)).wrench.fy_n;
    }
    let mut best = f64::INFINITY;
    for _ in 0..rounds {
        let t = Instant::now();
        for _ in 0..per_round {
            for p in &poses {
                let e = wrench(black_box(p));
                sink += e.wrench.fy_n + f32::from(e.status.bits());
            }
        }
        let ns = t.elapsed().as_secs_f64() * 1e9 / (per_round * poses.len()) as f64;
        best = best.min(ns);
    }
    black_box(sink);
    let per_s = 1e9 / best;
    println!("needle-haptics f32 paper model, set {:?} ({})", model_info::SET, model_info::SET_DIR);
    println!("  {:.1} ns per 6-axis wrench (best of {rounds} rounds of {} evaluations)", best, per_round * poses.len());
    println!("  {:.3e} wrench evaluations per second", per_s);
    println!("  paper (MATLAB): {PAPER_MATLAB_S} s per evaluation -> {:.2e} times faster here", PAPER_MATLAB_S * per_s);
    println!("  haptic budget at 1 kHz / 10 kHz: {:.4} % / {:.4} % of one core", best / 1e4, best / 1e3);
}
