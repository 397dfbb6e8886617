//! `needle eval --poses FILE.csv`: every golden vector of the default set, evaluated
//! through the batch command, gives the golden wrench and status bit for bit (the golden
//! file comes from the fitter's own f32 implementation, not from the library); bad rows
//! are named by file and line and nothing is written.

use std::path::PathBuf;
use std::process::Command;

fn default_set() -> PathBuf {
    needle_stdx::workspace_root().join("coeffs/default")
}

fn needle(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_needle")).args(args).output().expect("run needle")
}

fn hex_f32(t: &str) -> f32 {
    f32::from_bits(u32::from_str_radix(t.trim_start_matches("0x"), 16).expect("hex bits"))
}

#[test]
fn batch_eval_reproduces_every_golden_vector() {
    let set = default_set();
    let golden = std::fs::read_to_string(set.join("golden-f32.csv")).expect("golden-f32.csv");
    let rows: Vec<Vec<&str>> = golden.lines().skip(1).map(|l| l.split(',').collect()).collect();
    assert!(rows.len() > 1000, "golden file has {} rows", rows.len());
    let mut input = String::from("depth_mm,theta_z_deg,theta_x_deg,z_mm,x_mm,comment\n"); // another column order
    for r in &rows {
        let v: Vec<f32> = r[..5].iter().map(|t| hex_f32(t)).collect();
        input.push_str(&format!("{:?},{:?},{:?},{:?},{:?},ignored\n", v[4], v[3], v[2], v[1], v[0]));
    }
    let d = tempfile::tempdir().expect("tempdir");
    let file = d.path().join("poses.csv");
    std::fs::write(&file, input).expect("write poses");
    let out = d.path().join("wrenches.csv");
    let o = needle(&["eval", "--set", &set.to_string_lossy(), "--poses", &file.to_string_lossy(), "--out", &out.to_string_lossy()]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let text = std::fs::read_to_string(&out).expect("output");
    let got: Vec<Vec<&str>> = text.lines().skip(1).map(|l| l.split(',').collect()).collect();
    assert_eq!(got.len(), rows.len(), "one output row per input row");
    for (i, (g, r)) in got.iter().zip(&rows).enumerate() {
        // a NaN's payload does not survive the decimal text ("NaN"): any NaN is the same input
        let key = |v: f32| if v.is_nan() { u32::MAX } else { v.to_bits() };
        let pose_in: Vec<u32> = r[..5].iter().map(|t| key(hex_f32(t))).collect();
        let pose_out: Vec<u32> = g[..5].iter().map(|t| key(t.parse::<f32>().expect("pose"))).collect();
        assert_eq!(pose_in, pose_out, "row {}: pose echoed", i + 2);
        for c in 0..6 {
            let want = hex_f32(r[6 + c]).to_bits();
            let have = g[5 + c].parse::<f32>().expect("component").to_bits();
            assert_eq!(have, want, "row {}: component {c}: {:#010x} vs golden {want:#010x}", i + 2, have);
        }
        assert_eq!(g[11], r[5], "row {}: status", i + 2);
    }
}

#[test]
fn bad_rows_are_named_by_line_and_nothing_is_written() {
    let d = tempfile::tempdir().expect("tempdir");
    let file = d.path().join("poses.csv");
    std::fs::write(&file, "x_mm,z_mm,theta_x_deg,theta_z_deg,depth_mm\n1,2,3,4,5\n1,two,3,4,5\n1,2,3,4,5\n1,2,3\n").expect("write");
    let out = d.path().join("w.csv");
    let set = default_set();
    let o = needle(&["eval", "--set", &set.to_string_lossy(), "--poses", &file.to_string_lossy(), "--out", &out.to_string_lossy()]);
    assert_eq!(o.status.code(), Some(2));
    let err = String::from_utf8_lossy(&o.stderr);
    let name = file.display().to_string();
    assert!(err.contains(&format!("{name}:3: column z_mm: \"two\" is not a number")), "{err}");
    assert!(err.contains(&format!("{name}:5: column theta_z_deg: missing")), "{err}");
    assert!(err.contains("2 bad row(s), nothing evaluated"), "rows are counted, not fields (row 5 misses two): {err}");
    assert!(!out.exists(), "nothing written");
    std::fs::write(&file, "x_mm,z_mm,theta_x_deg,depth_mm\n1,2,3,4\n").expect("write");
    let o = needle(&["eval", "--set", &set.to_string_lossy(), "--poses", &file.to_string_lossy()]);
    assert!(
        String::from_utf8_lossy(&o.stderr).contains(&format!("{name}:1: no column \"theta_z_deg\"")),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
}

#[test]
fn a_pose_column_named_twice_is_refused() {
    let d = tempfile::tempdir().expect("tempdir");
    let file = d.path().join("poses.csv");
    std::fs::write(&file, "x_mm,z_mm,theta_x_deg,theta_z_deg,depth_mm,x_mm\n1,2,3,4,5,9\n").expect("write");
    let o = needle(&["eval", "--set", &default_set().to_string_lossy(), "--poses", &file.to_string_lossy()]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains(&format!("{}:1: column \"x_mm\" appears twice in the header (columns 1 and 6)", file.display())), "{err}");
    assert!(o.stdout.is_empty(), "nothing evaluated");
}

#[test]
fn a_huge_bad_field_is_cut_in_the_message() {
    let d = tempfile::tempdir().expect("tempdir");
    let file = d.path().join("poses.csv");
    let field = "z".repeat(5_000_000);
    std::fs::write(&file, format!("x_mm,z_mm,theta_x_deg,theta_z_deg,depth_mm\n1,{field},3,4,5\n")).expect("write");
    let o = needle(&["eval", "--set", &default_set().to_string_lossy(), "--poses", &file.to_string_lossy()]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2));
    assert!(err.len() < 2_000, "the message echoes {} bytes", err.len());
    assert!(
        err.contains(&format!("{}:2: column z_mm: \"{}\"... (5000000 bytes) is not a number", file.display(), "z".repeat(40))),
        "{err}"
    );
}

#[test]
fn out_without_poses_is_refused() {
    let d = tempfile::tempdir().expect("tempdir");
    let out = d.path().join("w.csv");
    let set = default_set();
    let args = ["--x-mm", "0", "--z-mm", "0", "--theta-x-deg", "0", "--theta-z-deg", "0", "--depth-mm", "3", "--out"];
    let o = needle(&[&["eval", "--set", &set.to_string_lossy()], &args[..], &[&out.to_string_lossy()]].concat());
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains("--out") && err.contains("--poses"), "{err}");
    assert!(!out.exists());
}

