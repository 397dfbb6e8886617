//! A bad model file must be refused with `path:line: what is wrong`, at the right line,
//! never with a panic: through the `needle-codegen` library (every kind of fault), and
//! through a real cargo build of `needle-haptics` with `NEEDLE_COEFFS` pointing at a
//! broken set.
//!
//! The model files here are written by this test from arbitrary, made-up coefficients in
//! the contract's format, and then broken on purpose. They are not a fitted model and
//! never go under coeffs/.
use needle_codegen::{generate, parse_model, parse_model_str, CodegenError};
use std::path::{Path, PathBuf};
use std::process::Command;

mod made_up_model;
use made_up_model::{list32, model_text, Part};

/// A valid model file in the contract's format, with made-up coefficients. Every
/// deviation row vanishes at t = -1 exactly (dyadic values).
fn valid_model() -> String {
    let header = format!(
        "# made-up coefficients for the codegen error tests (not a fit)\nformat = 1\nset = \"codegen-test\"\nfe_sha256 = \"{}\"\ndepth_max_mm = 6.0\nx_max_mm = 12.0\nz_max_mm = 12.0\ntheta_max_deg = 15.0",
        "ab".repeat(32)
    );
    let baseline = |c: usize| Part { coeffs: [0.1 * (c as f64 + 1.0), 0.5, -0.25, 0.125, -0.0625], residual: (1.0e-4, 3.0e-4) };
    let matrix = |k: usize, c: usize| {
        let n = (k * 6 + c) as f64;
        let row = |i: usize| {
            let mut r = [0.0; 5];
            for (j, v) in r.iter_mut().enumerate().skip(1) {
                *v = (n + 1.0) * (i as f64 + 1.0) * (j as f64) / 64.0 * if j % 2 == 0 { 1.0 } else { -0.5 };
            }
            r[0] = -(-r[1] + r[2] - r[3] + r[4]);
            r
        };
        Part { coeffs: [row(0), row(1), row(2), row(3), row(4)], residual: (2.0e-3, 5.0e-3) }
    };
    model_text(&header, baseline, matrix)
}

/// 1-based line of the `nth` (0-based) line that starts with `prefix` (after indentation).
fn line_starting(text: &str, prefix: &str, nth: usize) -> usize {
    text.lines()
        .enumerate()
        .filter(|(_, l)| l.trim_start().starts_with(prefix))
        .nth(nth)
        .map(|(i, _)| i + 1)
        .unwrap_or_else(|| panic!("no line {nth} starting with {prefix:?}"))
}

/// Replaces line `line` (1-based) with `f(old line)`.
fn edit_line(text: &str, line: usize, f: impl Fn(&str) -> String) -> String {
    let mut out: Vec<String> = text.lines().map(str::to_string).collect();
    out[line - 1] = f(&out[line - 1]);
    out.join("\n") + "\n"
}

/// Line of the first line of matrix `n` (0-based) that starts with `prefix`.
fn matrix_line(text: &str, n: usize, prefix: &str) -> usize {
    let start = line_starting(text, "[[matrix]]", n);
    text.lines()
        .enumerate()
        .skip(start)
        .find(|(_, l)| l.trim_start().starts_with(prefix))
        .map(|(i, _)| i + 1)
        .unwrap_or_else(|| panic!("matrix {n} has no line starting with {prefix:?}"))
}

fn expect_error(text: &str, line: usize, words: &[&str]) -> CodegenError {
    let path = Path::new("/sets/broken/model.toml");
    let e = parse_model_str(text, path).expect_err("the model must be refused");
    assert_eq!(e.path, path, "{e}");
    assert_eq!(e.line, Some(line), "wrong line: {e}");
    for w in words {
        assert!(e.message.contains(w), "message lacks {w:?}: {e}");
    }
    let shown = e.to_string();
    assert!(shown.starts_with(&format!("/sets/broken/model.toml:{line}: ")), "{shown}");
    assert!(!e.message.contains('\n'), "one line: {e:?}");
    e
}

