//! One relaxation function for the tissue: the boundary below the last puncture relaxes
//! through the same Prony terms as the shaft's held friction and cutting (issue 65).
//!
//! The rig's holds relax by about the same share whatever carries the held force (the
//! shaft at one speed, the boundary below at another: skin on muscle at 1, 2 and 3 mm/s);
//! fitted apart, the shaft's terms take the whole relaxation of a hold whose boundary is
//! elastic, and a trial held with more of its force on the shaft relaxes too far. Tied,
//! one set `(g_i, tau_i)` is both the boundary's quasi-linear terms (its column
//! `u + sum g_i y_i`, [`super::hold`]) and the shaft's (the weights
//! `beta_i = g_i / (1 + sum g)` of its arms' columns).
use super::stats::Normal;

/// The joint fit of the hold's normal equations `all` (columns: cutting, the boundary's
/// deflection, `m` filter responses `y_i`, `m` shaft columns) with the terms `choice`
/// tied: for weights `g` the shaft's shares are known and cutting and scale are a small
/// non-negative least squares; the weights are searched coordinate by coordinate
/// ([`SWEEPS`] golden sections over `0..=`[`G_MAX`]). Returns `(cutting, scale, beta...)`
/// and the sum of squares.
#[must_use]
pub fn fit(all: &Normal, choice: &[usize], m: usize) -> (Vec<f64>, f64) {
    let width = 2 + 2 * m;
    let unit = |k: usize| (0..width).map(|i| if i == k { 1.0 } else { 0.0 }).collect::<Vec<f64>>();
    let solve = |g: &[f64]| -> (Vec<f64>, f64) {
        let total = 1.0 + g.iter().sum::<f64>();
        let mut u = unit(1);
        let mut z = vec![0.0; width];
        for (gi, &c) in g.iter().zip(choice) {
            u[2 + c] = *gi;
            z[2 + m + c] = gi / total;
        }
        let (mut x, sse) = all.combine(&[unit(0), u, z]).with_last_fixed();
        x.extend(g.iter().map(|gi| gi / total));
        (x, sse)
    };
    let mut g = vec![0.0; choice.len()];
    let mut best = solve(&g);
    for _ in 0..SWEEPS {
        for k in 0..g.len() {
            let at = |x: f64| {
                let mut t = g.clone();
                t[k] = x;
                t
            };
            let x = golden(&|x| solve(&at(x)).1, G_MAX);
            let candidate = solve(&at(x));
            if candidate.1 < best.1 {
                g = at(x);
                best = candidate;
            }
        }
    }
    best
}

/// Sweeps of the coordinate search.
pub const SWEEPS: usize = 3;

/// The largest weight of one term: a third of the format's largest sum.
pub const G_MAX: f64 = needle_codegen::tissue::PRONY_G_SUM_MAX / 3.0;

/// Golden-section steps (the bracket shrinks by 0.618 each: about 1e-8 of it at the end).
const GOLDEN_STEPS: usize = 40;

/// The `x` in `0..=hi` minimising `f` (golden sections over `sqrt(x)`: finer near zero,
/// where most weights lie).
fn golden(f: &dyn Fn(f64) -> f64, hi: f64) -> f64 {
    let r = 0.5 * (5f64.sqrt() - 1.0);
    let (mut a, mut b) = (0.0f64, hi.sqrt());
    let (mut c, mut d) = (b - r * (b - a), a + r * (b - a));
    let (mut fc, mut fd) = (f(c * c), f(d * d));
    for _ in 0..GOLDEN_STEPS {
        if fc < fd {
            b = d;
            (d, fd) = (c, fc);
            c = b - r * (b - a);
            fc = f(c * c);
        } else {
            a = c;
            (c, fc) = (d, fd);
            d = a + r * (b - a);
            fd = f(d * d);
        }
    }
    let x = 0.5 * (a + b);
    x * x
}
