//! `needle fe verify --qlv`: the library's QLV filter (`needle_haptics::viscoelastic`,
//! f32, one tick of `InsertionConfig::DEFAULT_1KHZ`) run on the elastic FE wrench along
//! each ramp-and-hold run's depth-time path, against FEBio's viscoelastic solution
//! (`needle_fe::visco::qlv`: pairing, scores, bounds). The filter is the firmware's own
//! code; this module only feeds it and samples its output at the FE's must points;
//! [`filtered`] steps the filter, [`figure`] draws the comparison.
pub mod figure;
pub mod filtered;

use needle_fe::visco::qlv::{self, QlvCase, QlvOptions, QlvRun};
use needle_set::set_folder::SetFolder;

/// Run the check on the set `set` (opened once by the caller; `opts.set_dir` is its folder): solve (when `opts.solve`) and read the runs, filter, score, print each
/// run's line, write `[[qlv]]` of `<set>/fe/verify.toml`. Returns whether every run is
/// within the bounds (a missing run is a miss).
///
/// # Errors
/// As [`qlv::cases`], or verify.toml cannot be written.
pub fn check(set: &SetFolder, opts: &QlvOptions) -> anyhow::Result<bool> {
    let c = set.campaign();
    let mut runs: Vec<QlvRun> = Vec::new();
    let mut missing: Vec<String> = Vec::new();
    let mut compared: Vec<QlvCase> = Vec::new();
    for case in qlv::cases(set, opts)? {
        match case {
            Ok(case) => {
                let r = qlv::score(&case, &filtered::filtered(&case)?, filtered::tick_s(), c.needle.reference_from_tip_mm)?;
                println!("{r}");
                runs.push(r);
                compared.push(case);
            }
            Err((run, why)) => {
                println!("qlv {run}: no comparison: {why}");
                missing.push(format!("{run}: {why}"));
            }
        }
    }
    let report = qlv::report(runs, missing);
    report.summary().iter().for_each(|l| println!("{l}"));
    needle_fe::verify::write_table(&opts.set_dir, "qlv", &report)?;
    if !compared.is_empty() {
        let svg = figure::svg(&compared)?;
        let path = opts.set_dir.join("figures").join(figure::FILE);
        needle_stdx::fs::write_atomic(&path, svg.as_bytes())?;
        println!("wrote {}", path.display());
    }
    Ok(report.ok())
}
