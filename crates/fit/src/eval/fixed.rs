//! An independent implementation of the fixed-point evaluation (coeffs/README.md,
//! "Fixed-point evaluation"): it writes `golden-fixed.csv`, so it must not call the
//! `needle-haptics` library nor `needle-codegen`.
//!
//! Every intermediate is computed in i64 with checked operations and must stay within
//! the contract's invariant `|v| <= 2^30`; an intermediate outside it is reported as an
//! [`Overflow`] (the library, which computes in wrapping i32, would have produced garbage
//! there). Products are floored with `div_euclid`, not shifts.

use crate::contract::COMPONENT_COUNT;
use crate::contract::{
    Sweep, NCOEF, STATUS_FE_UNSOLVED, STATUS_SAT_DEPTH, STATUS_SAT_THETA_X, STATUS_SAT_THETA_Z, STATUS_SAT_X, STATUS_SAT_Z,
};
use crate::fixed_formats::{TablesFixed, LIMIT};
use std::fmt;

/// 1 mm or 1 degree in the Q16.16 pose.
pub const ONE: i64 = 65536;
/// Half-ranges of x, z, theta_x, theta_z in Q16.16.
pub const HALF_RANGE_Q16: [i64; 4] = {
    let [x, z, tx, tz] = needle_contract::HALF_RANGES;
    [x as i64 * ONE, z as i64 * ONE, tx as i64 * ONE, tz as i64 * ONE]
};
/// Depth range end in Q16.16.
pub const DEPTH_MAX_Q16: i64 = needle_contract::DEPTH_MAX_MM as i64 * ONE;
/// Divisors of the sweeps' normalisation, the contract's `FIXED_SWEEP_DIVISORS` (`V_k / 2 *
/// 2^16 / 2^15`: x, z 12; tilts 15).
pub const DIVISORS: [i64; 4] = {
    let [x, z, tx, tz] = needle_contract::FIXED_SWEEP_DIVISORS;
    [x as i64, z as i64, tx as i64, tz as i64]
};
/// Depth divisor, the contract's `FIXED_DEPTH_DIVISOR` (`3 * 2^16 / 2^15 = 6`).
pub const DEPTH_DIVISOR: i64 = needle_contract::FIXED_DEPTH_DIVISOR as i64;
/// `2^15`: the scale of U and T.
const Q15: i64 = 1 << 15;

/// An intermediate left the contract's range `|v| <= 2^30`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Overflow {
    /// Which intermediate.
    pub what: String,
    /// Its value (exact, in i64) or `None` when even i64 overflowed.
    pub value: Option<i64>,
}

impl fmt::Display for Overflow {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{} = {:?} exceeds 2^30", self.what, self.value)
    }
}

fn check(v: Option<i64>, what: impl Fn() -> String) -> Result<i64, Overflow> {
    match v {
        Some(x) if x.abs() <= LIMIT => Ok(x),
        _ => Err(Overflow { what: what(), value: v }),
    }
}

/// `floor(a * w / 2^15) + p`, checked.
fn step(a: i64, w: i64, p: i64, what: &dyn Fn() -> String) -> Result<i64, Overflow> {
    let prod = check(a.checked_mul(w).map(|m| m.div_euclid(Q15)), || format!("{} (product)", what()))?;
    check(prod.checked_add(p), what)
}

/// Horner in Q15, highest power first, every intermediate checked.
fn horner(p: &[i64; NCOEF], w: i64, what: &dyn Fn() -> String) -> Result<i64, Overflow> {
    let mut acc = check(Some(p[NCOEF - 1]), what)?;
    for c in p[..NCOEF - 1].iter().rev() {
        acc = step(acc, w, *c, what)?;
    }
    Ok(acc)
}

/// `(n + d / 2) / d - 32768` for `n >= 0`: the normalised input in Q15, rounded to nearest.
fn normalise(n: i64, d: i64) -> i64 {
    (n + d / 2) / d - Q15
}