#[test]
fn a_reader_that_closes_the_pipe_ends_needle_quietly() {
    use std::os::unix::process::ExitStatusExt;
    use std::process::Stdio;
    let set = default_set();
    let set = set.to_str().expect("utf-8");
    // 20,000 rows: more output than a pipe buffers (64 KiB), so the writes do hit the
    // closed pipe
    let d = tempfile::tempdir().expect("tempdir");
    let poses = d.path().join("poses.csv");
    std::fs::write(&poses, format!("x_mm,z_mm,theta_x_deg,theta_z_deg,depth_mm\n{}", "1,2,3,4,5\n".repeat(20_000))).expect("write");
    let one = ["--x-mm", "0", "--z-mm", "0", "--theta-x-deg", "0", "--theta-z-deg", "0", "--depth-mm", "3"];
    let single: Vec<&str> = ["eval", "--set", set].into_iter().chain(one).collect();
    let batch = vec!["eval", "--set", set, "--poses", poses.to_str().expect("utf-8")];
    for args in [single, batch] {
        let mut child =
            Command::new(env!("CARGO_BIN_EXE_needle")).args(&args).stdout(Stdio::piped()).stderr(Stdio::piped()).spawn().expect("spawn");
        drop(child.stdout.take()); // `| head -0`: the reader is gone
        let o = child.wait_with_output().expect("wait");
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(!err.contains("panicked"), "{args:?}: {err}");
        // killed by SIGPIPE like `cat`, or done before it wrote into the closed pipe
        assert!(o.status.signal() == Some(13) || o.status.success(), "{args:?}: {:?} {err}", o.status);
    }
}