#[test]
fn the_valid_model_is_accepted_and_generates() {
    let text = valid_model();
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("model.toml");
    std::fs::write(&path, &text).unwrap();
    let g = generate(&path, dir.path()).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(g.model.set, "codegen-test");
    assert_eq!(g.model.matrices.len(), 24);
    assert!(g.rust.contains("pub const DEVIATION: [[[[f32; 5]; 5]; 6]; 4]"));
    assert!(g.c_header.contains("#ifndef NEEDLE_COEFFS_H"));
    assert_eq!(std::fs::read_to_string(dir.path().join("tables_f32.rs")).unwrap(), g.rust);
    assert_eq!(std::fs::read_to_string(dir.path().join("needle_coeffs.h")).unwrap(), g.c_header);
}

#[test]
fn malformed_toml_names_the_line() {
    let text = valid_model();
    let line = matrix_line(&text, 3, "odd =");
    let bad = edit_line(&text, line, |_| "odd = tru".to_string());
    expect_error(&bad, line, &[]);
    let line = line_starting(&text, "fe_sha256", 0);
    let bad = edit_line(&text, line, |_| "fe_sha256 = \"abc".to_string());
    expect_error(&bad, line, &[]);
}

#[test]
fn truncated_file_names_the_last_line() {
    let text = valid_model();
    // Cut in the middle of matrix 10's rows: a TOML syntax error at the end.
    let line = matrix_line(&text, 10, "rows =") + 2;
    let cut: String = text.lines().take(line).map(|l| format!("{l}\n")).collect();
    let cut = &cut[..cut.len() - 9];
    expect_error(cut, line, &["truncated?"]);
    // Cut cleanly after matrix 16: valid TOML, but 17 matrices.
    let end = line_starting(&text, "[[matrix]]", 17) - 1;
    let cut: String = text.lines().take(end).map(|l| format!("{l}\n")).collect();
    let last = end - 1; // the blank line before [[matrix]] 17 is dropped by the span
    expect_error(&cut, last, &["17 [[matrix]] entries", "24", "truncated"]);
}

#[test]
fn wrong_matrix_shapes_name_the_line() {
    let text = valid_model();
    // 4 rows: drop the last row of matrix 5's `rows`.
    let rows = matrix_line(&text, 5, "rows =");
    let bad: String = text.lines().enumerate().filter(|(i, _)| *i + 1 != rows + 5).map(|(_, l)| format!("{l}\n")).collect();
    expect_error(&bad, rows, &["matrix x/mz_nmm", "4 rows", "expected 5"]);
    // 6 columns: one more value in row 2 of matrix 7's `rows`.
    let line = matrix_line(&text, 7, "rows =") + 3;
    let bad = edit_line(&text, line, |l| l.replace("],", ", 0.0],"));
    expect_error(&bad, line, &["matrix z/fy_n", "rows[2]", "6 values", "expected 5"]);
    // 6 columns in rows_f32 only.
    let line = matrix_line(&text, 7, "rows_f32 =") + 1;
    let bad = edit_line(&text, line, |l| l.replace("],", ", \"0x00000000\"],"));
    expect_error(&bad, line, &["rows_f32[0]", "6 values"]);
    // A baseline with 4 coefficients.
    let line = line_starting(&text, "coeffs =", 2);
    let bad = edit_line(&text, line, |_| "coeffs = [0.3, 0.5, -0.25, 0.125]".to_string());
    expect_error(&bad, line, &["baseline fz_n", "4 values"]);
}

#[test]
fn nan_and_infinite_coefficients_name_the_line() {
    let text = valid_model();
    let line = matrix_line(&text, 12, "rows =") + 4;
    let bad = edit_line(&text, line, |l| {
        let (head, tail) = l.split_once(", ").unwrap();
        format!("{head}, nan, {}", tail.split_once(", ").unwrap().1)
    });
    expect_error(&bad, line, &["matrix theta_x/fx_n", "rows[3][1]", "NaN", "finite"]);
    let line = line_starting(&text, "coeffs =", 4);
    let bad = edit_line(&text, line, |_| "coeffs = [0.5, inf, -0.25, 0.125, -0.0625]".to_string());
    expect_error(&bad, line, &["baseline my_nmm", "coeffs[1]", "finite"]);
    let line = matrix_line(&text, 0, "residual_max");
    let bad = edit_line(&text, line, |_| "residual_max = nan".to_string());
    expect_error(&bad, line, &["residual_max", "finite"]);
}

