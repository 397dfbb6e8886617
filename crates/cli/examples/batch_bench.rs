//! Benchmark of the batch path (issue 38, item 6): `needle eval --poses FILE --out F`
//! (CSV to CSV, streaming) side by side with the single-pose path (the library's
//! `wrench`, one call per pose, the poses already in memory), on the same random poses.
//!
//! ```text
//! cargo run --release -p needle-cli --example batch_bench -- [--poses N] [--repeat R]
//! ```
//!
//! Writes N poses (default 1,000,000; ChaCha8 with a fixed seed, uniform over the
//! domain) to `target/batch-bench/poses.csv`, then runs each path R times (default 5),
//! each run in a child process of its own (this program, `--run batch|single`) that
//! reports its wall time, its CPU time and its peak memory. Per path it prints the
//! median and the range; the instruction counts per pose come from callgrind
//! (`valgrind --tool=callgrind`, counting every thread) as differences of two runs, so
//! that start-up, the set's loading and the single path's reading of the file cancel.
//! The last line says whether the batch path's median wall time meets the goal
//! (1,000,000 poses in <= 1 s). Time is wall time on this machine, whatever else it runs:
//! the instruction counts are the repeatable figures.

use anyhow::{bail, Context, Result};
use needle_contract::{DEPTH_MAX_MM, HALF_RANGES};
use needle_haptics::wrench;
use rand::{Rng, SeedableRng};
use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

/// The goal of issue 38, item 6: seconds of wall time for 1,000,000 poses.
const GOAL_S_PER_MILLION: f64 = 1.0;

/// Poses of the smaller callgrind run (the larger one has twice as many): more than the
/// two chunks of records the batch path allocates once (2 x `CHUNK_ROWS`), so that the
/// difference is the steady state of a long file.
const CALLGRIND_POSES: usize = 2 * needle_cli::commands::eval::stream::CHUNK_ROWS + 10_000;

/// What one child run measured.
struct Measured {
    wall_s: f64,
    cpu_s: f64,
    peak_kib: u64,
}

fn main() -> Result<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let opt = |name: &str| args.iter().position(|a| a == name).and_then(|i| args.get(i + 1)).cloned();
    if let Some(mode) = opt("--run") {
        let input = PathBuf::from(opt("--input").context("--run needs --input FILE")?);
        let passes: usize = opt("--passes").map_or(Ok(1), |v| v.parse()).context("--passes: not a count")?;
        return child(&mode, &input, opt("--output").map(PathBuf::from).as_deref(), passes);
    }
    let n: usize = opt("--poses").map_or(Ok(1_000_000), |v| v.parse()).context("--poses: not a count")?;
    let repeat: usize = opt("--repeat").map_or(Ok(5), |v| v.parse()).context("--repeat: not a count")?;
    if n == 0 || repeat == 0 {
        bail!("--poses and --repeat must be at least 1");
    }
    let dir = PathBuf::from("target/batch-bench");
    std::fs::create_dir_all(&dir).with_context(|| format!("{}: cannot create", dir.display()))?;
    let input = dir.join("poses.csv");
    write_poses(&input, n)?;
    let output = dir.join("wrench.csv");
    println!("batch bench: {n} poses (uniform over the domain), {repeat} runs per path, cores: {}", cores());
    let batch = runs("batch", &input, Some(&output), repeat)?;
    let single = runs("single", &input, None, repeat)?;
    let (ib, is) = (instructions_per_pose("batch", &dir)?, instructions_per_pose("single", &dir)?);
    println!("{:<36} {:>12} {:>22} {:>10} {:>12} {:>14}", "path", "wall s", "wall range s", "cpu s", "peak MiB", "instr/pose");
    for (name, m, i) in [("batch: needle eval --poses (CSV->CSV)", &batch, ib), ("single: wrench() per pose, in memory", &single, is)] {
        let wall: Vec<f64> = m.iter().map(|r| r.wall_s).collect();
        let cpu: Vec<f64> = m.iter().map(|r| r.cpu_s).collect();
        let peak = m.iter().map(|r| r.peak_kib).max().unwrap_or(0) as f64 / 1024.0;
        let (lo, hi) = (wall.iter().copied().fold(f64::INFINITY, f64::min), wall.iter().copied().fold(0.0, f64::max));
        println!("{name:<36} {:>12.3} {:>22} {:>10.3} {peak:>12.1} {i:>14.0}", median(&wall), format!("{lo:.3} .. {hi:.3}"), median(&cpu));
    }
    let bw = median(&batch.iter().map(|r| r.wall_s).collect::<Vec<_>>());
    let sw = median(&single.iter().map(|r| r.wall_s).collect::<Vec<_>>());
    println!("ratios batch / single: wall {:.2}, instructions per pose {:.2}", bw / sw, ib / is);
    let per_million = bw * 1e6 / n as f64;
    let met = if per_million <= GOAL_S_PER_MILLION { "met" } else { "MISSED" };
    println!("goal <= {GOAL_S_PER_MILLION} s per 1,000,000 poses CSV to CSV: {per_million:.3} s per 1,000,000 (median wall): {met}");
    Ok(())
}

