//! Issue 67, item 4: the FE side reads a set once too. `needle fe status` and `needle fe
//! run` start from the campaign's plan (`needle_fe::campaign::plan`), which reads the
//! campaign spec and the run's manifest once each and decides what is up to date without
//! touching a file. Alone in its test binary (as `set_reads`): the count is per process.
use needle_fe::campaign::{plan, RunOptions};
use needle_set::set_folder::spec_and_manifest_reads;

#[test]
fn the_plan_reads_the_spec_and_the_manifest_once() {
    let set = needle_stdx::workspace_root().join("coeffs/default");
    let before = spec_and_manifest_reads();
    let p = plan(&RunOptions::new(set.clone())).unwrap_or_else(|e| panic!("plan of {}: {e:#}", set.display()));
    assert!(!p.reports.is_empty(), "the plan has poses");
    assert_eq!(spec_and_manifest_reads() - before, 2, "the plan reads the spec and the manifest once each");
    // the count sees a read: a second plan is two more
    plan(&RunOptions::new(set.clone())).unwrap_or_else(|e| panic!("plan: {e:#}"));
    assert_eq!(spec_and_manifest_reads() - before, 4);
}
