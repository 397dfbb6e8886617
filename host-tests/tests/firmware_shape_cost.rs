//! Issue 64's cost goals for an insertion step with the `tissue-shape` feature (a layer's
//! material family member and its pre-puncture softening), from the `bench` firmware
//! built with it (`needle firmware bench`'s method: QEMU `-icount shift=0`, the stack
//! painted below the caller's): every stack of the build, the shaped one too, a step
//! deflecting the surface and one deep inside, f32 and fixed point:
//!
//! - the M4F's f32 step at the surface <= 1,100 instructions;
//! - the M0's fixed-point step <= 20,000 instructions;
//! - one step's stack <= 1 KiB on every core.
//!
//! The elastic steps (`insertion`, `fixed-insertion`: the bench's rows without Prony
//! terms, the family member and the softening kept). Nothing skips: a missing QEMU or
//! rustup target fails with a message.
use needle_firmware_host::build::Features;
use needle_firmware_host::{self as firmware, bench, CORES};

/// The cases that miss their goal, as measured (issue 64 stays open for them, the closing
/// note has the figures and what was tried): none. The last one, the M0's fixed-point step
/// deflecting the rig skin's surface, takes 16,147.9 instructions (goal 20,000; 20,114.0
/// before the products that cannot saturate took one widening multiply, the 64-bit
/// division became the M0's own; 22,244.1 before a member's law rows were computed once).
/// Not a tolerance: every case must meet its goal; a case listed here is still printed.
const MISSED: [(&str, &str, &str); 0] = [];

#[test]
fn a_shaped_insertion_step_within_its_cost_goals_on_every_core() {
    let set = firmware::fitted_set(&firmware::compiled_set()).unwrap_or_else(|e| panic!("{e:#}"));
    let stacks: Vec<&str> = needle_haptics::insertion::stacks::ALL.iter().filter(|s| Features::Shape.compiles(s)).map(|s| s.name).collect();
    let shaped = needle_haptics::insertion::stacks::ALL.iter().filter(|s| !Features::Viscoelastic.compiles(s)).count();
    assert!(shaped > 0, "no stack of the set needs tissue-shape");
    let mut missed = Vec::new();
    for core in &CORES {
        let figures = bench::run_with(core, &set, Features::Shape).unwrap_or_else(|e| panic!("{e:#}"));
        for stack in &stacks {
            for case in ["surface", "deep"] {
                let pose = format!("{stack}-{case}");
                for evaluator in ["insertion", "fixed-insertion"] {
                    let f = figures.pose(&pose, evaluator).unwrap_or_else(|| panic!("{}: no {pose} {evaluator} row", core.core));
                    println!("{} {pose} {evaluator}: {:.1} instructions, stack {} B", core.core, f.instructions, f.stack_bytes);
                    if f.stack_bytes > 1024 {
                        missed.push(format!("{} {pose} {evaluator}: stack {} B > 1 KiB", core.core, f.stack_bytes));
                    }
                    let goal = match (core.name, evaluator, case) {
                        ("m4f", "insertion", "surface") => Some(1100.0),
                        ("m0", "fixed-insertion", _) => Some(20_000.0),
                        _ => None,
                    };
                    let known = MISSED.contains(&(core.name, pose.as_str(), evaluator));
                    if let (Some(goal), true) = (goal.filter(|g| f.instructions > *g), known) {
                        println!("MISSED (issue 64, open): {} {pose} {evaluator}: {:.1} instructions > {goal}", core.core, f.instructions);
                    } else if let Some(goal) = goal.filter(|g| f.instructions > *g) {
                        missed.push(format!("{} {pose} {evaluator}: {:.1} instructions > {goal}", core.core, f.instructions));
                    }
                }
            }
        }
    }
    assert!(missed.is_empty(), "with tissue-shape:\n{}", missed.join("\n"));
}
