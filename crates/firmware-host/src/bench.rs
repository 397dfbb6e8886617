//! The `bench` firmware: instructions per wrench and stack, per core (QEMU `-icount
//! shift=0`, SysTick; see examples/bench.rs for the method).
use super::{build, qemu, Core};
use anyhow::{bail, Context};
use std::path::Path;
use std::time::Duration;

/// One timed pose.
#[derive(Debug, Clone, PartialEq)]
pub struct PoseFigures {
    /// The firmware's name of the pose (`typical`, `positive`, `saturated`, `nan-input`).
    pub pose: String,
    /// The evaluator timed: `f32`, `f32+k` (wrench and stiffness), `fixed`, `fixed+k`,
    /// `insertion` or `fixed-insertion` (one insertion step).
    pub evaluator: String,
    /// Executed instructions per `wrench` call (call, return and result store included).
    pub instructions: f64,
    /// Stack bytes used by one call, from the caller's stack pointer.
    pub stack_bytes: u64,
    /// The evaluation's status bits.
    pub status: u8,
}

/// The figures of one core.
#[derive(Debug, Clone)]
pub struct CoreFigures {
    /// The core.
    pub core: Core,
    /// Instructions of the calibration loop and the SysTick ticks they took.
    pub calibration: (u64, u64),
    /// One entry per pose, in the firmware's order.
    pub poses: Vec<PoseFigures>,
}

impl CoreFigures {
    /// The figures of the pose named `name` with the evaluator `evaluator` (`f32`, `f32+k`, `fixed`).
    #[must_use]
    pub fn pose(&self, name: &str, evaluator: &str) -> Option<&PoseFigures> {
        self.poses.iter().find(|p| p.pose == name && p.evaluator == evaluator)
    }
}

fn field<'a>(line: &'a str, key: &str) -> Option<&'a str> {
    line.split(' ').find_map(|w| w.strip_prefix(key)?.strip_prefix('='))
}

/// Parses the `bench` firmware's output.
///
/// # Errors
/// The output is incomplete or malformed, or the run was not under `-icount`
/// (`deterministic=no`).
pub fn parse(core: &Core, output: &str) -> anyhow::Result<CoreFigures> {
    let mut lines = output.lines();
    let head = lines.next().unwrap_or_default();
    if !head.starts_with("needle-bench target=") {
        bail!("not the bench firmware's output: {head:?}");
    }
    if field(head, "deterministic") != Some("yes") {
        bail!("the bench ran without QEMU -icount shift=0 (two equal loops took different SysTick ticks): {head:?}");
    }
    let num =
        |k: &str| -> anyhow::Result<u64> { field(head, k).and_then(|v| v.parse().ok()).with_context(|| format!("no {k} in {head:?}")) };
    let calibration = (num("calibration_instructions")?, num("calibration_ticks")?);
    let mut poses = Vec::new();
    let mut ended = false;
    for line in lines {
        if line == "needle-bench end" {
            ended = true;
            break;
        }
        let ctx = || format!("bench line {line:?}");
        let pose = field(line, "pose").with_context(ctx)?.to_string();
        let evaluator = field(line, "evaluator").with_context(ctx)?.to_string();
        let instructions: f64 = field(line, "instructions_per_wrench").and_then(|v| v.parse().ok()).with_context(ctx)?;
        let stack = field(line, "stack_bytes").with_context(ctx)?;
        if stack.starts_with(">=") {
            bail!("{}: the stack use of one wrench filled the whole painted window ({stack} bytes)", core.core);
        }
        let stack_bytes = stack.parse().ok().with_context(ctx)?;
        let status =
            field(line, "status").and_then(|s| s.strip_prefix("0x")).and_then(|s| u8::from_str_radix(s, 16).ok()).with_context(ctx)?;
        poses.push(PoseFigures { pose, evaluator, instructions, stack_bytes, status });
    }
    if !ended || poses.is_empty() {
        bail!("the bench output is incomplete:\n{output}");
    }
    Ok(CoreFigures { core: *core, calibration, poses })
}

/// Builds and runs the `bench` example for `core` with the set `set` (absolute path).
///
/// # Errors
/// Build or run failed, or the output is malformed.
pub fn run(core: &Core, set: &Path) -> anyhow::Result<CoreFigures> {
    run_with(core, set, build::Features::Viscoelastic)
}

/// [`run`] on the `bench` firmware built with the library's `features`.
///
/// # Errors
/// As [`run`].
pub fn run_with(core: &Core, set: &Path, features: build::Features) -> anyhow::Result<CoreFigures> {
    let elf = build::build_examples_with(core, &["bench"], set, features)?.remove(0);
    let run = qemu::run(core, &elf, true, Duration::from_secs(600))?;
    if !run.status.success() {
        bail!("bench firmware on {} exited with {}:\n{}{}", core.core, run.status, run.stdout, run.stderr);
    }
    parse(core, &run.stdout)
}

/// The figures as a table: one row per core and pose.
#[must_use]
pub fn table(figures: &[CoreFigures]) -> String {
    let mut s = format!(
        "{:<11} {:<22} {:<10} {:<6} {:>22} {:>12} {:>7}\n",
        "core", "target", "pose", "eval", "instructions/wrench", "stack bytes", "status"
    );
    for f in figures {
        for p in &f.poses {
            s.push_str(&format!(
                "{:<11} {:<22} {:<10} {:<6} {:>22.1} {:>12} {:>7}\n",
                f.core.core,
                f.core.target,
                p.pose,
                p.evaluator,
                p.instructions,
                p.stack_bytes,
                format!("{:#04x}", p.status)
            ));
        }
    }
    s
}
