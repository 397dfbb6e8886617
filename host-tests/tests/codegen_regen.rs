//! The tables compiled into the library are exactly what `needle-codegen` generates from
//! the set the library was built with (unicode-ident style: regenerate and compare), and
//! the generated literals, bit comments and C header all carry the same f32 bits.
use needle_codegen::{generate, generate_unfitted, Generated};
use needle_haptics::model_info;
use std::path::Path;
use std::process::Command;

fn regenerate(out: &Path) -> Generated {
    let set = Path::new(model_info::SET_DIR);
    let model = set.join(needle_codegen::MODEL_FILE);
    let g = if model.is_file() {
        generate(&model, out).unwrap_or_else(|e| panic!("{e}"))
    } else {
        generate_unfitted(model_info::SET, out).unwrap_or_else(|e| panic!("{e}"))
    };
    assert_eq!(
        g.model.fitted,
        model_info::FITTED,
        "{} changed since the library was built (model.toml added or removed): rebuild",
        set.display()
    );
    g
}

#[test]
fn compiled_tables_match_a_fresh_generation() {
    let dir = tempfile::tempdir().unwrap();
    let g = regenerate(dir.path());
    assert!(
        g.rust == model_info::TABLES_RS,
        "the library's tables_f32.rs differs from a fresh generation from {}: stale build or a \
         non-deterministic generator",
        model_info::SET_DIR
    );
    assert!(g.c_header == model_info::C_HEADER, "the library's C header differs from a fresh generation");
    assert!(
        g.rust_fixed == needle_haptics::fixed::tables::SOURCE,
        "the library's tables_fixed.rs differs from a fresh generation from {}",
        model_info::SET_DIR
    );
    assert!(
        g.rust_unsolved == model_info::UNSOLVED_RS,
        "the library's unsolved.rs differs from a fresh generation from {}",
        model_info::SET_DIR
    );
    assert_eq!(g.unsolved.balls.len(), model_info::UNSOLVED_BALLS);
    assert_eq!(g.model.set, model_info::SET);
    assert_eq!(g.model.fe_sha256, model_info::FE_SHA256);
    // The numbers the evaluator uses, against the model file's f32 bits.
    let bits = |a: &[f32]| a.iter().map(|v| v.to_bits()).collect::<Vec<_>>();
    let flat_b: Vec<f32> = g.model.baseline_f32().iter().flatten().copied().collect();
    let lib_b: Vec<f32> = model_info::BASELINE.iter().flatten().copied().collect();
    assert_eq!(bits(&flat_b), bits(&lib_b), "BASELINE");
    let flat_d: Vec<f32> = g.model.deviation_f32().iter().flatten().flatten().flatten().copied().collect();
    let lib_d: Vec<f32> = model_info::DEVIATION.iter().flatten().flatten().flatten().copied().collect();
    assert_eq!(bits(&flat_d), bits(&lib_d), "DEVIATION");
    assert_eq!(model_info::ODD, needle_codegen::contract::ODD);
}

#[test]
fn generation_is_deterministic() {
    let a = tempfile::tempdir().unwrap();
    let b = tempfile::tempdir().unwrap();
    let (ga, gb) = (regenerate(a.path()), regenerate(b.path()));
    assert_eq!(ga.rust, gb.rust);
    assert_eq!(ga.c_header, gb.c_header);
    assert_eq!(ga.rust_fixed, gb.rust_fixed);
    assert!(!ga.rust.contains(a.path().to_str().unwrap()), "no paths in generated code");
}

/// Every `<literal>, // 0x........` line of the generated Rust: the literal parses to the
/// bits in its comment.
#[test]
fn rust_literals_round_trip_to_their_bit_comments() {
    let mut n = 0;
    for line in model_info::TABLES_RS.lines() {
        let Some((lit, comment)) = line.trim().split_once(", // 0x") else { continue };
        let want = u32::from_str_radix(&comment[..8], 16).unwrap();
        let got: f32 = lit.parse().unwrap_or_else(|e| panic!("{lit:?}: {e}"));
        assert_eq!(got.to_bits(), want, "{line}");
        n += 1;
    }
    assert_eq!(n, 6 * 5 + 24 * 25, "one literal per coefficient");
}

/// The C header compiles warning-free as C99 and its tables hold the library's bits.
#[test]
fn c_header_compiles_and_holds_the_same_bits() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("needle_coeffs.h"), model_info::C_HEADER).unwrap();
    let program = r#"
#include <stdio.h>
#include <string.h>
#include "needle_coeffs.h"
static void put(float v) { uint32_t b; memcpy(&b, &v, 4); printf("%08x\n", (unsigned)b); }
int main(void) {
    int c, k, i, j;
    for (c = 0; c < 6; c++) for (i = 0; i < 5; i++) put(NEEDLE_BASELINE[c][i]);
    for (k = 0; k < 4; k++) for (c = 0; c < 6; c++) for (i = 0; i < 5; i++) for (j = 0; j < 5; j++)
        put(NEEDLE_DEVIATION[k][c][i][j]);
    for (k = 0; k < 4; k++) put(NEEDLE_SWEEP_SCALE[k]);
    put(NEEDLE_ONE_THIRD); put(NEEDLE_X_MAX_MM); put(NEEDLE_DEPTH_MAX_MM);
    printf("%d %d %s\n", NEEDLE_COEFFS_FITTED, (int)NEEDLE_ODD[3][5], NEEDLE_COEFFS_SET);
    return NEEDLE_STATUS_ERROR == 0x80u ? 0 : 1;
}
"#;
    std::fs::write(dir.path().join("main.c"), program).unwrap();
    let exe = dir.path().join("dump");
    let cc = std::env::var("CC").unwrap_or_else(|_| "cc".into());
    let out = Command::new(&cc)
        .current_dir(dir.path())
        .args(["-std=c99", "-Wall", "-Wextra", "-Werror", "-pedantic", "-ffp-contract=off", "main.c", "-o"])
        .arg(&exe)
        .output()
        .unwrap_or_else(|e| panic!("cannot run the C compiler {cc:?} (set CC): {e}"));
    assert!(out.status.success(), "the header does not compile:\n{}", String::from_utf8_lossy(&out.stderr));
    let run = Command::new(&exe).output().unwrap();
    assert!(run.status.success());
    let text = String::from_utf8(run.stdout).unwrap();
    let mut want: Vec<String> = Vec::new();
    let hex = |v: f32| format!("{:08x}", v.to_bits());
    want.extend(model_info::BASELINE.iter().flatten().map(|v| hex(*v)));
    want.extend(model_info::DEVIATION.iter().flatten().flatten().flatten().map(|v| hex(*v)));
    want.extend([2.0f32 / 12.0, 2.0 / 12.0, 2.0 / 15.0, 2.0 / 15.0, 1.0 / 3.0].map(hex));
    want.extend([model_info::X_MAX_MM, model_info::DEPTH_MAX_MM].map(hex));
    want.push(format!("{} 1 {}", u8::from(model_info::FITTED), model_info::SET));
    assert_eq!(text.lines().collect::<Vec<_>>(), want);
}
