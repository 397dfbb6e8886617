//! The fixed-point tables (coeffs/README.md, "Fixed-point evaluation"): the Q format of
//! every row polynomial and of every component's accumulator, chosen from the f64
//! coefficients so that no intermediate of the integer evaluation can exceed
//! [`LIMIT`] anywhere in the domain (exact integer interval bounds), the integer
//! coefficients, and the error bound of the integer evaluation against the f64
//! evaluation of the same model.
//!
//! Everything here is exact integer arithmetic on the quantised coefficients except
//! [`quantize`] (one specified f64 rounding chain) and the error bound (f64, rounded up
//! by a safety factor), so a second implementation of the rules in coeffs/README.md
//! picks the same formats and integers.
use crate::contract::{COMPONENTS, SWEEPS};
use crate::error::CodegenError;
use crate::model::Model;
use needle_contract::COMPONENT_COUNT;
use needle_contract::{DEGREE, TERMS};
use std::path::Path;

/// Fractional bits of the fixed-point pose inputs (Q16.16: mm or degrees times 65536).
pub const POSE_FRAC_BITS: u32 = 16;
/// Fractional bits of the normalised inputs `U`, `T_k` (Q15, in `[-32768, 32768]`).
pub const NORM_FRAC_BITS: u32 = 15;
/// The normalisation divisors of depth, sweeps and cross inputs: the contract's (see
/// `needle_contract::FIXED_DEPTH_DIVISOR` and the others).
pub use needle_contract::{
    FIXED_CROSS_DIVISORS as CROSS_DIVISORS, FIXED_DEPTH_DIVISOR as DEPTH_DIVISOR, FIXED_SWEEP_DIVISORS as SWEEP_DIVISORS,
};
/// Every intermediate of the integer evaluation has a magnitude of at most `2^30`.
pub const LIMIT: i64 = 1 << 30;
/// The fixed-point stiffness differentiates coefficients shifted right by
/// `R = min(MAX_RATE_SHIFT, G)` (`A_i >> R`, `P_j >> R`): a derivative's coefficients
/// `i * a_i` sum to at most 4 times the polynomial's, so the rates are computed in
/// Q(G - R) and stay within [`LIMIT`] (coeffs/README.md, "Fixed-point stiffness").
pub const MAX_RATE_SHIFT: u32 = 3;
/// Largest number of fractional bits of any format.
pub const MAX_FRAC_BITS: u32 = 30;
/// Output unit: micro-newtons and micro-newton millimetres (coefficients are scaled by 10^6).
pub const OUTPUT_SCALE: f64 = 1e6;

/// The quantised coefficient `round(c * 10^6 * 2^f)`: one f64 multiplication by 10^6
/// (round to nearest even), an exact scaling by `2^f`, then rounding to the nearest
/// integer, ties away from zero (saturating at the i64 range, far beyond [`LIMIT`]).
#[must_use]
pub fn quantize(c: f64, frac_bits: u32) -> i64 {
    let scaled = c * OUTPUT_SCALE;
    (scaled * (1u64 << frac_bits) as f64).round() as i64
}

/// One row polynomial `r(t) = sum_j P[j] t^j` in Q(`frac_bits`) micro-units.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct FixedRow {
    /// Integer coefficients; `coeffs[j]` multiplies `t^j`.
    pub coeffs: [i32; TERMS],
    /// Fractional bits `f` of the row (its value is `r * 2^-f` micro-units).
    pub frac_bits: u32,
    /// `sum_j |coeffs[j]|`: bound of every Horner intermediate of the row over `|t| <= 1`.
    pub bound: i64,
}

