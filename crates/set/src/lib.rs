//! A coefficient set as fit, plot, explore and eval read it, knowing no engine: the
//! campaign spec (`spec/`, one module per section of campaign.toml, and the run hash),
//! the set folder opened once (`set_folder::SetFolder`), the manifest of the FE runs
//! (`manifest`), the FE result CSV format (`results`, `results_error`), the partial
//! records of poses that were not solved (`partial`) with the failure classes an engine
//! records (`failures`), the wrench's mirror (`wrench`), the input generators' versions
//! in the run hash (`versions`), and the count of spec and manifest reads
//! (`read_count`).
//!
//! **Boundary**: the set knows no engine. It holds the engines' *settings* as data
//! (`[solver]`, `[solver.febio]`: they are part of every run's hash, so results of two
//! engines or settings never mix) but no code that runs an engine, writes its input or
//! parses its output: that is `needle-fe` (FEBio, CalculiX, SLURM, the campaign runner,
//! the verification runs), which depends on this crate, never the other way round
//! (`host-tests/tests/crate_graph.rs`).
#![forbid(unsafe_code)]

pub mod failures;
pub mod manifest;
pub mod partial;
pub mod read_count;
pub mod results;
pub mod results_error;
pub mod set_folder;
pub mod spec;
pub mod versions;
pub mod wrench;