/// Steps 1-6 at one pose: the clamped inputs, `U`, `T_k`, `N_k`, the status and the
/// accumulators `A[c][i]`.
struct Accumulated {
    v: [i64; 4],
    u: i64,
    tk: [i64; 4],
    n: [i64; 4],
    status: u8,
    a: [[i64; NCOEF]; COMPONENT_COUNT],
}

/// The factors of the monomial of exponents `e` over the inputs `n`, in input order, each
/// repeated by its exponent.
fn factors(e: &[u8; 4], n: [i64; 4]) -> impl Iterator<Item = i64> + '_ {
    e.iter().zip(n).flat_map(|(&k, nk)| std::iter::repeat_n(nk, usize::from(k)))
}

/// The Q15 monomial: the factors multiplied left to right (each product floored), `none`
/// when there is no factor.
fn monomial(mut factors: impl Iterator<Item = i64>, none: i64, what: &dyn Fn() -> String) -> Result<i64, Overflow> {
    let Some(mut m) = factors.next() else { return Ok(none) };
    for nk in factors {
        m = step(m, nk, 0, what)?;
    }
    Ok(m)
}

fn accumulate(t: &TablesFixed, pose: [i32; 5]) -> Result<Accumulated, Overflow> {
    let p = pose.map(i64::from);
    let sat_bits = [STATUS_SAT_X, STATUS_SAT_Z, STATUS_SAT_THETA_X, STATUS_SAT_THETA_Z];
    let mut status = 0u8;
    let mut v = [0i64; 4];
    for k in 0..4 {
        v[k] = p[k].clamp(-HALF_RANGE_Q16[k], HALF_RANGE_Q16[k]);
        if v[k] != p[k] {
            status |= sat_bits[k];
        }
    }
    let d = p[4].clamp(0, DEPTH_MAX_Q16);
    if d != p[4] {
        status |= STATUS_SAT_DEPTH;
    }
    let u = normalise(d, DEPTH_DIVISOR);
    let tk: [i64; 4] = std::array::from_fn(|k| normalise(v[k].abs(), DIVISORS[k]));

    // A[c][i] accumulates the baseline and the four deviations' rows (sweep-major here,
    // component-major in the library: integer sums do not depend on the order).
    let mut a = t.baseline;
    for k in Sweep::ALL {
        let ki = k.index();
        for (c, ac) in a.iter_mut().enumerate() {
            let flip = v[ki] < 0 && k.is_odd(c);
            for (i, aci) in ac.iter_mut().enumerate() {
                let name = || format!("row {}/{c}/u^{i}", k.name());
                let r = horner(&t.rows[ki][c][i], tk[ki], &name)?;
                let shifted = r.div_euclid(1i64 << (t.row_frac[ki][c][i] - t.acc_frac[c]));
                let sum = if flip { aci.checked_sub(shifted) } else { aci.checked_add(shifted) };
                *aci = check(sum, || format!("A[{c}][{i}] after sweep {}", k.name()))?;
            }
        }
    }
    // 6. cross terms of the coupled form: signed Q15 inputs, Q15 monomials, A_i += ...
    let n: [i64; 4] = std::array::from_fn(|k| {
        let q = (v[k].abs() + DIVISORS[k]) / (2 * DIVISORS[k]);
        if v[k] < 0 {
            -q
        } else {
            q
        }
    });
    for (c, terms) in t.cross.iter().enumerate() {
        for (e, p, f) in terms {
            let what = || format!("cross {c} {e:?}");
            let m = monomial(factors(e, n), 0, &what)?;
            for (i, pi) in p.iter().enumerate() {
                let prod = step(*pi, m, 0, &what)?;
                let shifted = prod.div_euclid(1i64 << (f - t.acc_frac[c]));
                a[c][i] = check(a[c][i].checked_add(shifted), || format!("A[{c}][{i}] after cross {e:?}"))?;
            }
        }
    }
    // 7. the unsolved region (on the clamped pose)
    if crate::unsolved::inside_fixed(&t.unsolved, n, d) {
        status |= STATUS_FE_UNSOLVED;
    }
    Ok(Accumulated { v, u, tk, n, status, a })
}

