//! The library's f32 evaluator against the golden vectors the fitter wrote from its own,
//! independent implementation of the contract (coeffs/README.md): every row, bit for bit.
//!
//! The golden file is `<set>/golden-f32.csv` of the set compiled into the library
//! (`NEEDLE_COEFFS`, default coeffs/default). A missing file is a failure, never a skip:
//! it means `needle fit` has not been run on that set.
use needle_haptics::{model_info, wrench, Pose};
use std::path::Path;

use needle_contract::COMPONENTS;

/// `0x` and 8 lower-case hex digits.
fn f32_bits(field: &str, line: usize) -> u32 {
    needle_codegen::parse_bits(field).unwrap_or_else(|| panic!("golden-f32.csv:{line}: {field:?} is not 0x and 8 lower-case hex digits"))
}

fn status_bits(field: &str, line: usize) -> u8 {
    let ok = field.len() == 4 && field.starts_with("0x") && field[2..].chars().all(|c| c.is_ascii_digit() || ('a'..='f').contains(&c));
    assert!(ok, "golden-f32.csv:{line}: status {field:?} is not 0x and 2 lower-case hex digits");
    u8::from_str_radix(&field[2..], 16).unwrap()
}

/// Equal as the contract demands: NaN matches NaN (any payload), anything else by bits
/// (so +0.0 and -0.0 differ).
fn same(expected: u32, got: f32) -> bool {
    let e = f32::from_bits(expected);
    if e.is_nan() {
        got.is_nan()
    } else {
        got.to_bits() == expected
    }
}

#[test]
fn library_matches_golden_vectors_bit_for_bit() {
    let path = Path::new(model_info::SET_DIR).join("golden-f32.csv");
    if !model_info::FITTED {
        panic!(
            "the library was built without a fitted model: {} has no model.toml. Run \
             `needle fit --set {}` (it writes model.toml and golden-f32.csv), then rerun the tests",
            model_info::SET_DIR,
            model_info::SET_DIR
        );
    }
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| {
        panic!(
            "{}: cannot read the golden vectors ({e}). `needle fit --set {}` writes them \
             with model.toml; this test never skips",
            path.display(),
            model_info::SET_DIR
        )
    });
    let mut lines = text.lines();
    assert_eq!(lines.next(), Some(needle_fit::golden::float32::header().as_str()), "{}:1: unexpected header", path.display());

    let mut rows = 0usize;
    let mut mismatches = Vec::new();
    for (n, line) in lines.enumerate() {
        let line_no = n + 2;
        if line.is_empty() {
            continue;
        }
        let fields: Vec<&str> = line.split(',').collect();
        assert_eq!(fields.len(), 12, "{}:{line_no}: expected 12 fields, found {}", path.display(), fields.len());
        let p: Vec<f32> = fields[..5].iter().map(|f| f32::from_bits(f32_bits(f, line_no))).collect();
        let want_status = status_bits(fields[5], line_no);
        let want: Vec<u32> = fields[6..].iter().map(|f| f32_bits(f, line_no)).collect();
        let pose = Pose { x_mm: p[0], z_mm: p[1], theta_x_deg: p[2], theta_z_deg: p[3], depth_mm: p[4] };
        let got = wrench(&pose);
        rows += 1;

        let mut diffs = Vec::new();
        if got.status.bits() != want_status {
            diffs.push(format!("status want {want_status:#04x} got {:#04x}", got.status.bits()));
        }
        for ((name, w), g) in COMPONENTS.iter().zip(&want).zip(got.wrench.to_array()) {
            if !same(*w, g) {
                diffs.push(format!("{name} want {w:#010x} ({:?}) got {:#010x} ({g:?})", f32::from_bits(*w), g.to_bits()));
            }
        }
        if !diffs.is_empty() {
            mismatches.push(format!("line {line_no}: pose {pose:?}: {}", diffs.join("; ")));
        }
    }
    assert!(rows >= 2000, "{}: only {rows} golden rows; the contract asks for at least 2,000", path.display());
    if !mismatches.is_empty() {
        let first: Vec<&String> = mismatches.iter().take(10).collect();
        panic!(
            "{} of {rows} golden rows of {} differ from the library; first ones:\n{}",
            mismatches.len(),
            path.display(),
            first.iter().map(|s| s.as_str()).collect::<Vec<_>>().join("\n")
        );
    }
    println!("{rows} golden rows of {} match bit for bit", path.display());
}