#[test]
fn out_onto_a_symlink_or_a_fifo_is_refused_and_left_alone() {
    let d = tempfile::tempdir().expect("tempdir");
    let poses = d.path().join("poses.csv");
    std::fs::write(&poses, "x_mm,z_mm,theta_x_deg,theta_z_deg,depth_mm\n1,2,3,4,5\n").expect("write");
    let target = d.path().join("target.csv");
    std::fs::write(&target, "keep me\n").expect("write");
    let link = d.path().join("link.csv");
    std::os::unix::fs::symlink(&target, &link).expect("symlink");
    let fifo = d.path().join("fifo.csv");
    let made = Command::new("mkfifo").arg(&fifo).status().expect("mkfifo (coreutils)");
    assert!(made.success());
    let set = default_set();
    for (out, what) in [(&link, "a symbolic link"), (&fifo, "not a regular file")] {
        let o = needle(&["eval", "--set", &set.to_string_lossy(), "--poses", &poses.to_string_lossy(), "--out", &out.to_string_lossy()]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{err}");
        assert!(err.contains(&format!("{}: is {what}", out.display())), "{err}");
    }
    assert!(std::fs::symlink_metadata(&link).expect("link").file_type().is_symlink(), "the link is still a link");
    assert_eq!(std::fs::read_to_string(&target).expect("target"), "keep me\n");
    assert!(!std::fs::symlink_metadata(&fifo).expect("fifo").file_type().is_file(), "the FIFO is still a FIFO");
}

/// The streaming path (chunks of 65,536 rows): a bad row after the first chunks were
/// evaluated still leaves nothing written (the old `--out` file as it was, empty standard
/// output), and a good file of several chunks gives one row per input row, in order.
#[test]
fn a_bad_row_after_several_chunks_leaves_nothing_written() {
    let d = tempfile::tempdir().expect("tempdir");
    let file = d.path().join("poses.csv");
    let rows = needle_cli::eval_stream::CHUNK_ROWS * 2 + 17;
    let mut text = String::from("x_mm,z_mm,theta_x_deg,theta_z_deg,depth_mm\n");
    for i in 0..rows {
        text.push_str(&format!("{},0,0,0,{}\n", i % 7, (i % 60) as f32 / 10.0));
    }
    std::fs::write(&file, &text).expect("write");
    let set = default_set();
    let (set, poses) = (set.to_string_lossy(), file.to_string_lossy());
    let out = d.path().join("w.csv");
    let o = needle(&["eval", "--set", &set, "--poses", &poses, "--out", &out.to_string_lossy()]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let written = std::fs::read_to_string(&out).expect("output");
    assert_eq!(written.lines().count(), rows + 1, "the header and one row per pose");
    let o = needle(&["eval", "--set", &set, "--poses", &poses]);
    assert_eq!(String::from_utf8_lossy(&o.stdout), written, "standard output: the same bytes as --out");
    // a bad row near the end: the first chunks were good, nothing may reach the outputs
    text.push_str("1,2,3,four,5\n");
    std::fs::write(&file, &text).expect("write");
    let o = needle(&["eval", "--set", &set, "--poses", &poses, "--out", &out.to_string_lossy()]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains(&format!("{}:{}: column theta_z_deg", file.display(), rows + 2)));
    assert_eq!(std::fs::read_to_string(&out).expect("output"), written, "the old file is left as it was");
    assert_eq!(std::fs::read_dir(d.path()).expect("dir").count(), 2, "no temporary left beside it");
    let o = needle(&["eval", "--set", &set, "--poses", &poses]);
    assert_eq!(o.status.code(), Some(2));
    assert!(o.stdout.is_empty(), "nothing on standard output");
}

/// Every core parses a slice of each chunk: the problems of bad rows in different
/// slices and chunks are still listed in line order, each with its own line.
#[test]
fn bad_rows_in_several_slices_are_listed_in_line_order() {
    let d = tempfile::tempdir().expect("tempdir");
    let file = d.path().join("poses.csv");
    let chunk = needle_cli::eval_stream::CHUNK_ROWS;
    // 0-based rows: early in the first slice, late in the chunk (the last slice), next chunk
    let bad = [3, chunk - 2, chunk + 5];
    let mut text = String::from("x_mm,z_mm,theta_x_deg,theta_z_deg,depth_mm\n");
    for i in 0..chunk + 10 {
        text.push_str(if bad.contains(&i) { "1,x,0,0,1\n" } else { "1,0,0,0,1\n" });
    }
    std::fs::write(&file, &text).expect("write");
    let set = default_set();
    let o = needle(&["eval", "--set", &set.to_string_lossy(), "--poses", &file.to_string_lossy()]);
    assert_eq!(o.status.code(), Some(2));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("3 bad row(s)"), "{err}");
    let at: Vec<usize> = bad.iter().map(|i| err.find(&format!("{}:{}: column z_mm", file.display(), i + 2)).expect("listed")).collect();
    assert!(at.windows(2).all(|w| w[0] < w[1]), "in line order: {err}");
}

/// White space around a field or a header name is not part of it (the batch path trims
/// each field itself, the CSV reader only the header): a padded file gives the rows of
/// the plain one, byte for byte, and a bad padded field is echoed without its padding.
#[test]
fn padded_fields_read_as_the_numbers_they_hold() {
    let d = tempfile::tempdir().expect("tempdir");
    let set = default_set();
    let run = |name: &str, text: &str| {
        let file = d.path().join(name);
        std::fs::write(&file, text).expect("write");
        let out = d.path().join(format!("{name}.out"));
        let o = needle(&["eval", "--set", &set.to_string_lossy(), "--poses", &file.to_string_lossy(), "--out", &out.to_string_lossy()]);
        (o, std::fs::read(&out).ok(), file)
    };
    let (o, plain, _) = run("plain.csv", "x_mm,z_mm,theta_x_deg,theta_z_deg,depth_mm\n2,1,3,0,5\n-1.5,0.25,-4,7,2\n");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let (o, padded, _) =
        run("padded.csv", " x_mm ,\tz_mm,theta_x_deg , theta_z_deg,depth_mm\n 2 ,1\t, 3,0 ,  5\n\t-1.5,  0.25 ,-4 ,7,2 \n");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(plain.is_some());
    assert_eq!(padded, plain, "padded fields give the plain file's rows");
    let (o, written, file) = run("bad.csv", "x_mm,z_mm,theta_x_deg,theta_z_deg,depth_mm\n2, 1 x ,3,0,5\n");
    assert_eq!(o.status.code(), Some(2));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains(&format!("{}:2: column z_mm: \"1 x\" is not a number", file.display())), "{err}");
    assert!(written.is_none(), "nothing written");
}