/// One cross term of the coupled form in fixed point: `A_i += (P[i] * M >> 15) >> shift`
/// with `M` the Q15 monomial of `exponents`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct FixedCross {
    /// Exponents of `(xi, zeta, alpha, beta)`.
    pub exponents: [u8; 4],
    /// Integer coefficients in Q(`frac_bits`) micro-units; `coeffs[i]` goes to `A_i`.
    pub coeffs: Vec<i32>,
    /// Fractional bits `F` of the term: the largest in `0..=30` with every `|P[i]| <= 2^30`.
    pub frac_bits: u32,
    /// `frac_bits - G` of the component (>= 0).
    pub shift: u32,
    /// 1-based line of the `[[cross]]` entry.
    pub line: usize,
}

/// One wrench component: its 20 row polynomials, the shifts that align them to the
/// component's accumulator format, the baseline in that format, and the bounds.
#[derive(Debug, Clone, PartialEq)]
pub struct FixedComponent {
    /// `rows[k][i]`: row `i` (power of u) of sweep `k`'s deviation matrix.
    pub rows: [[FixedRow; TERMS]; 4],
    /// `shifts[k][i] = rows[k][i].frac_bits - frac_bits` (>= 0).
    pub shifts: [[u32; TERMS]; 4],
    /// Baseline coefficients in Q(`frac_bits`); `baseline[i]` multiplies `u^i`.
    pub baseline: [i32; TERMS],
    /// Fractional bits `G` of the accumulator `A_i` and of the Horner in `u`.
    pub frac_bits: u32,
    /// Bound of `|A_i|` (every partial sum) per `i`.
    pub a_bounds: [i64; TERMS],
    /// `sum_i a_bounds[i]`: bound of every intermediate of the Horner in `u`.
    pub horner_bound: i64,
    /// Error bound of the integer result against the f64 evaluation, in micro-units.
    pub error_bound: ErrorBound,
    /// The coupled form's cross terms of this component, in file order (empty for the
    /// paper form).
    pub cross: Vec<FixedCross>,
    /// `R = min(MAX_RATE_SHIFT, frac_bits)`: the stiffness's coefficient shift.
    pub rate_shift: u32,
    /// `rate_rows[k][i]` (sweeps x and z): the t-derivative of row `rows[k][i]`,
    /// `[(j + 1) * (P[j + 1] >> R)]` for `j = 0..4`, in Q(f - R).
    pub rate_rows: [[[i32; DEGREE]; TERMS]; 2],
    /// Bounds of the stiffness's Horner intermediates: by depth, by x, by z (each
    /// `<= LIMIT`, checked by [`fixed_formats`]).
    pub rate_bounds: [i64; 3],
}

/// The fixed-point tables of a model.
#[derive(Debug, Clone, PartialEq)]
pub struct FixedTables {
    /// One entry per component, contract order.
    pub components: [FixedComponent; COMPONENT_COUNT],
}

/// The largest `f` in `0..=MAX_FRAC_BITS` whose quantised row fits: `sum_j |q(c_j, f)| <= LIMIT`.
fn choose_row(c: &[f64; TERMS]) -> Option<FixedRow> {
    (0..=MAX_FRAC_BITS).rev().find_map(|f| {
        let q = c.map(|v| quantize(v, f));
        let bound = q.iter().map(|v| i128::from(*v).abs()).sum::<i128>();
        (bound <= i128::from(LIMIT)).then(|| FixedRow { coeffs: q.map(|v| v as i32), frac_bits: f, bound: bound as i64 })
    })
}

/// The largest `f` in `0..=MAX_FRAC_BITS` with every `|q(c_i, f)| <= LIMIT`: a cross
/// term's format (its products `P[i] * M >> 15` are then within `LIMIT` too, `|M| <= 2^15`).
fn choose_cross(c: &[f64]) -> Option<(u32, Vec<i32>)> {
    (0..=MAX_FRAC_BITS).rev().find_map(|f| {
        let q: Vec<i64> = c.iter().map(|v| quantize(*v, f)).collect();
        q.iter().all(|v| v.unsigned_abs() <= LIMIT as u64).then(|| (f, q.iter().map(|v| *v as i32).collect()))
    })
}

