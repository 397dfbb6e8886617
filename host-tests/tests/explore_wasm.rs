//! The explorer's wasm evaluator reproduces the set's golden vectors bit for bit: the
//! module `needle explore` serves (crates/wasm, built for wasm32-unknown-unknown with
//! the default set) replays every row of coeffs/default/golden-f32.csv under Node, through
//! the same glue the page uses (crates/explore/src/page/needle-wasm.mjs). Node and the wasm32
//! target are required (`.ci/test` installs both); missing, the test fails.

use needle_explore as explore;
use needle_stdx::workspace_root;
use std::process::Command;

#[test]
fn wasm_evaluator_reproduces_golden_f32_bit_for_bit() {
    let root = workspace_root();
    let set = root.join("coeffs/default");
    let wasm = explore::wasm::build(&set).expect("build the wasm evaluator");
    let golden = set.join("golden-f32.csv");
    let rows = std::fs::read_to_string(&golden).expect("golden-f32.csv").lines().count() - 1;
    assert!(rows > 1000, "{}: {rows} rows: the golden vectors are missing", golden.display());
    let out = Command::new("node")
        .arg(root.join("host-tests/tests/explore/golden.mjs"))
        .arg(&wasm)
        .arg(&golden)
        .output()
        .expect("node must be installed (apt nodejs): the wasm check runs under it");
    let stdout = String::from_utf8_lossy(&out.stdout);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "wasm evaluator differs from {}:\n{stdout}{stderr}", golden.display());
    assert!(stdout.starts_with(&format!("{rows} rows, 0 differ")), "unexpected report: {stdout}");
    println!("{stdout}");
}
