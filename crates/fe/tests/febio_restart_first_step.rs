//! A continuation's first time step on the real FEBio (issue: FEBio's first step after a
//! restart is `AutoTimeStep`'s, from the dump's own step, capped by the must-point curve;
//! `<step_size>` alone has no effect). The smoke mesh's centre pose in 10 load steps of
//! 0.6 mm runs to must point 3 (1.8 mm, its dump copied as soon as the rigid-body log has
//! that record: FEBio writes the dump before the log, `FEBioModel::DumpData`), then
//! restarts twice from that dump: with the restart input of `restart.rs` the first step is
//! 1/16 of a load step (1.8 -> 1.8375 mm); without its `<LoadData>` (the input before the
//! fix) it is the dump's step, a whole load step (1.8 -> 2.4 mm). Needs `febio4`
//! (`.ci/install-febio`); without it the test fails, it is not skipped. Takes ~10 s.

use needle_fe::febio::{self, feb, restart};
use std::path::Path;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

const FROM: u32 = 3;
const STEPS: u32 = 10;

fn febio_cmd(exe: &Path, dir: &Path, args: &[&str]) -> Command {
    let mut c = Command::new(exe);
    c.current_dir(dir)
        .arg("-nosplash")
        .args(args)
        .env("OMP_NUM_THREADS", "1")
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::null());
    c
}

/// Run the `.feb` in `dir` until the rigid-body log has must point [`FROM`], keep that
/// dump as `pose-from.dmp`, stop the run.
fn dump_at_must_point(exe: &Path, dir: &Path) {
    let mut child = febio_cmd(exe, dir, &["-i", "pose.feb", "-o", "pose.log", "-dump=3", restart::DUMP]).spawn().expect("start febio4");
    let start = Instant::now();
    loop {
        let records = std::fs::read_to_string(dir.join(feb::RIGID_LOG)).map(|t| t.matches("*Step").count()).unwrap_or(0);
        if records >= FROM as usize {
            std::fs::copy(dir.join(restart::DUMP), dir.join(restart::DUMP_FROM)).expect("copy the dump");
            let after = std::fs::read_to_string(dir.join(feb::RIGID_LOG)).map(|t| t.matches("*Step").count()).unwrap_or(0);
            let _ = child.kill();
            let _ = child.wait();
            assert_eq!((records, after), (FROM as usize, FROM as usize), "the dump copied at must point {FROM} only");
            return;
        }
        if let Some(s) = child.try_wait().expect("wait") {
            panic!("febio4 ended ({s}) before must point {FROM}: {}", std::fs::read_to_string(dir.join("pose.log")).unwrap_or_default());
        }
        assert!(start.elapsed() < Duration::from_secs(300), "no must point {FROM} in 300 s");
        std::thread::sleep(Duration::from_millis(2));
    }
}

/// The restart's time and its first time step's end, from FEBio's log of the restart.
fn first_step(exe: &Path, dir: &Path, input: &str, log: &str) -> (f64, f64) {
    std::fs::write(dir.join(restart::RESTART_INPUT), input).expect("write the restart input");
    let status =
        febio_cmd(exe, dir, &["-r", restart::RESTART_INPUT, "-noappend", "-o", log, "-dump=3", restart::DUMP]).status().expect("febio4");
    let text = std::fs::read_to_string(dir.join(log)).expect("the restart's log");
    // FEBio appends to the log: the last restart's part
    let part = &text[text.rfind("R E S T A R T").unwrap_or_else(|| panic!("{log}: no restart ({status}):\n{text}"))..];
    let number = |line: &str, key: &str| -> f64 {
        let v = line[line.find(key).expect("key") + key.len()..].trim().trim_end_matches(['.', '*', '=']).trim();
        v.split_whitespace().next().expect("a number").trim_end_matches('.').parse().unwrap_or_else(|e| panic!("{line}: {e}"))
    };
    let from = part.lines().find(|l| l.contains("Restarting from time")).map(|l| number(l, "Restarting from time")).expect("restart time");
    let to = part.lines().find(|l| l.contains("===== beginning time step")).map(|l| number(l, ":")).expect("a time step");
    (from, to)
}

#[test]
fn a_continuation_starts_with_its_first_step_not_the_dumps() {
    let exe = febio::find_febio().unwrap_or_else(|e| panic!("{e:#}: this test runs FEBio (.ci/install-febio)"));
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let spec = root.join("coeffs/default/campaign.toml");
    let mut c = needle_fe::spec::parse(&std::fs::read_to_string(&spec).expect("campaign.toml"), &spec).expect("the shipped spec");
    c.loading.steps = STEPS;
    let pose = c.poses().into_iter().find(|p| p.name == "centre").expect("centre");
    let mesh = c.mesh_level("smoke").expect("smoke").clone();
    let d = tempfile::tempdir().expect("tempdir");
    std::fs::write(d.path().join("pose.feb"), feb::write(&c, &pose, &mesh, STEPS, 1.0).expect("feb").text).expect("write");
    dump_at_must_point(&exe, d.path());

    let step = c.loading.step_time(FROM + 1);
    let first = step * restart::CONTINUE_STEP_FRACTION;
    let must_points = feb::must_points(&c.loading, STEPS, None);
    let r = restart::Restart { must_points: &must_points, from: FROM, first_step: first, dtmin: step * 1e-4, tolerances: None };
    let new = restart::restart_input(&r).expect("restart input");
    let (from, to) = first_step(&exe, d.path(), &new, "restart-new.log");
    let t3 = c.loading.time_at(FROM);
    assert!((from - t3).abs() < 1e-9, "restarted from {from}, not must point {FROM} at {t3}");
    assert!((to - (t3 + first)).abs() < 1e-5, "first step {t3} -> {to}: want {first} (1/16 of {step})");

    // the input before the fix: no <LoadData>, the dump's own step (whole load steps here)
    let old = format!("{}</febio_restart>\n", &new[..new.find("  <!-- must points").expect("the curve's comment")]);
    assert!(!old.contains("LoadData") && old.contains("<step_size>"), "{old}");
    let (from, to) = first_step(&exe, d.path(), &old, "restart-old.log");
    assert!((from - t3).abs() < 1e-9);
    assert!((to - (t3 + step)).abs() < 1e-5, "without the curve the first step is the dump's: {t3} -> {to}, want {}", t3 + step);
}