/// Evaluate at the Q16.16 pose `[x, z, theta_x, theta_z, depth]`: the wrench in µN and
/// µN·mm `[fx, fy, fz, mx, my, mz]` and the status byte.
///
/// # Errors
/// An intermediate leaves `|v| <= 2^30` (the tables do not meet the contract).
pub fn eval(t: &TablesFixed, pose: [i32; 5]) -> Result<([i32; COMPONENT_COUNT], u8), Overflow> {
    let acc = accumulate(t, pose)?;
    Ok((output(t, &acc)?, acc.status))
}

/// Step 7: `W = h(A, U)` per component, rounded half up to whole µN or µN·mm.
fn output(t: &TablesFixed, acc: &Accumulated) -> Result<[i32; COMPONENT_COUNT], Overflow> {
    let mut w = [0i32; COMPONENT_COUNT];
    for (c, wc) in w.iter_mut().enumerate() {
        let h = horner(&acc.a[c], acc.u, &|| format!("Horner in u of component {c}"))?;
        let g = t.acc_frac[c];
        let half = (1i64 << g) / 2;
        let out = (h + half).div_euclid(1i64 << g);
        *wc = i32::try_from(out).map_err(|_| Overflow { what: format!("output {c}"), value: Some(out) })?;
    }
    Ok(w)
}

/// The rates are computed on coefficients divided by `2^R` (floor), `R = min(3, G)`.
pub const MAX_RATE_SHIFT: u32 = 3;

/// `n / d` rounded to nearest (`floor((n + floor(d/2)) / d)`, `d > 0`), as an i32.
fn div_round(n: i64, d: i64, what: &dyn Fn() -> String) -> Result<i32, Overflow> {
    let q = (n + d / 2).div_euclid(d);
    i32::try_from(q).map_err(|_| Overflow { what: what(), value: Some(q) })
}

/// Horner in Q15 of any length (highest power first), every intermediate checked.
fn horner_n(p: &[i64], w: i64, what: &dyn Fn() -> String) -> Result<i64, Overflow> {
    let Some((last, rest)) = p.split_last() else { return Ok(0) };
    let mut acc = check(Some(*last), what)?;
    for c in rest.iter().rev() {
        acc = step(acc, w, *c, what)?;
    }
    Ok(acc)
}

/// The derivative's coefficients of `p` (`p[j]` multiplies `w^j`) on `p >> r`:
/// `[(j + 1) * floor(p[j + 1] / 2^r)]`, checked.
fn rate_coefficients(p: &[i64; NCOEF], r: u32, what: &dyn Fn() -> String) -> Result<Vec<i64>, Overflow> {
    p.iter().enumerate().skip(1).map(|(j, pj)| check(Some(j as i64 * pj.div_euclid(1 << r)), what)).collect()
}

/// The wrench (µN, µN·mm), the rates `[by depth, by x, by z]` (each `[fx .. mz]`) and
/// the status byte of [`eval_rates`].
pub type RatesFixed = ([i32; COMPONENT_COUNT], [[i32; COMPONENT_COUNT]; 3], u8);