#[test]
fn wrong_component_or_sweep_order_names_the_line() {
    let text = valid_model();
    // Swap the components of matrices 2 and 3 (x/fz_n, x/mx_nmm).
    let l2 = matrix_line(&text, 2, "component =");
    let l3 = matrix_line(&text, 3, "component =");
    let bad = edit_line(&edit_line(&text, l2, |_| "component = \"mx_nmm\"".into()), l3, |_| "component = \"fz_n\"".into());
    expect_error(&bad, l2, &["\"mx_nmm\"", "out of order", "expected \"fz_n\""]);
    // Baselines out of order.
    let l = line_starting(&text, "component =", 0);
    let bad = edit_line(&text, l, |_| "component = \"fy_n\"".into());
    expect_error(&bad, l, &["out of order", "expected \"fx_n\""]);
    // An unknown component name.
    let l = matrix_line(&text, 20, "component =");
    let bad = edit_line(&text, l, |_| "component = \"fq_n\"".into());
    expect_error(&bad, l, &["unknown"]);
    // Sweep-major order: matrix 6 must be sweep z.
    let l = matrix_line(&text, 6, "sweep =");
    let bad = edit_line(&text, l, |_| "sweep = \"theta_x\"".into());
    expect_error(&bad, l, &["sweep", "expected \"z\""]);
}

#[test]
fn hex_bits_that_are_not_the_nearest_f32_name_the_line() {
    let text = valid_model();
    // TOML integers read as f64 where the contract has a float.
    let l = line_starting(&text, "depth_max_mm", 0);
    let ints = edit_line(&text, l, |_| "depth_max_mm = 6".into());
    let l = line_starting(&ints, "coeffs =", 0);
    let ints = edit_line(&ints, l, |_| "coeffs = [0, 1, 0.0, 0.125, -0.0625]".into());
    let l = line_starting(&ints, "coeffs_f32 =", 0);
    let ints = edit_line(&ints, l, |_| format!("coeffs_f32 = {}", list32(&[0.0, 1.0, 0.0, 0.125, -0.0625])));
    parse_model_str(&ints, Path::new("m.toml")).unwrap_or_else(|e| panic!("{e}"));
    // One ulp off in matrix 9's rows_f32[1][2].
    let line = matrix_line(&text, 9, "rows_f32 =") + 2;
    let bad = edit_line(&text, line, |l| {
        let fields: Vec<&str> = l.trim().trim_end_matches("],").trim_start_matches('[').split(", ").collect();
        let bits = u32::from_str_radix(&fields[2][3..11], 16).unwrap() + 1;
        l.replace(fields[2], &format!("\"{bits:#010x}\""))
    });
    expect_error(&bad, line, &["matrix z/mx_nmm", "rows_f32[1][2]", "not the nearest f32"]);
    // A baseline hex string in the wrong form.
    let line = line_starting(&text, "coeffs_f32 =", 1);
    let bad = edit_line(&text, line, |l| l.replacen("\"0x", "\"0X", 1));
    expect_error(&bad, line, &["coeffs_f32[0]", "8 lower-case hex digits"]);
}

