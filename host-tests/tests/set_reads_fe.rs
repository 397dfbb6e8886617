//! Issue 67, item 4: the FE side reads a set once too. The FE commands open the set's folder
//! once ([`SetFolder`]) and pass the handle down: the campaign's plan, each variant of
//! `--visco` and `--family`, the checks of `needle fe verify` and `needle fixed-error` read
//! the campaign spec no second time. (Each campaign run reads its output folder's
//! manifest again: the campaign is the manifest's writer and another process may have
//! written it since; docs/architecture.md, section 6.) Alone in its test binary (as
//! `set_reads`): the count is per process, so one test runs the commands in turn.
use clap::Parser;
use needle_cli::commands::fe::FeCommand;
use needle_fe::campaign::{plan, RunOptions};
use needle_set::set_folder::{spec_and_manifest_reads, spec_reads, SetFolder};
use std::path::Path;

/// `needle fe ...` as the binary parses it.
#[derive(Parser)]
struct Fe {
    #[command(subcommand)]
    command: FeCommand,
}

/// Runs `needle fe <args>` in this process; returns the campaign specs it read.
fn fe_spec_reads(args: &[&str]) -> usize {
    let before = spec_reads();
    let fe = Fe::try_parse_from(std::iter::once("fe").chain(args.iter().copied())).unwrap_or_else(|e| panic!("{args:?}: {e}"));
    needle_cli::commands::fe::run(fe.command).unwrap_or_else(|e| panic!("needle fe {}: {e:#}", args.join(" ")));
    spec_reads() - before
}

/// `from` copied into `to`, folders included.
fn copy_dir(from: &Path, to: &Path) {
    std::fs::create_dir_all(to).unwrap_or_else(|e| panic!("{}: {e}", to.display()));
    for e in std::fs::read_dir(from).unwrap_or_else(|e| panic!("{}: {e}", from.display())).flatten() {
        let (src, dst) = (e.path(), to.join(e.file_name()));
        if src.is_dir() {
            copy_dir(&src, &dst);
        } else {
            std::fs::copy(&src, &dst).unwrap_or_else(|e| panic!("{}: {e}", src.display()));
        }
    }
}

#[test]
fn the_fe_commands_read_the_spec_once() {
    // this crate's folder, not needle_stdx::workspace_root(): the set of this source tree
    let default = Path::new(env!("CARGO_MANIFEST_DIR")).join("../coeffs/default");

    // the plan of `needle fe status` and `needle fe run`: the spec as opened, the manifest once
    let before = spec_and_manifest_reads();
    let set = SetFolder::open(&default).unwrap_or_else(|e| panic!("{}: {e:#}", default.display()));
    assert_eq!(spec_and_manifest_reads() - before, 2, "opening reads the spec and the manifest");
    let p = plan(&set, &RunOptions::new(default.clone())).unwrap_or_else(|e| panic!("plan of {}: {e:#}", default.display()));
    assert!(!p.reports.is_empty(), "the plan has poses");
    assert_eq!(spec_and_manifest_reads() - before, 3, "the plan reads the output folder's manifest, not the spec");
    // the count sees a read: opening again is one more spec
    let spec_before = spec_reads();
    SetFolder::open(&default).unwrap_or_else(|e| panic!("{e:#}"));
    assert_eq!(spec_reads() - spec_before, 1);

    // `needle fe run --visco` and `--family`: every variant (one per speed, one per member
    // run) planned from the one spec, as `fe run` plans each before it solves it
    let set_arg = default.to_str().expect("a UTF-8 path");
    for flag in ["--visco", "--family"] {
        let spec_before = spec_reads();
        let set = SetFolder::open(&default).unwrap_or_else(|e| panic!("{e:#}"));
        let opts = RunOptions { visco: flag == "--visco", family: flag == "--family", ..RunOptions::new(default.clone()) };
        let variants = needle_cli::commands::fe::spec::variants(&set, opts).unwrap_or_else(|e| panic!("{flag}: {e:#}"));
        assert!(variants.len() > 1, "{flag}: several campaign runs ({})", variants.len());
        for o in &variants {
            plan(&set, o).unwrap_or_else(|e| panic!("{flag}: plan: {e:#}"));
        }
        assert_eq!(spec_reads() - spec_before, 1, "fe run {flag}: {} variants planned from one read of the spec", variants.len());
        // the same through the command
        assert_eq!(fe_spec_reads(&["status", "--set", set_arg, flag]), 1, "needle fe status {flag}");
    }

    // `needle fe verify`: the checks that read the results there (no solver), on a copy
    // (verify writes fe/verify.toml and a figure)
    let d = tempfile::tempdir().expect("tempdir");
    std::fs::copy(default.join("campaign.toml"), d.path().join("campaign.toml")).expect("copy campaign.toml");
    copy_dir(&default.join("fe"), &d.path().join("fe"));
    let copy = d.path().to_str().expect("a UTF-8 path");
    assert_eq!(fe_spec_reads(&["verify", "--set", copy, "--mirror", "--smooth"]), 1, "needle fe verify --mirror --smooth");
    assert_eq!(fe_spec_reads(&["verify", "--set", copy, "--qlv", "--no-solve"]), 1, "needle fe verify --qlv --no-solve");
    assert!(d.path().join("fe/verify.toml").is_file(), "verify wrote its table");

    // `needle fixed-error` on the set compiled into this build
    let before = spec_reads();
    let a = needle_cli::commands::fixed_error::FixedErrorArgs { set: default.clone(), grid: 2, random: 0 };
    needle_cli::commands::fixed_error::run(a).unwrap_or_else(|e| panic!("fixed-error: {e:#}"));
    assert_eq!(spec_reads() - before, 1, "needle fixed-error");
}
