//! Model files in the contract's format (coeffs/README.md) with made-up coefficients, for
//! the code generator's tests. Not a fitted model: they never go under coeffs/.

#![allow(dead_code)]

use std::fmt::Write as _;
use std::path::Path;

/// Component and sweep names and mirror parities in contract order (coeffs/README.md).
pub use needle_contract::{COMPONENTS, ODD, SWEEPS};

/// `[a, b, ...]` with each value's shortest round-trip f64 text.
pub fn list(values: &[f64]) -> String {
    format!("[{}]", values.iter().map(|v| format!("{v:?}")).collect::<Vec<_>>().join(", "))
}

/// `["0x3f800000", ...]`: the f32 bits of each value, as the format's `*_f32` fields.
pub fn list32(values: &[f64]) -> String {
    format!("[{}]", values.iter().map(|v| format!("\"{:#010x}\"", (*v as f32).to_bits())).collect::<Vec<_>>().join(", "))
}

/// One part of a made-up model: coefficients and the residuals (rms, max) to write.
pub struct Part<T> {
    /// The coefficients.
    pub coeffs: T,
    /// `residual_rms`, `residual_max`.
    pub residual: (f64, f64),
}

/// A model file: `header` lines first (format, set, fe_sha256, domain...), then a
/// `[[baseline]]` per component (`baseline(c)`) and a `[[matrix]]` per sweep and
/// component (`matrix(k, c)`, rows in order), with each part's f64 and f32 values.
pub fn model_text(
    header: &str,
    baseline: impl Fn(usize) -> Part<[f64; 5]>,
    matrix: impl Fn(usize, usize) -> Part<[[f64; 5]; 5]>,
) -> String {
    let mut s = String::new();
    let w = &mut s;
    let _ = writeln!(w, "{}", header.trim_end());
    for (c, name) in COMPONENTS.iter().enumerate() {
        let b = baseline(c);
        let _ = writeln!(w, "\n[[baseline]]\ncomponent = \"{name}\"");
        let _ = writeln!(w, "coeffs = {}\ncoeffs_f32 = {}", list(&b.coeffs), list32(&b.coeffs));
        let _ = writeln!(w, "residual_rms = {:?}\nresidual_max = {:?}", b.residual.0, b.residual.1);
    }
    for (k, sweep) in SWEEPS.iter().enumerate() {
        for (c, name) in COMPONENTS.iter().enumerate() {
            let m = matrix(k, c);
            let _ = writeln!(w, "\n[[matrix]]\nsweep = \"{sweep}\"\ncomponent = \"{name}\"\nodd = {}", ODD[k][c]);
            let _ = writeln!(w, "rows = [");
            for r in &m.coeffs {
                let _ = writeln!(w, "  {},", list(r));
            }
            let _ = writeln!(w, "]\nrows_f32 = [");
            for r in &m.coeffs {
                let _ = writeln!(w, "  {},", list32(r));
            }
            let _ = writeln!(w, "]\nresidual_rms = {:?}\nresidual_max = {:?}", m.residual.0, m.residual.1);
        }
    }
    s
}

/// The default model.toml's baseline and deviation matrices alone, as a paper-form file
/// (its `form` line and its `[coupled]` and `[[cross]]` entries left out, if any).
pub fn paper_default_text() -> String {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../coeffs/default/model.toml");
    let text = std::fs::read_to_string(&path).expect("coeffs/default/model.toml");
    let paper = text.find("\n[coupled]").map_or(text.as_str(), |i| &text[..i]);
    let mut s = String::new();
    for line in paper.lines().filter(|l| !l.starts_with("form = ")) {
        let _ = writeln!(s, "{line}");
    }
    s
}

/// [`paper_default_text`] with `form = "coupled"` and made-up cross terms (degree <= 3
/// in the pose, 2 in depth): a deterministic pattern of +-0.5 mN (forces) and +-30 mN*mm
/// (moments), about 5 % of the default set's peak Fy.
pub fn coupled_default_text() -> String {
    let mut k = 0u32;
    coupled_text(&paper_default_text(), |c, i| {
        k += 1;
        let size = if needle_contract::is_force(c) { 5e-4 } else { 3e-2 };
        size * (f64::from(k) * 0.7 + f64::from(i)).sin()
    })
}

/// `paper` (a paper-form model file) with `form = "coupled"` and a cross term for every
/// monomial of degree <= 3 with each component's parities, depth degree 2: coefficient
/// `i` (of `u^i`) of each term of component `c` is `coeff(c, i)`, called in file order.
pub fn coupled_text(paper: &str, mut coeff: impl FnMut(usize, u32) -> f64) -> String {
    let mut s = String::new();
    for line in paper.lines() {
        let _ = writeln!(s, "{line}");
        if line.starts_with("theta_max_deg") {
            let _ = writeln!(s, "form = \"coupled\"");
        }
    }
    let _ = writeln!(s, "\n[coupled]\nmax_degree = 3\ndepth_degree = 2\ntraining_runs = 0");
    let _ = writeln!(s, "cv_rms_pct = [0.1, 0.1, 0.1, 0.1, 0.1, 0.1]\nscale = [0.07, 0.07, 0.07, 4.2, 4.2, 4.2]");
    for (c, name) in COMPONENTS.iter().enumerate() {
        for e in needle_fit::cross_terms::monomials(c, 3) {
            let p: Vec<f64> = (0..3_u32).map(|i| coeff(c, i)).collect();
            let f64s: Vec<String> = p.iter().map(|v| format!("{v:?}")).collect();
            let f32s: Vec<String> = p.iter().map(|v| format!("\"{}\"", needle_fit::model_file::hex32(*v as f32))).collect();
            let _ = writeln!(
                s,
                "\n[[cross]]\ncomponent = \"{name}\"\nexponents = [{}, {}, {}, {}]\ncoeffs = [{}]\ncoeffs_f32 = [{}]",
                e[0],
                e[1],
                e[2],
                e[3],
                f64s.join(", "),
                f32s.join(", ")
            );
        }
    }
    s
}

