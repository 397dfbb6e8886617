//! Host benchmark of `needle eval --poses`: parse a CSV of 100,000 poses, evaluate each
//! with the library, format the output CSV; the best of several rounds, in poses per
//! second (issue 19's goal: 100,000 poses in under 1 s on one core). Parsing, evaluation
//! and formatting are timed separately to show where the time goes. Beside it, the
//! streaming path the command takes for CSV (`eval_stream`: chunks, every core, bounded
//! memory) on 1,000,000 poses from a file (issue 38's goal: <= 1 s), and the ratio of the
//! two per pose.
//!
//! `cargo bench -p needle-host-tests --bench eval_batch` (plain `std::time`, no harness).
use needle_cli::commands::eval::batch::{evaluate, parse_poses, to_csv};
use needle_cli::commands::eval::stream as eval_stream;
use std::hint::black_box;
use std::path::Path;
use std::time::Instant;

const POSES: usize = 100_000;
const ROUNDS: usize = 5;

fn input(poses: usize) -> String {
    let mut s: u32 = 0x1234_5678;
    let mut next = move |lo: f32, hi: f32| {
        s ^= s << 13;
        s ^= s >> 17;
        s ^= s << 5;
        lo + (hi - lo) * (s >> 8) as f32 / (1u32 << 24) as f32
    };
    let mut t = String::from("x_mm,z_mm,theta_x_deg,theta_z_deg,depth_mm\n");
    for _ in 0..poses {
        let v = [next(-12.0, 12.0), next(-12.0, 12.0), next(-15.0, 15.0), next(-15.0, 15.0), next(0.0, 6.0)];
        t.push_str(&format!("{:?},{:?},{:?},{:?},{:?}\n", v[0], v[1], v[2], v[3], v[4]));
    }
    t
}

fn main() {
    let quick = !std::env::args().any(|a| a == "--bench");
    let text = input(POSES);
    let path = Path::new("bench.csv");
    let rounds = if quick { 1 } else { ROUNDS };
    let mut best = [f64::INFINITY; 4];
    for _ in 0..rounds {
        let t0 = Instant::now();
        let poses = parse_poses(black_box(&text), path).unwrap_or_default();
        let t1 = Instant::now();
        let evals = evaluate(&poses);
        let t2 = Instant::now();
        let out = to_csv(&poses, &evals);
        let t3 = Instant::now();
        black_box(out.len());
        assert_eq!(poses.len(), POSES, "every row parsed");
        let times = [(t1 - t0).as_secs_f64(), (t2 - t1).as_secs_f64(), (t3 - t2).as_secs_f64(), (t3 - t0).as_secs_f64()];
        for (b, t) in best.iter_mut().zip(times) {
            *b = b.min(t);
        }
    }
    println!(
        "needle eval --poses, {POSES} poses, best of {rounds}: parse {:.1} ms, evaluate {:.1} ms, format {:.1} ms, total {:.1} ms = {:.2} million poses/s (goal: 100,000 in < 1 s)",
        best[0] * 1e3,
        best[1] * 1e3,
        best[2] * 1e3,
        best[3] * 1e3,
        POSES as f64 / best[3] / 1e6
    );
    // the streaming path on 1,000,000 poses, from a file to a sink
    const STREAMED: usize = 1_000_000;
    let dir = std::env::temp_dir().join(format!("needle-bench-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap_or_default();
    let file = dir.join("poses.csv");
    std::fs::write(&file, input(STREAMED)).unwrap_or_default();
    let mut streamed = f64::INFINITY;
    for _ in 0..rounds {
        let t0 = Instant::now();
        let mut sink = std::io::sink();
        let rows = eval_stream::stream(&file, Some(&mut sink)).unwrap_or_default();
        streamed = streamed.min(t0.elapsed().as_secs_f64());
        assert_eq!(rows, STREAMED, "every row streamed");
    }
    let _ = std::fs::remove_dir_all(&dir);
    println!(
        "needle eval --poses streamed (CSV), {STREAMED} poses from a file, best of {rounds}: {:.1} ms = {:.2} million poses/s (goal: 1,000,000 in <= 1 s); per pose {:.2}x the in-memory path's speed",
        streamed * 1e3,
        STREAMED as f64 / streamed / 1e6,
        (best[3] / POSES as f64) / (streamed / STREAMED as f64)
    );
}
