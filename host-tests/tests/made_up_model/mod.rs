//! Model files in the contract's format (coeffs/README.md) with made-up coefficients, for
//! the code generator's tests. Not a fitted model: they never go under coeffs/.

#![allow(dead_code)]

use std::fmt::Write as _;

/// Component names in contract order.
pub const COMPONENTS: [&str; 6] = ["fx_n", "fy_n", "fz_n", "mx_nmm", "my_nmm", "mz_nmm"];
/// Sweep names in contract order.
pub const SWEEPS: [&str; 4] = ["x", "z", "theta_x", "theta_z"];
/// Which (sweep, component) matrices are odd in the swept variable (coeffs/README.md).
pub const ODD: [[bool; 6]; 4] = [
    [true, false, false, false, true, true],
    [false, false, true, true, true, false],
    [false, false, true, true, true, false],
    [true, false, false, false, true, true],
];

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
