//! The fixed-point tables of a model, by the rules of coeffs/README.md ("Fixed-point
//! evaluation": quantisation and format choice), implemented here independently of
//! `needle-codegen`: the golden vectors written from them check the generator's choice
//! of formats as well as the library's arithmetic.

use super::contract::{Sweep, COMPONENTS, NCOEF};
use super::model::Model;
use crate::contract::COMPONENT_COUNT;
use anyhow::{bail, Result};

/// Magnitude limit of every integer intermediate: 2^30.
pub const LIMIT: i64 = 1 << 30;
/// Formats are searched in `0..=MAX_FRAC` fractional bits.
pub const MAX_FRAC: u32 = 30;

/// The integer tables, in the f32 tables' layout (sweep-major).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct TablesFixed {
    /// `rows[k][c][i][j]`: integer coefficient of `t^j` in row `i` of matrix (k, c).
    pub rows: [[[[i64; NCOEF]; NCOEF]; COMPONENT_COUNT]; 4],
    /// Fractional bits `f` of each row, `[k][c][i]`.
    pub row_frac: [[[u32; NCOEF]; COMPONENT_COUNT]; 4],
    /// Baseline coefficients in each component's accumulator format, `[c][i]`.
    pub baseline: [[i64; NCOEF]; COMPONENT_COUNT],
    /// Fractional bits `G` of each component's accumulator.
    pub acc_frac: [u32; COMPONENT_COUNT],
    /// The coupled form's cross terms per component, file order: exponents, integer
    /// coefficients (`[i]` goes to `A_i`) and their fractional bits `F` (empty for the
    /// paper form).
    pub cross: [Vec<CrossTermFixed>; COMPONENT_COUNT],
    /// The set's unsolved region (`unsolved.toml`; empty: no pose is flagged).
    pub unsolved: Vec<crate::unsolved::Entry>,
}

/// One cross term in fixed point: exponents of (x, z, theta_x, theta_z), integer
/// coefficients (`[i]` goes to `A_i`), fractional bits `F`.
pub type CrossTermFixed = ([u8; 4], Vec<i64>, u32);

/// Largest `f` with every quantised coefficient `|P_i| <= 2^30`: a cross term's format.
fn cross_format(p: &[f64]) -> Option<(u32, Vec<i64>)> {
    let mut best = None;
    for f in 0..=MAX_FRAC {
        let q: Vec<i64> = p.iter().map(|c| quantise(*c, f)).collect();
        if q.iter().all(|v| v.checked_abs().is_some_and(|a| a <= LIMIT)) {
            best = Some((f, q));
        } else {
            break;
        }
    }
    best
}

/// `round(c * 10^6 * 2^f)`, ties away from zero: the f64 product `c * 1e6` rounded once,
/// then scaled exactly.
pub fn quantise(c: f64, f: u32) -> i64 {
    let micro = c * 1.0e6;
    (micro * 2f64.powi(f as i32)).round() as i64
}

/// Largest `f` whose quantised row has `sum |P_j| <= 2^30` (the sum grows with `f`, so this
/// searches upwards and keeps the last that fits), with the row and its sum.
fn row_format(row: &[f64; NCOEF]) -> Option<(u32, [i64; NCOEF], i64)> {
    let mut best = None;
    for f in 0..=MAX_FRAC {
        let q = row.map(|c| quantise(c, f));
        let sum = q.iter().try_fold(0i64, |s, v| s.checked_add(v.checked_abs()?));
        match sum {
            Some(s) if s <= LIMIT => best = Some((f, q, s)),
            _ => break,
        }
    }
    best
}

impl TablesFixed {
    /// The same tables with the unsolved region `entries` (`FE_UNSOLVED` in the status).
    #[must_use]
    pub fn with_unsolved(mut self, entries: Vec<crate::unsolved::Entry>) -> Self {
        self.unsolved = entries;
        self
    }