#[test]
fn other_contract_violations_name_the_line() {
    let text = valid_model();
    let l = line_starting(&text, "format", 0);
    expect_error(&edit_line(&text, l, |_| "format = 2".into()), l, &["format"]);
    let l = line_starting(&text, "x_max_mm", 0);
    expect_error(&edit_line(&text, l, |_| "x_max_mm = 10.0".into()), l, &["x_max_mm", "12"]);
    let l = line_starting(&text, "fe_sha256", 0);
    expect_error(&edit_line(&text, l, |_| "fe_sha256 = \"abc\"".into()), l, &["64 lower-case hex"]);
    let l = matrix_line(&text, 4, "odd =");
    expect_error(&edit_line(&text, l, |_| "odd = false".into()), l, &["matrix x/my_nmm", "odd"]);
    let l = matrix_line(&text, 1, "residual_rms");
    expect_error(&edit_line(&text, l, |_| "residual_rms = -1.0".into()), l, &["residual", ">= 0"]);
    let l = matrix_line(&text, 1, "residual_rms");
    expect_error(&edit_line(&text, l, |_| "residual_rmx = 1.0".into()), l, &["unknown field `residual_rmx`"]);
    // A deviation row that is not zero at t = -1 (constant column not shifted).
    let l = matrix_line(&text, 8, "rows =") + 1;
    let bad = edit_line(&text, l, |row| row.replacen('[', "[1.0 + ", 1));
    assert!(parse_model_str(&bad, Path::new("m.toml")).is_err());
    let bad = edit_line(&text, l, |row| {
        let (first, rest) = row.trim().trim_start_matches('[').split_once(", ").unwrap();
        let v: f64 = first.parse().unwrap();
        format!("  [{:?}, {rest}", v + 1.0)
    });
    let bad = edit_line(&bad, matrix_line(&text, 8, "rows_f32 =") + 1, |row| {
        let (first, rest) = row.trim().trim_start_matches('[').split_once(", ").unwrap();
        let v = f32::from_bits(u32::from_str_radix(&first[3..11], 16).unwrap()) + 1.0;
        format!("  [\"{:#010x}\", {rest}", v.to_bits())
    });
    expect_error(&bad, l, &["matrix z/fz_n", "rows_f32[0]", "t = -1", "in f32"]);
    // 25 matrices: the extra one is named.
    let extra = text[text.rfind("[[matrix]]").unwrap()..].to_string();
    let bad = format!("{text}\n{extra}");
    let l = line_starting(&bad, "[[matrix]]", 24);
    expect_error(&bad, l, &["25 [[matrix]] entries", "exactly 24"]);
}

/// The first value of row `l` (1-based line of `[f64, ...]`) and of its `rows_f32` line
/// `l32`, replaced by `f(value as f32)` in both (so the hex stays the nearest f32).
fn edit_row_constant(text: &str, l: usize, l32: usize, f: impl Fn(f32) -> f32) -> String {
    let row = text.lines().nth(l - 1).unwrap();
    let (first, rest) = row.trim().trim_start_matches('[').split_once(", ").unwrap();
    let v = f(first.parse::<f64>().unwrap() as f32);
    let bad = edit_line(text, l, |_| format!("  [{:?}, {rest}", f64::from(v)));
    edit_line(&bad, l32, |row| {
        let (_, rest) = row.trim().trim_start_matches('[').split_once(", ").unwrap();
        format!("  [\"{:#010x}\", {rest}", v.to_bits())
    })
}

#[test]
fn a_deviation_row_not_exactly_zero_at_sweep_zero_in_f32_names_the_line() {
    let text = valid_model();
    let (l, l32) = (matrix_line(&text, 8, "rows =") + 2, matrix_line(&text, 8, "rows_f32 =") + 2);
    // One f32 step off in the constant: within 2^-21 of the row's size in f64 (the f64
    // tolerance), but the f32 Horner at t = -1 is no longer exactly 0.
    let bad = edit_row_constant(&text, l, l32, |v| f32::from_bits(v.to_bits() + 1));
    let e = expect_error(&bad, l, &["matrix z/fz_n", "rows_f32[1]", "t = -1", "in f32, not 0"]);
    assert!(!e.message.contains("in f64"), "{e}");
    // The unchanged row is accepted: the error is that one step.
    assert!(parse_model_str(&edit_row_constant(&text, l, l32, |v| v), Path::new("m.toml")).is_ok());
    // Exactly 0 in f32 (1e-46 rounds to +0.0) but not within 2^-21 of 0 in f64.
    let bad = edit_line(&text, l, |_| "  [0.0, 1e-46, 0.0, 0.0, 0.0],".into());
    let bad = edit_line(&bad, l32, |_| format!("  [{}],", ["\"0x00000000\""; 5].join(", ")));
    expect_error(&bad, l, &["matrix z/fz_n", "rows[1]", "t = -1", "in f64", "2^-21"]);
}

