//! `needle fixed-error`: the fixed-point evaluator's measured error against f64, beside
//! the bound derived at code generation.
pub mod measure;

use crate::compiled_set::check_compiled_set;
use clap::Args;
use measure::{ErrorStats, GOAL_PCT};
use needle_contract::COMPONENT_COUNT;
use needle_set::set_folder::SetFolder;
use rand::{RngCore, SeedableRng};
use std::path::PathBuf;
use std::process::ExitCode;

/// Arguments of `needle fixed-error`.
#[derive(Args, Debug)]
pub struct FixedErrorArgs {
    /// The coefficient set folder; must be the set compiled into this build.
    #[arg(long, value_name = "DIR")]
    pub set: PathBuf,
    /// Grid points per input (edges included): N^5 poses; 2 ..= 41 (41^5 = 116 million
    /// poses, minutes of work).
    #[arg(long, default_value_t = 11, allow_negative_numbers = true, value_parser = clap::value_parser!(u64).range(2..=41))]
    pub grid: u64,
    /// Random poses (ChaCha8, fixed seed) uniform over the domain, after the grid; at
    /// most 100 million.
    #[arg(long, default_value_t = 100_000, allow_negative_numbers = true, value_parser = clap::value_parser!(u64).range(0..=100_000_000))]
    pub random: u64,
}

/// `needle fixed-error --set DIR`: evaluate the library's fixed-point and the fitter's
/// f64 model on a grid and random poses; print the max error per component and the
/// generated bound. Exit code 1 when an error exceeds its bound or a bound misses the
/// goal (0.1 % of peak |Fy|, moments times the lever arm).
///
/// # Errors
/// `DIR` is not the compiled-in set, or its model.toml / campaign.toml is unreadable.
pub fn run(a: FixedErrorArgs) -> anyhow::Result<ExitCode> {
    check_compiled_set(&a.set)?;

    let set = SetFolder::open(&a.set)?;
    let (model, lever) = measure::load(&set)?;
    let mut stats = ErrorStats::default();
    stats.add_grid(&model, usize::try_from(a.grid)?);
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(0x6669_7865_6400_0001);
    let max = [12i64 << 16, 12 << 16, 15 << 16, 15 << 16, 6 << 16];
    for _ in 0..a.random {
        let pose: [i32; 5] = std::array::from_fn(|i| {
            let lo = if i < 4 { -max[i] } else { 0 };
            (lo + (rng.next_u64() % (max[i] - lo + 1) as u64) as i64) as i32
        });
        stats.add(&model, pose);
    }
    println!("needle fixed-error: set {} ({}^5 grid + {} random poses)", a.set.display(), a.grid, a.random);
    print!("{}", measure::table(&stats, lever));
    let within = (0..COMPONENT_COUNT).all(|c| stats.max_error[c] <= measure::bound(c));
    let goal = (0..COMPONENT_COUNT).all(|c| 100.0 * measure::bound(c) / measure::scale(&stats, c, lever) <= GOAL_PCT);
    println!("every measured error within its bound: {}", if within { "yes" } else { "NO" });
    Ok(if within && goal { ExitCode::SUCCESS } else { ExitCode::from(1) })
}