/// The run of one path in this process: the poses read, then the measured part (the
/// single path `passes` times over the poses).
fn child(mode: &str, input: &Path, output: Option<&Path>, passes: usize) -> Result<()> {
    let (wall, cpu0) = match mode {
        "batch" => {
            let out = output.context("--run batch needs --output FILE")?;
            let (t, c) = (Instant::now(), cpu_s()?);
            needle_cli::commands::eval::stream::eval_csv(input, Some(out))?;
            (t.elapsed().as_secs_f64(), c)
        }
        "single" => {
            let text = std::fs::read_to_string(input).with_context(|| format!("{}: cannot read", input.display()))?;
            let poses = needle_cli::commands::eval::batch::parse_poses(&text, input)?;
            let (t, c) = (Instant::now(), cpu_s()?);
            let mut sum = 0.0f32;
            for _ in 0..passes {
                for p in &poses {
                    sum += wrench(std::hint::black_box(p)).wrench.fy_n;
                }
            }
            std::hint::black_box(sum);
            (t.elapsed().as_secs_f64(), c)
        }
        _ => bail!("--run {mode}: not batch or single"),
    };
    let cpu = cpu_s()? - cpu0;
    println!("{wall} {cpu} {}", peak_kib()?);
    Ok(())
}

/// `repeat` child runs of `mode`.
fn runs(mode: &str, input: &Path, output: Option<&Path>, repeat: usize) -> Result<Vec<Measured>> {
    (0..repeat)
        .map(|_| {
            let mut cmd = Command::new(std::env::current_exe()?);
            cmd.args(["--run", mode, "--input"]).arg(input);
            if let Some(o) = output {
                cmd.arg("--output").arg(o);
            }
            let text = run(&mut cmd)?;
            let v: Vec<f64> = text.split_whitespace().map(str::parse).collect::<Result<_, _>>().context("child's figures")?;
            match v.as_slice() {
                [wall_s, cpu_s, peak] => Ok(Measured { wall_s: *wall_s, cpu_s: *cpu_s, peak_kib: *peak as u64 }),
                _ => bail!("child printed {text:?}, not three numbers"),
            }
        })
        .collect()
}