/// The wrench, its rates `[by depth, by x, by z]` (each `[fx .. mz]`, µN/mm and
/// µN·mm/mm) and the status at the Q16.16 pose, by coeffs/README.md, "Fixed-point
/// stiffness".
///
/// # Errors
/// An intermediate leaves `|v| <= 2^30` (the tables do not meet the contract).
pub fn eval_rates(t: &TablesFixed, pose: [i32; 5]) -> Result<RatesFixed, Overflow> {
    let acc = accumulate(t, pose)?;
    let (w, status) = (output(t, &acc)?, acc.status);
    let mut rates = [[0i32; COMPONENT_COUNT]; 3];
    for c in 0..COMPONENT_COUNT {
        let g = t.acc_frac[c];
        let rs = g.min(MAX_RATE_SHIFT);
        let unit = 1i64 << (g - rs);
        // by depth: E_i = (i + 1) * (A_(i+1) >> R), D = h(E, U), rate = round(D / (3 * 2^(G-R)))
        let what = || format!("rate by depth of component {c}");
        let e = rate_coefficients(&acc.a[c], rs, &what)?;
        let d = horner_n(&e, acc.u, &what)?;
        rates[0][c] = div_round(d, 3 * unit, &what)?;
        // by x and z: row rates (sign by the chain rule through |v|), cross-term rates
        for (slot, k) in [(1, Sweep::X), (2, Sweep::Z)] {
            let ki = k.index();
            let what = || format!("rate by {} of component {c}", k.name());
            let minus = acc.v[ki] < 0 && !k.is_odd(c);
            let mut g_i = [0i64; NCOEF];
            for (i, gi) in g_i.iter_mut().enumerate() {
                let r = horner_n(&rate_coefficients(&t.rows[ki][c][i], rs, &what)?, acc.tk[ki], &what)?;
                let shifted = r.div_euclid(1i64 << (t.row_frac[ki][c][i] - g));
                *gi = check(if minus { gi.checked_sub(shifted) } else { gi.checked_add(shifted) }, what)?;
            }
            for (e, p, f) in &t.cross[c] {
                let ek = i64::from(e[ki]);
                if ek == 0 {
                    continue;
                }
                let mut reduced = *e;
                reduced[ki] -= 1;
                let r = monomial(factors(&reduced, acc.n), 1 << 15, &what)?;
                for (i, pi) in p.iter().enumerate() {
                    let prod = step(pi.div_euclid(1 << rs), r, 0, &what)?;
                    let term = check(Some(ek * prod.div_euclid(1i64 << (f - g + 1))), what)?;
                    g_i[i] = check(g_i[i].checked_add(term), what)?;
                }
            }
            let h = horner_n(&g_i, acc.u, &what)?;
            rates[slot][c] = div_round(h, 6 * unit, &what)?;
        }
    }
    for (slot, bit) in [(0, STATUS_SAT_DEPTH), (1, STATUS_SAT_X), (2, STATUS_SAT_Z)] {
        if status & bit != 0 {
            rates[slot] = [0; COMPONENT_COUNT];
        }
    }
    Ok((w, rates, status))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn normalisation_rounds_to_nearest_and_spans_q15() {
        assert_eq!(normalise(0, 12), -32768);
        assert_eq!(normalise(12 * ONE, 12), 32768);
        assert_eq!(normalise(15 * ONE, 15), 32768);
        assert_eq!(normalise(6 * ONE, 6), 32768);
        assert_eq!(normalise(3 * ONE, 6), 0);
        // 5/12 rounds down, 6/12 rounds up, 7/15 down, 8/15 up
        assert_eq!(normalise(5, 12), -32768);
        assert_eq!(normalise(6, 12), -32767);
        assert_eq!(normalise(7, 15), -32768);
        assert_eq!(normalise(8, 15), -32767);
    }

    #[test]
    fn steps_floor_towards_minus_infinity() {
        let what = || String::new();
        assert_eq!(step(3, -1, 0, &what).unwrap(), -1);
        assert_eq!(step(-3, 1, 0, &what).unwrap(), -1);
        assert_eq!(step(3, 1, 0, &what).unwrap(), 0);
        assert_eq!(step(-(1 << 30), -(1 << 15), 0, &what).unwrap(), 1 << 30);
        assert!(step(1 << 30, 1 << 15, 1, &what).is_err());
    }
}