    /// Quantise `model` and choose its formats.
    ///
    /// # Errors
    /// A row or a component does not fit within 2^30 micro-units even with 0 fractional
    /// bits (the library's build refuses such a model too).
    pub fn from_model(model: &Model) -> Result<Self> {
        let mut t = TablesFixed {
            rows: [[[[0; NCOEF]; NCOEF]; COMPONENT_COUNT]; 4],
            row_frac: [[[0; NCOEF]; COMPONENT_COUNT]; 4],
            baseline: [[0; NCOEF]; COMPONENT_COUNT],
            acc_frac: [0; COMPONENT_COUNT],
            cross: Default::default(),
            unsolved: Vec::new(),
        };
        if let Some(k) = &model.cross {
            for (c, terms) in k.terms.terms.iter().enumerate() {
                for (e, p) in terms {
                    let Some((f, q)) = cross_format(p) else {
                        bail!("cross {} {e:?}: a coefficient does not fit in 2^30 micro-units", COMPONENTS[c]);
                    };
                    t.cross[c].push((*e, q, f));
                }
            }
        }
        let mut row_sum = [[[0i64; NCOEF]; COMPONENT_COUNT]; 4];
        for k in Sweep::ALL {
            for c in 0..COMPONENT_COUNT {
                for (i, row) in model.matrices[k.index()][c].rows.iter().enumerate() {
                    let Some((f, q, s)) = row_format(row) else {
                        bail!("matrix {}/{}: row u^{i} does not fit in 2^30 micro-units", k.name(), COMPONENTS[c]);
                    };
                    t.rows[k.index()][c][i] = q;
                    t.row_frac[k.index()][c][i] = f;
                    row_sum[k.index()][c][i] = s;
                }
            }
        }
        for c in 0..COMPONENT_COUNT {
            let g_max =
                Sweep::ALL.iter().flat_map(|k| t.row_frac[k.index()][c]).chain(t.cross[c].iter().map(|x| x.2)).min().unwrap_or(MAX_FRAC);
            let bound_at = |g: u32| -> (i64, [i64; NCOEF]) {
                let base = model.baseline[c].coeffs.map(|b| quantise(b, g));
                let mut total = 0i64;
                for (i, b) in base.iter().enumerate() {
                    let mut a = b.saturating_abs();
                    for k in 0..4 {
                        let shift = t.row_frac[k][c][i] - g;
                        // ceil(sum / 2^shift): the largest |r >> shift| when |r| <= sum
                        let d = 1i64 << shift;
                        a = a.saturating_add((row_sum[k][c][i] + d - 1) / d);
                    }
                    for (_, q, f) in &t.cross[c] {
                        let d = 1i64 << (f - g);
                        let p = q.get(i).map_or(0, |v| v.abs());
                        a = a.saturating_add((p + d - 1) / d);
                    }
                    total = total.saturating_add(a);
                }
                (total, base)
            };
            let mut chosen = None;
            for g in 0..=g_max {
                let (total, base) = bound_at(g);
                if total > LIMIT {
                    break;
                }
                chosen = Some((g, base));
            }
            let Some((g, base)) = chosen else {
                bail!("component {}: baseline plus deviations exceed 2^30 micro-units", COMPONENTS[c]);
            };
            t.acc_frac[c] = g;
            t.baseline[c] = base;
        }
        Ok(t)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quantise_rounds_half_away_from_zero() {
        assert_eq!(quantise(0.5e-6, 0), 1);
        assert_eq!(quantise(-0.5e-6, 0), -1);
        assert_eq!(quantise(1.0, 3), 8_000_000);
        assert_eq!(quantise(-0.25e-6, 1), -1);
    }

    #[test]
    fn row_format_keeps_the_largest_fitting_format() {
        // 1 N = 10^6 uN: 2^30 / 10^6 = 1073.7, so f = 10 (1024 * 10^6 <= 2^30 < 2048 * 10^6)
        let only = |c0: f64| std::array::from_fn(|i| if i == 0 { c0 } else { 0.0 });
        let (f, q, s) = row_format(&only(1.0)).unwrap();
        assert_eq!((f, q[0], s), (10, 1_024_000_000, 1_024_000_000));
        assert_eq!(row_format(&[0.0; NCOEF]).unwrap().0, MAX_FRAC);
        assert!(row_format(&only(2000.0)).is_none());
    }
}
