//! What a FEBio attempt needs to go on after its campaign was killed (a session's end
//! SIGKILLs every process; no handler runs): `running.toml` ([`RUNNING_FILE`]) in the
//! pose's work folder, and the rule that says from which must point its dump goes on.
//!
//! At the start of each FEBio process of an attempt (the run from depth 0, each
//! continuation from a must point, the continuation of the furthest attempt) the backend
//! writes [`Running`] atomically: the attempt, its ladder plan, the furthest attempt it
//! continues (if any), the rigid-body records of the segments before this process, the
//! continuation depths and the number of segment logs kept. It removes the file as soon
//! as the attempt ends, before its failure bookkeeping. When `solve` is called for the
//! attempt the file names and `pose.dmp` exists, the attempt goes on from the dump
//! ([`resume_point`]) instead of from its start.
//!
//! **The dump's time.** FEBio 4.11, at a must point: "converged at time", then the dump
//! (`-dump=3`: the file is truncated and rewritten), then "Restart point created", then
//! the rigid-body record (seen in the logs of tz+08, and in the files' times: the dump
//! 13:30:28.367, `needle-rb.txt` 13:30:28.591). So a kill leaves the dump either at the
//! last logged must point, or at the next one without its record (killed between the
//! dump and the record), or cut short (killed while writing it). The dump names its own
//! time: FEBio's `Serialize` writes the restart format's version (`int` 6), the module's
//! name (`int` length, bytes: "solid") and the model's time (`f64`) first
//! ([`dump_time`]; on the restart FEBio prints the same "Restarting from time 9.6.").
//! The file names and data records of FEBio's IO data come last, so a dump without the
//! rigid log's name in its last [`TAIL_BYTES`] is taken as cut short
//! ([`dump_complete`]). The attempt goes on from the dump only when its time is a must
//! point whose record, and every one before it, is logged; otherwise it is rerun from
//! its start, and the reason is printed. If FEBio still cannot read the dump (its
//! restart does not print "Restarting from time"), the backend reruns the attempt from
//! its start too (`febio/mod.rs`).

use super::logs::RigidRecord;
use super::{feb, ladder, pick_steps};
use crate::spec::Loading;
use anyhow::{Context, Result};
use serde::{Deserialize, Serialize};
use std::io::{Read, Seek, SeekFrom};
use std::path::{Path, PathBuf};

/// The running attempt's state in a pose's work folder.
pub const RUNNING_FILE: &str = "running.toml";

/// The restart format version FEBio 4 writes first in a dump (`RSTRTVERSION`).
pub const DUMP_FORMAT: i32 = 6;

/// How far from the end of a dump FEBio's IO data (file names, data records) is looked for.
pub const TAIL_BYTES: u64 = 64 * 1024;

/// What FEBio prints when its restart has read the dump ("Restarting from time 9.6.").
pub const RESTARTED: &str = "Restarting from time";

/// `running.toml`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Running {
    /// The campaign's attempt index (0-based, `Job::attempt`).
    pub attempt: u32,
    /// The ladder's plan of the attempt.
    pub plan: ladder::Plan,
    /// The furthest attempt this one continues (a [`ladder::Plan::Continue`]).
    pub continued: Option<ladder::Furthest>,
    /// The rigid-body records of the segments before the running process (as logged).
    pub earlier: Vec<RigidRecord>,
    /// The depths (solver's time) the attempt's continuations started from
    /// (`restart::Continuations::from_mm`).
    pub continued_from: Vec<f64>,
    /// Segment logs kept so far (`needle-rb-<n>.txt`, `pose-<n>.log`, n < this).
    pub segments: u32,
}

/// `<work_dir>/running.toml`.
pub fn path(work_dir: &Path) -> PathBuf {
    work_dir.join(RUNNING_FILE)
}

/// Write `r` atomically.
///
/// # Errors
/// The file cannot be written (with its path).
pub fn write(work_dir: &Path, r: &Running) -> Result<()> {
    let p = path(work_dir);
    let text = format!(
        "# the running FEBio attempt of this pose (fe/febio/running.rs): a rerun goes on from pose.dmp\n{}",
        toml::to_string(r).with_context(|| format!("{}: cannot serialise", p.display()))?
    );
    needle_stdx::fs::write_atomic(&p, text.as_bytes())
}

