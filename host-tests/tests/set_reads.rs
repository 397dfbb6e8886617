//! Issue 37: a set is opened once. What `needle fit`, `needle validate`, `needle plot` and
//! `needle explore` do below the CLI, on one [`SetFolder`], reads the campaign spec and the
//! manifest of the FE runs once each: when the folder is opened, never again (the
//! fitter's runs are checked against that one copy of the manifest). Alone in its test
//! binary: the count is per process.
mod fit_synthetic;

use needle_set::set_folder::{spec_and_manifest_reads, SetFolder};

#[test]
fn the_commands_read_the_spec_and_the_manifest_once() {
    let (dir, out) = fit_synthetic::fitted();
    std::fs::write(dir.path().join(needle_fit::MODEL_FILE), &out.model_toml).expect("write model.toml");
    let before = spec_and_manifest_reads();
    let set = SetFolder::open(dir.path()).unwrap_or_else(|e| panic!("{e:#}"));
    assert_eq!(spec_and_manifest_reads() - before, 2, "opening reads the spec and the manifest");
    let fitted = needle_fit::fit_set(&set).unwrap_or_else(|e| panic!("fit: {e:#}"));
    assert_eq!(fitted.model_toml, out.model_toml, "the same fit as from the folder's path");
    needle_fit::coupled_report::measure(&set).unwrap_or_else(|e| panic!("coupled report: {e:#}"));
    let report = needle_fit::validate::validate(&set, needle_contract::DEGREE).unwrap_or_else(|e| panic!("validate: {e:#}"));
    assert!(!report.runs.is_empty(), "validate compared runs");
    let figures = needle_plot::render_set(&set).unwrap_or_else(|e| panic!("plot: {e:#}"));
    assert!(!figures.is_empty(), "plot drew figures");
    let json = needle_explore::set_json::set_json(&set).unwrap_or_else(|e| panic!("explore: {e:#}"));
    assert!(json["runs"].as_array().is_some_and(|r| !r.is_empty()), "set.json has runs");
    assert_eq!(spec_and_manifest_reads() - before, 2, "fit, validate, plot and explore read neither file again");
    // the count sees a read: opening again is two more
    SetFolder::open(dir.path()).unwrap_or_else(|e| panic!("{e:#}"));
    assert_eq!(spec_and_manifest_reads() - before, 4);
}