/// `ceil(s / 2^shift)` for `s >= 0`: the bound of `|r >> shift|` when `|r| <= s`.
fn shifted_bound(s: i64, shift: u32) -> i64 {
    (s + (1i64 << shift) - 1) >> shift
}

/// `(a_bounds, horner_bound, baseline)` of a component at accumulator format `g`.
fn component_bounds(rows: &[[FixedRow; TERMS]; 4], cross: &[FixedCross], base: &[f64; TERMS], g: u32) -> ([i64; TERMS], i64, [i64; TERMS]) {
    let baseline = base.map(|b| quantize(b, g));
    let mut a = [0i64; TERMS];
    for (i, ai) in a.iter_mut().enumerate() {
        let mut s = i128::from(baseline[i]).abs();
        for row in rows {
            s += i128::from(shifted_bound(row[i].bound, row[i].frac_bits - g));
        }
        for x in cross {
            let p = x.coeffs.get(i).map_or(0, |v| i64::from(*v).abs());
            s += i128::from(shifted_bound(p, x.frac_bits - g));
        }
        *ai = s.min(i128::from(i64::MAX)) as i64;
    }
    let total = a.iter().map(|v| i128::from(*v)).sum::<i128>().min(i128::from(i64::MAX)) as i64;
    (a, total, baseline)
}

/// The t-derivative of a row for the fixed-point stiffness: `(j + 1) * (p[j + 1] >> r)`
/// (`r <= 3`), `None` when a coefficient would leave [`LIMIT`] (`r < 3` only).
fn rate_row(p: &[i32; TERMS], r: u32) -> Option<[i32; DEGREE]> {
    let d: [i64; DEGREE] = std::array::from_fn(|j| (j as i64 + 1) * i64::from(p[j + 1] >> r));
    d.iter().all(|v| v.abs() <= LIMIT).then(|| d.map(|v| v as i32))
}

/// The bounds of every intermediate of the fixed-point stiffness (coeffs/README.md,
/// "Fixed-point stiffness"), `[by depth, by x, by z]`:
/// - by depth: the Horner of `E_i = (i + 1) * (A_(i+1) >> r)` is bounded by `sum |E_i|`,
///   `|A_i >> r| <= ceil(a_bounds[i] / 2^r)`;
/// - by x (z): per `i`, the row's rate Horner `sum_j |rate_rows[k][i][j]|` shifted by
///   `shifts[k][i]`, plus per cross term with exponent `e >= 1` of that input
///   `e * ceil(ceil(|P[i]| / 2^r) / 2^(shift + 1))`; the Horner in `u` of those sums is
///   bounded by their total (each row's own Horner by its coefficient sum, below
///   `LIMIT` for `r = 3` by construction: `4 * 2^27`).
fn rate_bounds(
    a_bounds: &[i64; TERMS],
    r: u32,
    rate_rows: &[[[i32; DEGREE]; TERMS]; 2],
    shifts: &[[u32; TERMS]; 4],
    cross: &[FixedCross],
) -> [i64; 3] {
    let depth = a_bounds.iter().enumerate().skip(1).map(|(i, a)| i as i64 * shifted_bound(*a, r)).sum();
    let along = |k: usize| -> i64 {
        let mut total = 0i64;
        for i in 0..5 {
            let row: i64 = rate_rows[k][i].iter().map(|p| i64::from(*p).abs()).sum();
            total += shifted_bound(row, shifts[k][i]);
            for x in cross {
                let e = i64::from(x.exponents[k]);
                let p = x.coeffs.get(i).map_or(0, |v| i64::from(*v).abs());
                if e > 0 {
                    total += e * shifted_bound(shifted_bound(p, r), x.shift + 1);
                }
            }
        }
        total
    };
    [depth, along(0), along(1)]
}