/// Read `running.toml`; `Ok(None)` when there is none.
///
/// # Errors
/// It exists but cannot be read or parsed (with its path).
pub fn read(work_dir: &Path) -> Result<Option<Running>> {
    let p = path(work_dir);
    match std::fs::read_to_string(&p) {
        Ok(t) => toml::from_str(&t).map(Some).with_context(|| format!("{}: not a running attempt's record", p.display())),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(None),
        Err(e) => Err(e).with_context(|| format!("{}: cannot read", p.display())),
    }
}

/// Remove `running.toml` (the attempt ended); a missing file is fine.
pub fn remove(work_dir: &Path) {
    let _ = std::fs::remove_file(path(work_dir));
}

/// The model's time a FEBio 4 dump starts with (module docs), or `None` when the first
/// bytes are not that header (another format, or a file cut short in its first bytes).
pub fn dump_time(head: &[u8]) -> Option<f64> {
    let int = |at: usize| head.get(at..at + 4).and_then(|b| b.try_into().ok()).map(i32::from_le_bytes);
    if int(0)? != DUMP_FORMAT {
        return None;
    }
    let len = usize::try_from(int(4)?).ok().filter(|&n| (1..=64).contains(&n))?;
    let name = head.get(8..8 + len)?;
    if !name.iter().all(|c| c.is_ascii_alphanumeric() || *c == b'-' || *c == b'_') {
        return None;
    }
    let t = f64::from_le_bytes(head.get(8 + len..16 + len)?.try_into().ok()?);
    (t.is_finite() && t >= 0.0).then_some(t)
}

/// Whether the dump at `dump` ends with FEBio's IO data: the rigid-body log's file name
/// within its last [`TAIL_BYTES`] (module docs). `false` when it cannot be read.
pub fn dump_complete(dump: &Path) -> bool {
    let tail = (|| -> std::io::Result<Vec<u8>> {
        let mut f = std::fs::File::open(dump)?;
        let len = f.metadata()?.len();
        f.seek(SeekFrom::Start(len.saturating_sub(TAIL_BYTES)))?;
        let mut b = Vec::new();
        f.read_to_end(&mut b)?;
        Ok(b)
    })();
    let name = feb::RIGID_LOG.as_bytes();
    tail.map(|t| t.windows(name.len()).any(|w| w == name)).unwrap_or(false)
}

/// Where an interrupted attempt goes on from.
#[derive(Debug, Clone, PartialEq)]
pub struct ResumePoint {
    /// Must points reached (from step 1 on, without a gap); the dump is at the last.
    pub steps: u32,
    /// The records of every segment up to the dump's must point (later ones dropped).
    pub records: Vec<RigidRecord>,
}

