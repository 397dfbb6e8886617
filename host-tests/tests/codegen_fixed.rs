//! The fixed-point tables of `needle-codegen`: a model whose coefficients cannot be held
//! in the integer evaluator (every intermediate <= 2^30 micro-units) is refused with
//! `path:line: what is wrong`, naming the matrix (or the component's baseline), through
//! the library and through a real cargo build; and the generated tables obey the format
//! rules of coeffs/README.md.
use needle_codegen::{fixed, generate, parse_model_str};
use std::path::{Path, PathBuf};
use std::process::Command;

mod made_up_model;
use made_up_model::{model_text, Part};

/// A model in the contract's format (made-up coefficients, not a fit): baseline fy_n =
/// `base_fy`, matrix z/fy_n row 2 = `[a, a, 0, 0, 0]` (zero at t = -1), the rest small.
fn model(base_fy: f64, a: f64) -> String {
    let header = format!(
        "format = 1\nset = \"fixed-test\"\nfe_sha256 = \"{}\"\ndepth_max_mm = 6.0\nx_max_mm = 12.0\nz_max_mm = 12.0\ntheta_max_deg = 15.0",
        "cd".repeat(32)
    );
    let baseline =
        |c: usize| Part { coeffs: if c == 1 { [base_fy, 0.5, 0.0, 0.0, 0.0] } else { [0.125, 0.0, 0.0, 0.0, 0.0] }, residual: (0.0, 0.0) };
    let matrix = |k: usize, c: usize| {
        let row = |i: usize| if k == 1 && c == 1 && i == 2 { [a, a, 0.0, 0.0, 0.0] } else { [0.25, 0.25, 0.0, 0.0, 0.0] };
        Part { coeffs: [row(0), row(1), row(2), row(3), row(4)], residual: (0.0, 0.0) }
    };
    model_text(&header, baseline, matrix)
}

fn nth_line(text: &str, prefix: &str, nth: usize) -> usize {
    text.lines().enumerate().filter(|(_, l)| l.starts_with(prefix)).nth(nth).map(|(i, _)| i + 1).unwrap()
}

#[test]
fn formats_follow_the_rules() {
    let text = model(0.08, 0.001);
    let m = parse_model_str(&text, Path::new("m.toml")).unwrap_or_else(|e| panic!("{e}"));
    let t = needle_codegen::fixed_tables(&m, Path::new("m.toml")).unwrap_or_else(|e| panic!("{e}"));
    for (c, comp) in t.components.iter().enumerate() {
        for (k, rows) in comp.rows.iter().enumerate() {
            for (i, r) in rows.iter().enumerate() {
                assert!(r.bound <= fixed::LIMIT);
                assert_eq!(r.bound, r.coeffs.iter().map(|v| i64::from(*v).abs()).sum::<i64>());
                // the largest format that fits: one more fractional bit would not
                let row = m.matrices.iter().find(|x| x.component == c && x.sweep == k).unwrap().rows[i];
                if r.frac_bits < fixed::MAX_FRAC_BITS {
                    let finer: i64 = row.iter().map(|v| fixed::quantize(*v, r.frac_bits + 1).abs()).sum();
                    assert!(finer > fixed::LIMIT, "row {c}/{k}/{i}: Q{} also fits", r.frac_bits + 1);
                }
                assert_eq!(comp.shifts[k][i], r.frac_bits - comp.frac_bits);
            }
        }
        assert!(comp.horner_bound <= fixed::LIMIT);
        assert!(comp.error_bound.total() > 0.0);
    }
    // 0.25 N + 0.25 N t: sum = 0.5 N = 5e5 uN; 5e5 * 2^11 = 1.02e9 <= 2^30 < 5e5 * 2^12
    assert_eq!(t.components[0].rows[0][0].frac_bits, 11);
    assert_eq!(t.components[0].rows[0][0].coeffs[0], 250_000 << 11);
}

#[test]
fn a_row_too_large_is_refused_naming_the_matrix_and_line() {
    // 600 N + 600 N t: 1.2e9 uN > 2^30 even with no fractional bit
    let text = model(0.08, 600.0);
    let path = Path::new("/sets/huge/model.toml");
    let m = parse_model_str(&text, path).unwrap_or_else(|e| panic!("{e}"));
    let e = needle_codegen::fixed_tables(&m, path).expect_err("must not fit");
    let line = nth_line(&text, "[[matrix]]", 7); // matrix 7: z / fy_n
    assert_eq!(e.line, Some(line), "{e}");
    for w in ["matrix z/fy_n", "row u^2", "2^30", "does not fit"] {
        assert!(e.message.contains(w), "message lacks {w:?}: {e}");
    }
    assert!(e.to_string().starts_with(&format!("/sets/huge/model.toml:{line}: ")), "{e}");
}

#[test]
fn a_component_too_large_is_refused_naming_the_baseline() {
    // each row fits alone, but the baseline (1000 N) plus the rows exceed 2^30 uN
    let text = model(1000.0, 300.0);
    let path = Path::new("/sets/big/model.toml");
    let m = parse_model_str(&text, path).unwrap_or_else(|e| panic!("{e}"));
    let e = needle_codegen::fixed_tables(&m, path).expect_err("must not fit");
    let line = nth_line(&text, "[[baseline]]", 1);
    assert_eq!(e.line, Some(line), "{e}");
    assert!(e.message.contains("baseline fy_n") && e.message.contains("2^30"), "{e}");
}

/// Through `cargo build` of the library: `cargo::error=path:line: ...`, no panic.
#[test]
fn cargo_build_refuses_a_model_too_large_for_fixed_point() {
    let dir = tempfile::tempdir().unwrap();
    let set = dir.path().join("huge-set");
    std::fs::create_dir(&set).unwrap();
    let text = model(0.08, 600.0);
    let model_path = set.join("model.toml");
    std::fs::write(&model_path, &text).unwrap();
    let g = generate(&model_path, dir.path());
    assert!(g.is_err());
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    let workspace = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("..");
    let out = Command::new(cargo)
        .current_dir(&workspace)
        .args(["build", "-p", "needle-haptics", "--target-dir"])
        .arg(PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("codegen-build"))
        .env("NEEDLE_COEFFS", &set)
        .env_remove("CARGO_TARGET_DIR")
        .env_remove("RUSTFLAGS")
        .env_remove("CARGO_ENCODED_RUSTFLAGS")
        .output()
        .expect("run cargo");
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "the build must fail:\n{stderr}");
    let want = format!("{}:{}: matrix z/fy_n", model_path.display(), nth_line(&text, "[[matrix]]", 7));
    assert!(stderr.contains(&want), "cargo's output lacks {want:?}:\n{stderr}");
    assert!(!stderr.contains("panicked"), "{stderr}");
}