/// Chooses every format of `model` and quantises its coefficients; the error bounds are
/// left at zero for [`fixed_tables`](crate::fixed_bound::fixed_tables) to fill in.
///
/// # Errors
/// A row polynomial or a component cannot be represented within [`LIMIT`] even with
/// no fractional bits (coefficients of the order of 1,000 N or N·mm); the error names
/// the matrix (or baseline), its line in `model_path` and the bound that is exceeded.
pub fn fixed_formats(model: &Model, model_path: &Path) -> Result<FixedTables, CodegenError> {
    let at = |line: usize, message: String| CodegenError { path: model_path.to_path_buf(), line: (line > 0).then_some(line), message };
    let mut components = Vec::with_capacity(COMPONENT_COUNT);
    for (c, base) in model.baseline.iter().enumerate() {
        let rows = fixed_rows(model, c, &at)?;
        let cross = fixed_cross(model, c, &at)?;
        components.push(fixed_component(c, rows, cross, base, &at)?);
    }
    let components: [FixedComponent; COMPONENT_COUNT] =
        components.try_into().map_err(|_| at(0, format!("the model does not have {COMPONENT_COUNT} components")))?;
    Ok(FixedTables { components })
}

/// `CodegenError` at a line of model.toml (0: the file).
type At<'p> = dyn Fn(usize, String) -> CodegenError + 'p;

/// Component `c`'s row polynomials `[sweep][i]`, each in its own format.
fn fixed_rows(model: &Model, c: usize, at: &At<'_>) -> Result<[[FixedRow; TERMS]; 4], CodegenError> {
    let zero_row = FixedRow { coeffs: [0; TERMS], frac_bits: 0, bound: 0 };
    let mut rows = [[zero_row; TERMS]; 4];
    for m in model.matrices.iter().filter(|m| m.component == c) {
        for (i, row) in m.rows.iter().enumerate() {
            rows[m.sweep][i] = choose_row(row).ok_or_else(|| {
                let sum: f64 = row.iter().map(|v| v.abs()).sum();
                at(
                    m.line,
                    format!(
                        "matrix {}/{}: row u^{i} does not fit the fixed-point evaluator: sum_j |rows[{i}][j]| = {sum:e} {}, which is {:.0} micro-units even with 0 fractional bits; every integer intermediate is limited to 2^30 = {LIMIT} micro-units (1073.7 N or N*mm)",
                        SWEEPS[m.sweep],
                        COMPONENTS[c],
                        crate::contract::UNITS[c],
                        sum * OUTPUT_SCALE
                    ),
                )
            })?;
        }
    }
    Ok(rows)
}

/// Component `c`'s cross terms, each in its own format (shift set by [`fixed_component`]).
fn fixed_cross(model: &Model, c: usize, at: &At<'_>) -> Result<Vec<FixedCross>, CodegenError> {
    let mut cross = Vec::new();
    for t in model.cross.iter().filter(|t| t.component == c) {
        let (frac_bits, coeffs) = choose_cross(&t.coeffs).ok_or_else(|| {
            at(
                t.line,
                format!(
                    "cross {} {:?}: a coefficient does not fit the fixed-point evaluator: |coeffs| up to {:e} {}, over 2^30 = {LIMIT} micro-units even with 0 fractional bits",
                    COMPONENTS[c],
                    t.exponents,
                    t.coeffs.iter().map(|v| v.abs()).fold(0.0, f64::max),
                    crate::contract::UNITS[c]
                ),
            )
        })?;
        cross.push(FixedCross { exponents: t.exponents, coeffs, frac_bits, shift: 0, line: t.line });
    }
    Ok(cross)
}