/// The must point the dump at `dump` is at, given the records of the segments before the
/// interrupted process (`earlier`) and of the interrupted one (`current`). Guarantees:
/// `Ok` only for a readable, complete dump whose time is must point k of `loading`
/// (`steps` in all) with records at must points 1..=k; the records returned then stop at
/// the dump's time. `Err` says why the attempt cannot go on from the dump.
pub fn resume_point(
    dump: &Path,
    earlier: &[RigidRecord],
    current: &[RigidRecord],
    loading: &Loading,
    steps: u32,
) -> std::result::Result<ResumePoint, String> {
    // the file's name only: the reason goes into the manifest's settings line
    let name = dump.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    let mut head = [0u8; 96];
    let n = std::fs::File::open(dump).and_then(|mut f| f.read(&mut head)).map_err(|e| format!("{name}: cannot read: {e}"))?;
    let t = dump_time(head.get(..n).unwrap_or_default())
        .ok_or_else(|| format!("{name}: no FEBio 4 dump header with the model's time in its first {n} bytes"))?;
    if !dump_complete(dump) {
        return Err(format!("{name} (time {t}) is cut short: no {} in its IO data at the end", feb::RIGID_LOG));
    }
    let tol = 1e-6 * loading.time_at(steps);
    let records: Vec<RigidRecord> = earlier.iter().chain(current.iter().filter(|r| r.time <= t + tol)).copied().collect();
    let reached = pick_steps(&records, loading, steps).iter().take_while(|v| v.is_some()).count() as u32;
    let at = loading.time_at(reached);
    if reached == 0 || (t - at).abs() > tol {
        return Err(format!(
            "{name} is at time {t}, the last must point with a record (and every one before it) at {at}{}",
            if t > at { ": killed between FEBio's dump and its record" } else { "" }
        ));
    }
    Ok(ResumePoint { steps: reached, records })
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use needle_contract::COMPONENT_COUNT;

    /// The bytes of a FEBio 4 dump at time `t` as far as [`resume_point`] reads them: the
    /// header, a body, and (when `complete`) the IO data with the rigid log's name.
    pub(crate) fn dump_bytes(t: f64, complete: bool) -> Vec<u8> {
        let mut b = Vec::new();
        b.extend_from_slice(&DUMP_FORMAT.to_le_bytes());
        b.extend_from_slice(&5i32.to_le_bytes());
        b.extend_from_slice(b"solid");
        b.extend_from_slice(&t.to_le_bytes());
        b.extend(std::iter::repeat_n(0x33u8, 4096));
        if complete {
            b.extend_from_slice(format!("pose.feb pose.xplt pose.log pose.dmp {} Fx;Fy;Fz;Mx;My;Mz", feb::RIGID_LOG).as_bytes());
        }
        b
    }

    fn rec(t: f64, v: f64) -> RigidRecord {
        RigidRecord { time: t, values: [v; COMPONENT_COUNT] }
    }

    #[test]
    fn the_dump_header_names_its_time() {
        assert_eq!(dump_time(&dump_bytes(9.6, false)), Some(9.6));
        assert_eq!(dump_time(&dump_bytes(3.3000000000000003, false)), Some(3.3000000000000003));
        assert_eq!(dump_time(&dump_bytes(9.6, false)[..20]), None, "cut inside the time");
        assert_eq!(dump_time(&[]), None);
        let mut other = dump_bytes(9.6, false);
        other[0] = 7;
        assert_eq!(dump_time(&other), None, "another restart format");
    }

    /// The dump-time rule of the module docs, case by case: 4 steps to 6 mm (must points
    /// 1.5, 3, 4.5, 6); an earlier segment logged 1.5, the interrupted one 3 and 4.5.
    #[test]
    fn the_attempt_goes_on_only_from_a_complete_dump_at_a_logged_must_point() {
        let d = tempfile::tempdir().expect("tempdir");
        let dump = d.path().join("pose.dmp");
        let loading = Loading { depth_mm: 6.0, steps: 4, ramp_hold: None };
        let earlier = [rec(1.5, 1.0)];
        let current = [rec(3.0, 2.0), rec(4.5, 3.0)];
        let at = |t: f64, complete: bool| {
            std::fs::write(&dump, dump_bytes(t, complete)).expect("write");
            resume_point(&dump, &earlier, &current, &loading, 4)
        };
        // the usual case: the dump at the last logged must point
        assert_eq!(at(4.5, true), Ok(ResumePoint { steps: 3, records: vec![earlier[0], current[0], current[1]] }));
        // killed between the dump at 6 and its record
        let e = at(6.0, true).expect_err("no record at the dump's time");
        assert!(e.contains("at time 6, the last must point with a record") && e.contains("killed between"), "{e}");
        // killed while writing the dump
        assert!(at(6.0, false).expect_err("cut short").contains("cut short"));
        // records past the dump's time are not the dump's (dropped)
        assert_eq!(at(3.0, true).map(|p| (p.steps, p.records.len())), Ok((2, 2)));
        // a dump between must points, or before any, or empty
        assert!(at(3.7, true).is_err() && at(0.0, true).is_err());
        std::fs::write(&dump, b"").expect("empty");
        assert!(resume_point(&dump, &earlier, &current, &loading, 4).expect_err("empty").contains("no FEBio 4 dump header"));
        // a gap in the records before the dump
        std::fs::write(&dump, dump_bytes(4.5, true)).expect("write");
        assert!(resume_point(&dump, &[], &current, &loading, 4).is_err(), "must point 1 has no record");
    }

    #[test]
    fn the_record_survives_its_file() {
        let d = tempfile::tempdir().expect("tempdir");
        assert_eq!(read(d.path()).expect("none"), None);
        let a = ladder::fresh_order(false);
        let r = Running {
            attempt: 2,
            plan: ladder::Plan::Continue { from_attempt: 1, from_steps: 2, contact: a[0] },
            continued: Some(ladder::Furthest {
                attempt: 1,
                steps: 2,
                records: vec![[1.0, -2.5e-3, 0.0, 0.0, 4.0, 1e-9]; 2],
                settings: "s".into(),
            }),
            earlier: vec![rec(1.5, 1.0), rec(3.0, 2.0)],
            continued_from: vec![3.0],
            segments: 1,
        };
        write(d.path(), &r).expect("write");
        assert_eq!(read(d.path()).expect("read"), Some(r));
        remove(d.path());
        assert_eq!(read(d.path()).expect("gone"), None);
        std::fs::write(path(d.path()), "attempt = 1").expect("write");
        assert!(read(d.path()).is_err());
    }

    /// A pose's work folder as a campaign killed while FEBio ran leaves it, and the fake
    /// febio4 that made it (bookkeeping only, no physics): its first run logs the must
    /// points 1.5 and 3 mm (of 4 steps to 6 mm), copies `dump` (the fixture) to `pose.dmp`,
    /// copies the work folder to `snap` at that moment (that copy is the killed campaign's
    /// folder: `running.toml` written before the process, the dump, the log), then gives up
    /// at 3.2 mm. A restart (`-r`) reads `pose-from.dmp`: one holding `UNREADABLE` fails
    /// as FEBio does on a dump it cannot read; else it prints FEBio's restart line and logs
    /// 4.5 and 6 mm. Every call's arguments go to `calls`.
    pub(crate) struct Killed {
        pub(crate) exe: PathBuf,
        calls: PathBuf,
        pub(crate) dump: PathBuf,
        pub(crate) snap: PathBuf,
    }

    pub(crate) fn killed(dir: &Path) -> Killed {
        use std::os::unix::fs::PermissionsExt;
        let k =
            Killed { exe: dir.join("fake-febio4"), calls: dir.join("calls.txt"), dump: dir.join("fixture.dmp"), snap: dir.join("snap") };
        let rb = |ts: &[(f64, f64)]| -> String {
            ts.iter()
                .map(|(t, v)| format!("*Step  = 1\\n*Time  = {t}\\n*Data  = Fx;Fy;Fz;Mx;My;Mz\\n2,{v},{v},{v},{v},{v},{v}\\n"))
                .collect()
        };
        let script = format!(
            "#!/bin/sh\n\
             echo \"$*\" >> '{calls}'\n\
             case \" $* \" in *\" -r \"*)\n\
             grep -q '<Archive>pose-from.dmp</Archive>' pose-restart.feb && [ -f pose-from.dmp ] || exit 3\n\
             if grep -q UNREADABLE pose-from.dmp; then echo 'FATAL ERROR: failed reading restart data from archive pose-from.dmp'; exit 1; fi\n\
             echo ' * {RESTARTED} 3.'\n\
             printf '{late}' > needle-rb.txt\n\
             printf ' ------- converged at time : 4.5\\n ------- converged at time : 6\\n N O R M A L   T E R M I N A T I O N\\n' > pose.log\n\
             exit 0;;\n\
             esac\n\
             printf '{early}' > needle-rb.txt; cp '{dump}' pose.dmp\n\
             [ -d '{snap}' ] || {{ mkdir -p '{snap}' && cp -p * '{snap}/'; }}\n\
             printf ' ------- converged at time : 1.5\\n ------- converged at time : 3\\n ------- failed to converge at time : 3.2\\n E R R O R   T E R M I N A T I O N\\n' > pose.log\n\
             exit 1\n",
            calls = k.calls.display(),
            late = rb(&[(4.5, 3.0), (6.0, 4.0)]),
            early = rb(&[(1.5, 1.0), (3.0, 2.0)]),
            dump = k.dump.display(),
            snap = k.snap.display(),
        );
        std::fs::write(&k.exe, script).expect("write the fake febio4");
        std::fs::set_permissions(&k.exe, std::fs::Permissions::from_mode(0o755)).expect("chmod");
        k
    }

    /// The calls of the fake since the last look: `-r` (a restart) or `-i` (from depth 0).
    /// The FEBio backend running `exe` with one thread (its fields are the module's).
    pub(crate) fn backend_with(exe: &Path) -> super::super::FebioBackend {
        super::super::FebioBackend { exe: Some(exe.to_path_buf()), threads: 1 }
    }

    pub(crate) fn calls(k: &Killed) -> Vec<&'static str> {
        let text = std::fs::read_to_string(&k.calls).unwrap_or_default();
        let _ = std::fs::remove_file(&k.calls);
        text.lines().map(|l| if l.contains(" -r ") { "-r" } else { "-i" }).collect()
    }

    pub(crate) type Solve = std::result::Result<crate::backend::Solved, crate::backend::SolveFailure>;

    /// Kill a campaign in attempt 1 of `centre` (the first FEBio process, at 3 mm) with
    /// `fixture` as the dump it left, and solve the attempt again in the killed folder.
    fn kill_and_rerun(fixture: &[u8]) -> (Killed, Solve, Solve, tempfile::TempDir) {
        use crate::backend::{Backend, Job};
        let tmp = tempfile::tempdir().expect("tempdir");
        let d = tmp.path().to_path_buf();
        let set = d.join("set");
        std::fs::create_dir_all(&set).expect("mkdir");
        std::fs::copy(needle_stdx::workspace_root().join("coeffs/default/campaign.toml"), set.join("campaign.toml")).expect("copy");
        let (mut c, _) = crate::spec::load(&set).expect("spec");
        c.loading.steps = 4;
        let pose = c.poses().into_iter().find(|p| p.name == "centre").expect("centre");
        let mesh = c.mesh_level("smoke").expect("smoke").clone();
        let k = killed(&d);
        std::fs::write(&k.dump, fixture).expect("fixture");
        let backend = super::super::FebioBackend { exe: Some(k.exe.clone()), threads: 1 };
        let work = d.join("work");
        std::fs::create_dir_all(&work).expect("mkdir");
        fn job<'a>(
            c: &'a crate::spec::Campaign,
            pose: &'a crate::spec::PoseSpec,
            mesh: &'a crate::spec::MeshLevel,
            dir: &'a Path,
        ) -> Job<'a> {
            Job {
                campaign: c,
                pose,
                mesh_name: "smoke",
                mesh,
                steps: 4,
                work_dir: dir,
                timeout: None,
                stall: None,
                first_increment: 1.0,
                attempt: 0,
            }
        }
        // the run that was not killed: its first process continued from 3 mm at once
        let whole = backend.solve(&job(&c, &pose, &mesh, &work));
        assert!(read(&work).expect("readable").is_none(), "running.toml goes when the attempt ends");
        let running = read(&k.snap).expect("readable").expect("running.toml of the killed process");
        assert_eq!((running.attempt, running.segments, running.earlier.len()), (0, 0, 0));
        calls(&k);
        let again = backend.solve(&job(&c, &pose, &mesh, &k.snap));
        (k, again, whole, tmp)
    }

    /// A killed campaign's attempt goes on from its dump at 3 mm with a restart (not from
    /// depth 0), with the plan's own first step, and gives the uninterrupted run's wrenches
    /// (the earlier segment's records and the restart's).
    #[test]
    fn a_killed_attempt_goes_on_from_its_dump() {
        let (k, again, whole, _tmp) = kill_and_rerun(&dump_bytes(3.0, true));
        let s = again.unwrap_or_else(|f| panic!("resumed: {}", f.message));
        let whole = whole.unwrap_or_else(|f| panic!("the uninterrupted run: {}", f.message));
        assert_eq!(calls(&k), ["-r"], "one restart, no run from depth 0");
        assert_eq!(s.wrenches, whole.wrenches);
        assert!(s.settings.ends_with("; resumed after an interruption at 3 mm"), "{}", s.settings);
        let restart = std::fs::read_to_string(k.snap.join(super::super::restart::RESTART_INPUT)).expect("restart input");
        let loading = Loading { depth_mm: 6.0, steps: 4, ramp_hold: None };
        assert!(restart.contains(&format!("<step_size>{:e}</step_size>", loading.step_time(3))), "a whole load step: {restart}");
        assert!(k.snap.join(super::super::restart::segment_log_name(0)).is_file(), "the killed segment's log is kept");
        assert!(read(&k.snap).expect("readable").is_none());
    }

    /// The dump-time rule in the backend: a dump past the last record (killed between the
    /// dump and its record), and one FEBio cannot read, rerun the attempt from depth 0.
    #[test]
    fn a_dump_without_its_record_or_unreadable_reruns_the_attempt_from_its_start() {
        let (k, again, whole, _tmp) = kill_and_rerun(&dump_bytes(4.5, true));
        let s = again.unwrap_or_else(|f| panic!("rerun: {}", f.message));
        let whole = whole.unwrap_or_else(|f| panic!("the uninterrupted run: {}", f.message));
        assert_eq!(calls(&k), ["-i", "-r"], "from depth 0, then its own continuation");
        assert_eq!(s.wrenches, whole.wrenches);
        assert!(s.settings.contains("could not go on from its dump (pose.dmp is at time 4.5, the last must point"), "{}", s.settings);

        let mut unreadable = dump_bytes(3.0, true);
        unreadable.extend_from_slice(b"UNREADABLE");
        let (k, again, _, _tmp) = kill_and_rerun(&unreadable);
        let f = again.expect_err("the fake's restarts all fail on this dump");
        assert_eq!(calls(&k), ["-r", "-i", "-r"], "the restart fails, then from depth 0: {}", f.message);
        assert!(f.message.contains("after 2 of 4 steps"), "{}", f.message);
    }
}
