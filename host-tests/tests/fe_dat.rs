//! The `.dat` reaction force reader and the `.sta` reader, on real ccx 2.20 output
//! stored in tests/data/ccx/ (see its README for the decks that produced it).

use needle_fe::ccx;
use needle_fe::ccx::dat::{parse_rf, StepRf};
use std::path::PathBuf;

fn data(name: &str) -> String {
    let p = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data/ccx").join(name);
    std::fs::read_to_string(&p).unwrap_or_else(|e| panic!("{}: {e}", p.display()))
}

/// ccx's own `total force (fx,fy,fz) for set <set>` lines: (time, total), read here
/// independently of the library.
fn totals(text: &str, set: &str) -> Vec<(f64, [f64; 3])> {
    let head = format!("total force (fx,fy,fz) for set {set} and time");
    let lines: Vec<&str> = text.lines().collect();
    let mut out = Vec::new();
    for (i, l) in lines.iter().enumerate() {
        if let Some(t) = l.trim().strip_prefix(&head) {
            let time: f64 = t.trim().parse().expect("time");
            let v: Vec<f64> = lines[i + 1..]
                .iter()
                .find(|l| !l.trim().is_empty())
                .expect("a totals line")
                .split_whitespace()
                .map(|x| x.parse().expect("number"))
                .collect();
            assert_eq!(v.len(), 3, "totals line after line {}", i + 1);
            out.push((time, [v[0], v[1], v[2]]));
        }
    }
    out
}

fn sum(step: &StepRf) -> [f64; 3] {
    let mut s = [0.0; 3];
    for (_, f) in &step.nodes {
        for k in 0..3 {
            s[k] += f[k];
        }
    }
    s
}

#[test]
fn needle_set_three_steps_match_ccx_totals() {
    let text = data("needle-nprint-3steps.dat");
    // set names are case-insensitive
    let steps = parse_rf(&text, "nprint").expect("parse");
    assert_eq!(steps.len(), 3, "one block per step");
    let node_count = text.lines().filter(|l| l.trim_start().starts_with("1000")).count();
    for (k, s) in steps.iter().enumerate() {
        assert_eq!(s.total_time, (k + 1) as f64, "step {} ends at total time {}", k + 1, k + 1);
        assert_eq!(s.nodes.len(), 438, "NPRINT has 438 nodes");
        let ids: std::collections::BTreeSet<u32> = s.nodes.iter().map(|n| n.0).collect();
        assert_eq!(ids.len(), s.nodes.len(), "node numbers are distinct");
        assert!(s.nodes.iter().all(|(_, f)| f.iter().all(|v| v.is_finite())));
    }
    assert_eq!(node_count, 3 * 438, "every node line of the file was read");
    assert_eq!(steps[0].nodes.iter().map(|n| n.0).collect::<Vec<_>>(), steps[2].nodes.iter().map(|n| n.0).collect::<Vec<_>>());

    let tot = totals(&text, "NPRINT");
    assert_eq!(tot.len(), 3, "the file has ccx's totals for each step");
    for (s, (t, total)) in steps.iter().zip(&tot) {
        assert_eq!(s.total_time, *t);
        let mine = sum(s);
        for k in 0..3 {
            // ccx prints 7 significant digits per node and per total: the bound of the
            // rounding of every printed number
            let abs_sum: f64 = s.nodes.iter().map(|(_, f)| f[k].abs()).sum();
            let tol = 5e-7 * (abs_sum + total[k].abs());
            assert!((mine[k] - total[k]).abs() <= tol, "time {t}, component {k}: sum {} vs ccx total {}", mine[k], total[k]);
        }
    }
    // the needle is pushed into the tissue: a non-zero vertical reaction that grows
    let fy: Vec<f64> = steps.iter().map(|s| sum(s)[1]).collect();
    assert!(fy.iter().all(|f| *f != 0.0), "{fy:?}");
    assert!(fy[2].abs() > fy[1].abs() && fy[1].abs() > fy[0].abs(), "|Fy| grows with depth: {fy:?}");
}

#[test]
fn rigid_body_sets_among_other_blocks() {
    let text = data("rigid-rp-3steps.dat");
    let rp = parse_rf(&text, "RP").expect("RP");
    let rot = parse_rf(&text, "rprot").expect("RPROT");
    assert_eq!((rp.len(), rot.len()), (3, 3));
    assert!(rp.iter().all(|s| s.nodes.len() == 1 && s.nodes[0].0 == 999_999));
    assert!(rot.iter().all(|s| s.nodes.len() == 1 && s.nodes[0].0 == 999_998));
    // the same model solved with prescribed needle nodes instead of a rigid body: the
    // reference node's force is the total of the needle nodes' reactions
    let tot = totals(&data("needle-nprint-3steps.dat"), "NPRINT");
    for (s, (t, total)) in rp.iter().zip(&tot) {
        assert_eq!(s.total_time, *t);
        assert_eq!(s.nodes[0].1, *total, "rigid RP force = NPRINT total at time {t}");
    }
}

