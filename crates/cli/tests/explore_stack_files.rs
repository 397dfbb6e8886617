//! `needle explore --stack FILE` (issue 65 item 3: the explorer draws a plausible tissue
//! too): a stack calibrated on three skin repeats (read in place from
//! `../shared/data/stokes-needle-rig/`) and the tissues drawn within its spread reach the
//! page as the wasm module's layer words (`/stacks.json`), and the page's glue
//! (`needle-wasm.mjs` `insertLayers`) plays each under Node bit for bit as the host's
//! library plays the tissue file and `needle stack sample --seed K`'s file: every tick's
//! Fy bits, phase and punctures. Node and the wasm32 target are required (`.ci/test`
//! installs both); missing, the test fails.

mod common;
use common::{needle, shipped_set_arg, show};
use needle_calibrate::runtime_stack::OwnedStack;
use needle_haptics::insertion::{Insertion, InsertionConfig};
use needle_haptics::Pose;
use std::path::{Path, PathBuf};

fn rig(name: &str) -> String {
    let p = needle_stdx::workspace_root().join("../shared/data/stokes-needle-rig").join(name);
    assert!(p.is_file(), "{}: the measured rig trials live beside the checkout", p.display());
    p.to_string_lossy().into_owned()
}

/// The path: in at 2 mm/s from -1 mm to 5 mm past the layers, held 1 s, out again (1 kHz).
fn depths(stack: &OwnedStack) -> Vec<f32> {
    let deepest = stack.layers.iter().map(|l| f64::from(l.thickness_mm)).sum::<f64>() + 5.0;
    let ticks = ((deepest + 1.0) / 0.002).round() as usize;
    let down: Vec<f32> = (0..=ticks).map(|i| (-1.0 + 0.002 * i as f64) as f32).collect();
    let last = *down.last().expect("ticks");
    down.iter().copied().chain(std::iter::repeat_n(last, 1000)).chain(down.iter().rev().copied()).collect()
}

/// The host's line for `stack` on `path`, as stack_files.mjs prints it.
fn host_line(label: &str, stack: &OwnedStack, path: &[f32]) -> String {
    let mut ins = Insertion::new(&stack.as_stack(), InsertionConfig::DEFAULT_1KHZ).expect("a loaded stack starts");
    let (mut digest, mut punctures) = (0xcbf2_9ce4_8422_2325_u64, 0u32);
    let mut word = |v: u32| {
        for b in v.to_le_bytes() {
            digest ^= u64::from(b);
            digest = digest.wrapping_mul(0x100_0000_01b3);
        }
    };
    for &d in path {
        let e = ins.step(&Pose { x_mm: 0.0, z_mm: 0.0, theta_x_deg: 0.0, theta_z_deg: 0.0, depth_mm: d });
        word(e.wrench.to_array()[1].to_bits());
        word(u32::from(e.phase.code()));
        word(u32::from(e.punctures));
        punctures += u32::from(e.punctures);
    }
    format!("{label} ticks={} punctures={punctures} digest={digest:016x}", path.len())
}

fn calibrated_skin(dir: &Path) -> PathBuf {
    let out = dir.join("skin.toml");
    let mut args: Vec<String> = vec!["calibrate".into(), "--trials".into()];
    args.extend((1..=3).map(|k| rig(&format!("skin_2mmps_0deg_needle2_trial{k}.csv"))));
    for a in ["--name", "skin", "--needle-diameter-mm", "1.27", "--write-on-miss", "--set", &shipped_set_arg()] {
        args.push(a.into());
    }
    args.extend([
        "--out".into(),
        out.to_string_lossy().into_owned(),
        "--figure".into(),
        dir.join("skin.svg").to_string_lossy().into_owned(),
    ]);
    let o = needle(&args);
    assert!(out.is_file() && dir.join("skin.spread.csv").is_file(), "stack and spread written: {}", show(&o));
    out
}

#[test]
fn tissue_files_and_their_draws_play_in_wasm_as_on_the_host() {
    let root = needle_stdx::workspace_root();
    let d = tempfile::tempdir().expect("tempdir");
    let skin = calibrated_skin(d.path());
    let draws = 3;
    let json = needle_explore::stacks_json::stacks_json(&[&skin], draws).unwrap_or_else(|e| panic!("{e:#}"));
    let file = json.get(0).expect("one stack");
    let drawn = file["drawn"].as_array().expect("drawn");
    assert_eq!(drawn.len(), draws as usize, "{file}");
    // each draw is `needle stack sample --seed K`'s file, and moves the fitted values
    let base = OwnedStack::load(&skin).unwrap_or_else(|e| panic!("{e:#}"));
    let path = depths(&base);
    let mut want = vec![host_line("skin file", &base, &path)];
    for seed in 1..=draws {
        let out = d.path().join(format!("again/skin_{seed}.toml"));
        std::fs::create_dir_all(out.parent().expect("parent")).expect("mkdir");
        let o =
            needle(&["stack", "sample", "--stack", &skin.to_string_lossy(), "--seed", &seed.to_string(), "--out", &out.to_string_lossy()]);
        assert!(o.status.success(), "{}", show(&o));
        let mut sampled = OwnedStack::load(&out).unwrap_or_else(|e| panic!("{e:#}"));
        sampled.name = base.name.clone();
        assert_ne!(sampled, base, "seed {seed} draws another tissue");
        let moved = drawn[(seed - 1) as usize]["values"].as_array().expect("values").iter().filter(|v| v["from"] != v["to"]).count();
        assert!(moved > 0, "seed {seed}: no value drawn: {}", drawn[(seed - 1) as usize]);
        want.push(host_line(&format!("skin seed={seed}"), &sampled, &path));
    }
    let (stacks_path, depths_path) = (d.path().join("stacks.json"), d.path().join("depths.json"));
    std::fs::write(&stacks_path, json.to_string()).expect("write stacks.json");
    std::fs::write(&depths_path, serde_json::to_string(&path).expect("depths")).expect("write depths.json");
    let wasm = needle_explore::wasm::build(&root.join("coeffs/default")).unwrap_or_else(|e| panic!("{e:#}"));
    let out = std::process::Command::new("node")
        .arg(root.join("host-tests/tests/explore/stack_files.mjs"))
        .args([&wasm, &stacks_path, &depths_path])
        .output()
        .expect("node must be installed (apt nodejs): the wasm check runs under it");
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "node: {stdout}{}", String::from_utf8_lossy(&out.stderr));
    println!("{stdout}");
    let got: Vec<String> = stdout.lines().map(str::to_string).collect();
    assert_eq!(got, want, "the page's wasm plays the tissue files differently from the host");
    assert!(want.iter().all(|l| !l.contains(" punctures=0 ")), "every tissue punctures on the path: {want:?}");
}