/// Component `c` with the largest accumulator format its bounds allow, the alignment
/// shifts and the stiffness's rate rows.
fn fixed_component(
    c: usize,
    rows: [[FixedRow; TERMS]; 4],
    mut cross: Vec<FixedCross>,
    base: &crate::model::Baseline,
    at: &At<'_>,
) -> Result<FixedComponent, CodegenError> {
    let max_g = rows.iter().flatten().map(|r| r.frac_bits).chain(cross.iter().map(|x| x.frac_bits)).min().unwrap_or(MAX_FRAC_BITS);
    let chosen = (0..=max_g).rev().find_map(|g| {
        let (a, total, baseline) = component_bounds(&rows, &cross, &base.coeffs, g);
        (total <= LIMIT).then_some((g, a, total, baseline))
    });
    let Some((g, a_bounds, horner_bound, baseline)) = chosen else {
        let (_, total, _) = component_bounds(&rows, &cross, &base.coeffs, 0);
        return Err(at(
            base.line,
            format!(
                "baseline {0}: component {0} does not fit the fixed-point evaluator: the baseline plus the four deviations (matrices x/{0} .. theta_z/{0}) and its cross terms can reach {total} micro-units ({1}) in the domain even with 0 fractional bits, over the limit 2^30 = {LIMIT} of every integer intermediate",
                COMPONENTS[c],
                crate::contract::UNITS[c]
            ),
        ));
    };
    let shifts = rows.map(|r| r.map(|row| row.frac_bits - g));
    for x in &mut cross {
        x.shift = x.frac_bits - g;
    }
    let rate_shift = g.min(MAX_RATE_SHIFT);
    let [rows_x, rows_z, _, _] = &rows;
    let rate_of = |rows: &[FixedRow; TERMS]| -> Option<[[i32; DEGREE]; TERMS]> {
        let r: Vec<[i32; DEGREE]> = rows.iter().map(|row| rate_row(&row.coeffs, rate_shift)).collect::<Option<_>>()?;
        r.try_into().ok()
    };
    let rate_rows = rate_of(rows_x).zip(rate_of(rows_z)).map(|(x, z)| [x, z]);
    let rate_bounds = rate_rows.map(|rr| rate_bounds(&a_bounds, rate_shift, &rr, &shifts, &cross));
    let (Some(rate_rows), Some(rate_bounds)) = (rate_rows, rate_bounds.filter(|b| b.iter().all(|v| *v <= LIMIT))) else {
        return Err(at(
            base.line,
            format!(
                "baseline {0}: component {0} does not fit the fixed-point stiffness: with accumulator format Q{g} and coefficient shift {rate_shift}, a rate row or a Horner bound of its rates by depth, x, z {rate_bounds:?} exceeds the limit 2^30 = {LIMIT} micro-units ({1})",
                COMPONENTS[c],
                crate::contract::UNITS[c]
            ),
        ));
    };
    let comp = FixedComponent {
        rows,
        shifts,
        baseline: baseline.map(|v| v as i32),
        frac_bits: g,
        a_bounds,
        horner_bound,
        error_bound: ErrorBound::default(),
        cross,
        rate_shift,
        rate_rows,
        rate_bounds,
    };
    Ok(comp)
}

/// The error bound of one component, term by term, in micro-units (µN or µN·mm).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ErrorBound {
    /// Rounding of the integer arithmetic (Horner floors, alignment shifts).
    pub arithmetic: f64,
    /// Rounding of the f64 coefficients to integers.
    pub coefficients: f64,
    /// Rounding of the normalised inputs `U`, `T_k` to Q15.
    pub inputs: f64,
    /// Rounding of the result to whole micro-units.
    pub output: f64,
}

impl ErrorBound {
    /// The whole bound, raised by a relative `1e-9` for the f64 arithmetic of the bound
    /// itself.
    #[must_use]
    pub fn total(&self) -> f64 {
        (self.arithmetic + self.coefficients + self.inputs + self.output) * (1.0 + 1e-9)
    }

    /// The whole bound in whole micro-units, rounded up.
    #[must_use]
    pub fn total_micro(&self) -> u32 {
        self.total().ceil() as u32
    }
}