#[test]
fn an_unreadable_file_names_the_file() {
    let e = parse_model(Path::new("/nonexistent/set/model.toml")).expect_err("missing file");
    assert_eq!(e.line, None);
    assert!(e.to_string().starts_with("/nonexistent/set/model.toml: cannot read"), "{e}");
}

// ---- real cargo builds of the library ----

struct Build {
    ok: bool,
    stderr: String,
}

/// `cargo build -p needle-haptics` of this workspace with `NEEDLE_COEFFS=set`, in a
/// target folder of its own (kept between runs, so only the first build compiles the
/// dependencies).
fn cargo_build_library(set: &Path) -> Build {
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    let workspace = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("..");
    let target_dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("codegen-build");
    let out = Command::new(cargo)
        .current_dir(&workspace)
        .args(["build", "-p", "needle-haptics", "--target-dir"])
        .arg(&target_dir)
        .env("NEEDLE_COEFFS", set)
        .env("RUST_BACKTRACE", "1")
        .env_remove("CARGO_TARGET_DIR")
        .env_remove("RUSTFLAGS")
        .env_remove("CARGO_ENCODED_RUSTFLAGS")
        .output()
        .expect("run cargo");
    Build { ok: out.status.success(), stderr: String::from_utf8_lossy(&out.stderr).into_owned() }
}

#[test]
fn cargo_build_fails_cleanly_on_a_broken_set() {
    let dir = tempfile::tempdir().unwrap();
    let set = dir.path().join("broken-set");
    std::fs::create_dir(&set).unwrap();
    let text = valid_model();
    let line = matrix_line(&text, 12, "rows =") + 4;
    // row 3 of matrix theta_x/fx_n becomes [nan, <its other four values>]
    let bad = edit_line(&text, line, |l| {
        let body = l.trim().trim_start_matches('[').trim_end_matches("],");
        let vals: Vec<&str> = body.split(", ").collect();
        format!("  [nan, {}],", vals[1..5].join(", "))
    });
    let model = set.join("model.toml");
    std::fs::write(&model, &bad).unwrap();
    // (the library parses it the same way as the build)
    let e = parse_model(&model).expect_err("broken");
    assert_eq!(e.line, Some(line), "{e}");

    let b = cargo_build_library(&set);
    assert!(!b.ok, "the build must fail:\n{}", b.stderr);
    let want = format!("{}:{line}: ", model.display());
    assert!(b.stderr.contains(&want), "cargo's output lacks {want:?}:\n{}", b.stderr);
    assert!(b.stderr.contains("NaN"), "{}", b.stderr);
    assert!(!b.stderr.contains("panicked"), "the build script panicked:\n{}", b.stderr);
    assert!(!b.stderr.contains("stack backtrace"), "{}", b.stderr);

    // A set folder that does not exist.
    let b = cargo_build_library(&dir.path().join("no-such-set"));
    assert!(!b.ok);
    assert!(b.stderr.contains("no-such-set: no such set folder"), "{}", b.stderr);
    assert!(!b.stderr.contains("panicked"), "{}", b.stderr);

    // A new set without model.toml builds, unfitted, with a warning.
    let empty = dir.path().join("new-set");
    std::fs::create_dir(&empty).unwrap();
    let b = cargo_build_library(&empty);
    assert!(b.ok, "an unfitted set must build:\n{}", b.stderr);
    assert!(b.stderr.contains("no model.toml yet"), "{}", b.stderr);

    // The same set once fitted (here: the valid made-up model) builds without it.
    std::fs::write(empty.join("model.toml"), &text).unwrap();
    let b = cargo_build_library(&empty);
    assert!(b.ok, "{}", b.stderr);
    assert!(!b.stderr.contains("no model.toml yet"), "{}", b.stderr);
}
