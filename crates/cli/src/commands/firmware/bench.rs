//! `needle firmware bench`: instructions per wrench and stack per core, f32 and fixed
//! point, with the goals.
use super::goals::{Goals, INSERTION_FIXED_M0_INSTRUCTIONS, INSERTION_STACK_BYTES, QLV_M4F_EXTRA_INSTRUCTIONS};
use super::{banner, goal, FirmwareArgs};
use needle_firmware_host::{self as firmware, bench};
use std::process::ExitCode;

/// `needle firmware bench`.
pub fn run(a: &FirmwareArgs) -> anyhow::Result<ExitCode> {
    let set = firmware::fitted_set(&a.set())?;
    let cores = firmware::cores(&a.cores)?;
    let goals = Goals::of(&set)?;
    let figures = cores.iter().map(|c| bench::run(c, &set)).collect::<anyhow::Result<Vec<_>>>()?;
    banner("needle firmware bench", &set)?;
    println!("model form: {} (its goals below)", goals.form);
    println!("QEMU -icount shift=0, SysTick; {} calls per pose minus an empty loop; stack painted\n", 256);
    print!("{}", bench::table(&figures));
    println!();
    for f in &figures {
        print_core_goals(f, &goals);
    }
    Ok(ExitCode::SUCCESS)
}

/// The goal lines of one core: the evaluators' instructions and stack, the insertion's,
/// the stiffness and fixed-point ratios.
fn print_core_goals(f: &bench::CoreFigures, goals: &Goals) {
    let Some(t) = f.pose("typical", "f32") else { return };
    // the evaluators' stack goal (512 B); the insertion step has its own (issue 41: 1 KiB)
    let is_insertion = |e: &str| e.starts_with("insertion") || e.starts_with("fixed-insertion");
    let max_stack = f.poses.iter().filter(|p| !is_insertion(&p.evaluator)).map(|p| p.stack_bytes).max().unwrap_or(0);
    let insertion_stack = f.poses.iter().filter(|p| is_insertion(&p.evaluator)).map(|p| p.stack_bytes).max();
    let instr_goal = if f.core.name == "m4f" {
        format!("; <= {} instructions: {}", goals.m4f_f32_instructions, goal(t.instructions <= goals.m4f_f32_instructions))
    } else {
        String::new()
    };
    println!(
        "goals {}: {:.1} instructions per wrench (typical pose){instr_goal}; stack {max_stack} B <= 512 B: {}",
        f.core.core,
        t.instructions,
        goal(max_stack <= 512)
    );
    print_insertion_goals(f, insertion_stack);
    if let Some(k) = f.pose("typical", "f32+k") {
        let ratio = k.instructions / t.instructions;
        println!(
            "stiffness {}: {:.1} instructions per wrench and stiffness (typical pose), {ratio:.2}x the wrench alone; <= 1.6x: {}",
            f.core.core,
            k.instructions,
            goal(ratio <= 1.6)
        );
    }
    if let Some(q) = f.pose("typical", "fixed") {
        let m0_goal = if f.core.name == "m0" {
            format!("; <= {} instructions on the M0: {}", goals.m0_fixed_instructions, goal(q.instructions <= goals.m0_fixed_instructions))
        } else {
            String::new()
        };
        println!(
            "fixed point {}: {:.1} instructions per wrench (typical pose), {:.2}x the f32 evaluator's speed{m0_goal}",
            f.core.core,
            q.instructions,
            t.instructions / q.instructions
        );
        if let Some(qk) = f.pose("typical", "fixed+k") {
            println!(
                "fixed-point stiffness {}: {:.1} instructions per wrench and stiffness (typical pose), {:.2}x the fixed-point wrench alone",
                f.core.core,
                qk.instructions,
                qk.instructions / q.instructions
            );
        }
    }
}

/// The insertion's goal lines of one core: the stack of a step, the fixed-point step's
/// instructions (and the M0 goal).
fn print_insertion_goals(f: &bench::CoreFigures, insertion_stack: Option<u64>) {
    if let Some(b) = insertion_stack {
        println!("insertion {}: stack of one step {b} B <= {INSERTION_STACK_BYTES} B: {}", f.core.core, goal(b <= INSERTION_STACK_BYTES));
    }
    let fixed_steps: Vec<f64> = f.poses.iter().filter(|p| p.evaluator == "fixed-insertion").map(|p| p.instructions).collect();
    if let Some(worst) = fixed_steps.iter().copied().reduce(f64::max) {
        let m0_goal = if f.core.name == "m0" {
            format!("; <= {INSERTION_FIXED_M0_INSTRUCTIONS} on the M0: {}", goal(worst <= INSERTION_FIXED_M0_INSTRUCTIONS))
        } else {
            String::new()
        };
        let insertion_f32 = f.poses.iter().filter(|p| p.evaluator == "insertion").map(|p| p.instructions).reduce(f64::max);
        let ratio = insertion_f32.map(|t| format!(", {:.2}x the f32 insertion's speed", t / worst)).unwrap_or_default();
        println!(
            "fixed-point insertion {}: {worst:.1} instructions per step (most of every stack's surface and deep tick){ratio}{m0_goal}",
            f.core.core
        );
    }
    print_filter_cost(f);
}

/// The viscoelastic filter's cost: the most, over every stack's surface and deep tick, of
/// the step with three Prony terms on every layer (`+qlv`) less the step without.
fn print_filter_cost(f: &bench::CoreFigures) {
    for (plain, filtered) in [("insertion", "insertion+qlv"), ("fixed-insertion", "fixed-insertion+qlv")] {
        let extra = f
            .poses
            .iter()
            .filter(|p| p.evaluator == filtered)
            .filter_map(|q| f.pose(&q.pose, plain).map(|p| q.instructions - p.instructions))
            .reduce(f64::max);
        let Some(extra) = extra else { continue };
        let m4f_goal = if f.core.name == "m4f" && plain == "insertion" {
            format!("; <= {QLV_M4F_EXTRA_INSTRUCTIONS} on the M4F: {}", goal(extra <= QLV_M4F_EXTRA_INSTRUCTIONS))
        } else {
            String::new()
        };
        println!(
            "viscoelastic filter {} ({plain}): {extra:.1} extra instructions per step at most (3 Prony terms, 6 components){m4f_goal}",
            f.core.core
        );
    }
}