#[test]
fn missing_set_names_the_sets_present() {
    // ccx 2.20 only warns about an undefined *NODE PRINT set and exits 0
    let text = data("nodeprint-undefined-set.dat");
    let e = parse_rf(&text, "NOSUCHSET").expect_err("no such block").to_string();
    assert!(e.contains("NOSUCHSET") && e.contains("RPROT"), "{e}");
    let e = parse_rf("", "NPRINT").expect_err("empty file").to_string();
    assert!(e.contains("no reaction force block"), "{e}");
}

/// Line number (1-based) and text of the first node line of the file.
fn first_node_line(text: &str) -> (usize, String) {
    text.lines().enumerate().find(|(_, l)| l.trim_start().starts_with("1000")).map(|(i, l)| (i + 1, l.to_string())).expect("a node line")
}

fn replace_line(text: &str, n: usize, new: &str) -> String {
    text.lines().enumerate().map(|(i, l)| if i + 1 == n { new } else { l }).collect::<Vec<_>>().join("\n")
}

#[test]
fn bad_input_errors_name_line_and_text() {
    let text = data("needle-nprint-3steps.dat");
    let (n, line) = first_node_line(&text);

    // a Fortran overflow in a number
    let fields: Vec<&str> = line.split_whitespace().collect();
    let bad = line.replacen(fields[2], "*************", 1);
    let e = parse_rf(&replace_line(&text, n, &bad), "NPRINT").expect_err("overflow").to_string();
    assert!(e.contains(&format!("line {n}:")) && e.contains("*************") && e.contains("fy"), "{e}");

    // a truncated line
    let bad = format!("{} {}", fields[0], fields[1]);
    let e = parse_rf(&replace_line(&text, n, &bad), "NPRINT").expect_err("truncated").to_string();
    assert!(e.contains(&format!("line {n}:")) && e.contains(&bad), "{e}");

    // a header whose time is not a number
    let h = text.lines().position(|l| l.contains("forces (fx,fy,fz) for set NPRINT")).expect("header") + 1;
    let bad = " forces (fx,fy,fz) for set NPRINT and time  x.y";
    let e = parse_rf(&replace_line(&text, h, bad), "NPRINT").expect_err("time").to_string();
    assert!(e.contains(&format!("line {h}:")) && e.contains("x.y"), "{e}");

    // a header followed directly by another block: no node lines
    let cut: String = text.lines().take(h + 1).chain(text.lines().skip(h + 1 + 438)).collect::<Vec<_>>().join("\n");
    let e = parse_rf(&cut, "NPRINT").expect_err("empty block").to_string();
    assert!(e.contains(&format!("line {h}:")) && e.contains("no node lines"), "{e}");

    // a file cut in the middle of a node line's numbers
    let end = text.lines().position(|l| l.contains("total force")).expect("total");
    let mut cut: Vec<&str> = text.lines().take(end - 2).collect();
    let last = cut.pop().expect("line");
    let half = &last[..last.len() - 14]; // drop the last number and its space
    let cut = format!("{}\n{half}", cut.join("\n"));
    let e = parse_rf(&cut, "NPRINT").expect_err("cut").to_string();
    assert!(e.contains(&format!("line {}:", end - 2)) && e.contains(half.trim()), "{e}");
}

#[test]
fn sta_files() {
    let ok = ccx::parse_sta(&data("needle-nprint-3steps.sta"));
    assert_eq!((ok.increments, ok.cutbacks, ok.steps_done()), (3, 0, 3));
    assert_eq!(ok.iterations, 12 + 9 + 9);
    // every attempt of the only increment was cut back (ATT with a U)
    let text = data("table1-cutbacks.sta");
    let attempts: Vec<Vec<&str>> =
        text.lines().map(|l| l.split_whitespace().collect::<Vec<_>>()).filter(|f| f.len() == 7 && f[0] == "1").collect();
    assert!(attempts.len() >= 3 && attempts.iter().all(|f| f[2].ends_with('U')));
    let cut = ccx::parse_sta(&text);
    assert_eq!((cut.increments, cut.cutbacks as usize, cut.steps_done()), (0, attempts.len(), 0));
    assert_eq!(cut.iterations, attempts.iter().map(|f| f[3].parse::<u32>().expect("ITRS")).sum::<u32>());
    let none = ccx::parse_sta(&data("boundary-undefined-set.sta"));
    assert_eq!((none.increments, none.iterations, none.steps_done()), (0, 0, 0));
}

#[test]
fn log_tail_of_a_fatal_input_error() {
    let log = data("boundary-undefined-set.log");
    let t = ccx::tail(&log, 5);
    assert_eq!(t.lines().count(), 5);
    assert!(t.contains("CalculiX stops"), "{t}");
    assert!(ccx::tail(&log, ccx::LOG_TAIL_LINES).contains("*ERROR reading *BOUNDARY"));
}