/// Instructions per pose of `mode` under callgrind: for the batch path the count on 2n
/// poses minus the count on n poses, for the single path the count of two passes over n
/// poses minus that of one (the file's parse cancels), over n.
fn instructions_per_pose(mode: &str, dir: &Path) -> Result<f64> {
    let mut counts = [0f64; 2];
    for (k, count) in counts.iter_mut().enumerate() {
        let (n, passes) = if mode == "batch" { (CALLGRIND_POSES << k, 1) } else { (CALLGRIND_POSES, 1 + k) };
        let input = dir.join(format!("poses-{n}.csv"));
        write_poses(&input, n)?;
        let mut cmd = Command::new("valgrind");
        cmd.args(["--tool=callgrind", "--callgrind-out-file=/dev/null"]).arg(std::env::current_exe()?);
        cmd.args(["--run", mode, "--passes", &passes.to_string(), "--input"]).arg(&input);
        cmd.arg("--output").arg(dir.join("callgrind-out.csv"));
        let out = cmd.output().context("valgrind (apt-get install valgrind) could not be started")?;
        let log = String::from_utf8_lossy(&out.stderr);
        if !out.status.success() {
            bail!("valgrind --tool=callgrind {mode}: {}\n{log}", out.status);
        }
        // "==123== Collected : 1234567" (callgrind's summary, every thread)
        *count = log
            .lines()
            .find_map(|l| l.split_once("Collected :").map(|(_, v)| v.trim().replace(',', "")))
            .and_then(|v| v.parse().ok())
            .with_context(|| format!("no \"Collected :\" line in callgrind's output:\n{log}"))?;
    }
    Ok((counts[1] - counts[0]) / CALLGRIND_POSES as f64)
}

/// Runs `cmd`; its standard output, or its failure with its standard error.
fn run(cmd: &mut Command) -> Result<String> {
    let out = cmd.output().with_context(|| format!("{cmd:?} could not be started"))?;
    if !out.status.success() {
        bail!("{cmd:?}: {}\n{}", out.status, String::from_utf8_lossy(&out.stderr));
    }
    Ok(String::from_utf8_lossy(&out.stdout).trim().to_string())
}

/// `n` random poses as a pose file (mm, degrees; 5 decimals).
fn write_poses(path: &Path, n: usize) -> Result<()> {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(0x6261_7463_6800_0001);
    let mut w = std::io::BufWriter::new(std::fs::File::create(path).with_context(|| format!("{}: cannot create", path.display()))?);
    writeln!(w, "x_mm,z_mm,theta_x_deg,theta_z_deg,depth_mm")?;
    for _ in 0..n {
        let [x, z, tx, tz] = HALF_RANGES.map(|h| rng.gen_range(-h..=h));
        let d = rng.gen_range(0.0..=DEPTH_MAX_MM);
        writeln!(w, "{x:.5},{z:.5},{tx:.5},{tz:.5},{d:.5}")?;
    }
    w.flush().with_context(|| format!("{}: cannot write", path.display()))
}

/// CPU time of this process so far (user + system, seconds), from /proc/self/stat.
fn cpu_s() -> Result<f64> {
    let stat = std::fs::read_to_string("/proc/self/stat").context("/proc/self/stat")?;
    // fields after the command name (which may hold spaces): utime is the 14th field
    let rest = stat.rsplit_once(')').map(|(_, r)| r).context("/proc/self/stat: no ')'")?;
    let f: Vec<&str> = rest.split_whitespace().collect();
    let ticks = |i: usize| f.get(i).and_then(|v| v.parse::<f64>().ok()).context("/proc/self/stat: no utime/stime");
    // SAFETY: sysconf has no preconditions
    let hz = unsafe { libc::sysconf(libc::_SC_CLK_TCK) } as f64;
    Ok((ticks(11)? + ticks(12)?) / hz.max(1.0))
}

/// Peak resident memory of this process (KiB), VmHWM of /proc/self/status.
fn peak_kib() -> Result<u64> {
    let status = std::fs::read_to_string("/proc/self/status").context("/proc/self/status")?;
    status
        .lines()
        .find_map(|l| l.strip_prefix("VmHWM:"))
        .and_then(|v| v.trim().trim_end_matches("kB").trim().parse().ok())
        .context("/proc/self/status: no VmHWM")
}

fn cores() -> usize {
    std::thread::available_parallelism().map_or(1, std::num::NonZeroUsize::get)
}

fn median(v: &[f64]) -> f64 {
    let mut s = v.to_vec();
    s.sort_by(f64::total_cmp);
    s.get(s.len() / 2).copied().unwrap_or(f64::NAN)
}