/// A coupled model built to exercise every case of the evaluators' exact Horner trimming
/// (the library's `horner` module): the default model's coefficients with `+0.0` and
/// `-0.0` put where a trimmed evaluation would differ from the contract's if the `-0.0`
/// rule were wrong. Matrix (k, c) gets pattern `(k + c) % 4`:
///
/// 0. the default's rows (degree 1-4 in t, or all `+0.0`);
/// 1. rows 0-2 `[r0, r0, -0.0, +0, +0]` (a row that starts at `-0.0` after `+0.0`s), and
///    rows 3 and 4 `[-0.0, +0, ...]` and `+0.0` (the Horner in depth starts at `-0.0`);
/// 2. rows 0-3 `[-r0, -0.0, r0, +0, +0]` (the depth Horner of the rates by t starts at a
///    row whose `-0.0` at index 1 leads its rate), row 4 `+0.0`;
/// 3. rows 0-2 `[r1 - r2, r1, r2, +0, +0]`, rows 3 and 4 `+0.0` (plain trimming).
///
/// (`r_i` the default row's coefficients; every row vanishes at `t = -1`, as the format
/// requires.)
///
/// Baselines: fy the default's; the others `[-0.0, 0..]`, `[b0, b1, +0, -0.0, +0]`,
/// `[+0, +0, 1e-3, +0, +0]`, `[-0.0, -0.0, 0..]`, `[1e-3, -0.0, 0..]`. Cross terms (depth
/// degree 2) cycle through `[a, b, +0]`, `[a, +0, -0.0]`, `[+0, +0, -0.0]`, `[a, b, c]`.
///
/// my_nmm is made of signed zeros alone (baseline as above, every matrix's rows 0 and 1
/// `[-0.0, -0.0, 0..]` and `[-0.0, 0..]`, every cross term `[-0.0, -0.0, +0]`): its wrench
/// and rates are zeros whose signs follow the signs of `u` and `t` through every step
/// the contract takes, so a step left out that mattered shows as a flipped sign bit
/// (a sum with any nonzero addend would hide it). Not a fit.
pub fn signed_zeros_text() -> String {
    let paper = paper_default_text();
    let model = needle_fit::model_file::parse(&paper, Path::new("coeffs/default/model.toml")).expect("default model");
    let header: String = paper.lines().take_while(|l| !l.starts_with("[[baseline]]")).map(|l| format!("{l}\n")).collect();
    let baseline = |c: usize| {
        let [b0, b1, ..] = model.baseline[1].coeffs;
        let coeffs = match c {
            0 => [-0.0, 0.0, 0.0, 0.0, 0.0],
            1 => model.baseline[1].coeffs,
            2 => [b0, b1, 0.0, -0.0, 0.0],
            3 => [0.0, 0.0, 1e-3, 0.0, 0.0],
            4 => [-0.0, -0.0, 0.0, 0.0, 0.0],
            _ => [1e-3, -0.0, 0.0, 0.0, 0.0],
        };
        Part { coeffs, residual: (0.0, 0.0) }
    };
    let matrix = |k: usize, c: usize| {
        let rows = model.matrices[k][c].rows;
        let row = |i: usize| {
            let [r0, r1, r2, ..] = rows[i];
            match ((k + c) % 4, i) {
                _ if c == 4 => [[-0.0, -0.0, 0.0, 0.0, 0.0], [-0.0, 0.0, 0.0, 0.0, 0.0], [0.0; 5], [0.0; 5], [0.0; 5]][i],
                (0, _) => rows[i],
                (1, 0..=2) => [r0, r0, -0.0, 0.0, 0.0],
                (1, 3) => [-0.0, 0.0, 0.0, 0.0, 0.0],
                (2, 0..=3) => [-r0, -0.0, r0, 0.0, 0.0],
                // the constant that makes the f32 row exactly 0 at t = -1 (the fitter's rule)
                (3, 0..=2) => [f64::from(-needle_fit::model::f32_row_tail_at_minus_one(&[0.0, r1, r2, 0.0, 0.0])), r1, r2, 0.0, 0.0],
                _ => [0.0; 5],
            }
        };
        Part { coeffs: [row(0), row(1), row(2), row(3), row(4)], residual: (0.0, 0.0) }
    };
    let mut n = 0_u32;
    coupled_text(&model_text(&header, baseline, matrix), |c, i| {
        if i == 0 {
            n += 1;
        }
        let size = if needle_contract::is_force(c) { 5e-4 } else { 3e-2 };
        let a = size * (f64::from(n) * 0.7 + f64::from(i)).sin();
        match (n % 4, i) {
            _ if c == 4 => [-0.0, -0.0, 0.0][i as usize],
            (0, 2) | (1, 1) | (2, 0 | 1) => 0.0,
            (1 | 2, 2) => -0.0,
            _ => a,
        }
    })
}
