//! The axial force of a viscoelastic boundary indented at a steady speed: the elastic
//! surrogate through the layer's relaxation function (quasi-linear viscoelasticity,
//! `G(t) = 1 + sum g_i exp(-t / tau_i)` in the tissue files' long-term normalisation).
//! `needle calibrate-published` fits a layer with Prony terms against this curve, so that
//! its filtered force follows the published one at the replay speed (the published model
//! names no speed; coeffs/default/measured/davidor2023-epidural/README.md).
//!
//! The response is the exact QLV convolution of the elastic force taken as linear in time
//! between samples [`STEP_MM`] apart: per step of `dt` and elastic change `de`, each term
//! `h_i <- a_i h_i + b_i de` with `a_i = exp(-dt / tau_i)`, `b_i = g_i (1 - a_i) / (dt /
//! tau_i)` (the library's recursion, `needle_haptics::viscoelastic`, in f64 and with this
//! step instead of the tick), the force `e + sum h_i`.

use needle_codegen::tissue::PronyTerm;

/// Indentation between the samples of the response, mm.
pub const STEP_MM: f64 = 0.01;

/// The response sampled every [`STEP_MM`] from contact.
#[derive(Debug, Clone, PartialEq)]
pub struct RampResponse {
    values: Vec<f64>,
}

impl RampResponse {
    /// The response of `elastic(indentation_mm)` (N, 0 at contact) with `terms` at
    /// `speed_mm_per_s` (> 0), from contact to `max_mm` of indentation.
    #[must_use]
    pub fn new(elastic: &dyn Fn(f64) -> f64, terms: &[PronyTerm], speed_mm_per_s: f64, max_mm: f64) -> Self {
        let n = (max_mm.max(0.0) / STEP_MM).ceil() as usize + 1;
        let dt_s = STEP_MM / speed_mm_per_s;
        let coefficients: Vec<(f64, f64)> = terms
            .iter()
            .map(|t| {
                let x = dt_s / t.tau_s;
                ((-x).exp(), t.g * -(-x).exp_m1() / x)
            })
            .collect();
        let mut h = vec![0.0; terms.len()];
        let mut last = elastic(0.0);
        let mut values = Vec::with_capacity(n);
        values.push(last);
        for k in 1..n {
            let e = elastic(k as f64 * STEP_MM);
            let de = e - last;
            for (h, (a, b)) in h.iter_mut().zip(&coefficients) {
                *h = a * *h + b * de;
            }
            values.push(e + h.iter().sum::<f64>());
            last = e;
        }
        Self { values }
    }

    /// The response at `indentation_mm` (linear between samples; 0 before contact, the
    /// last sample past the end).
    #[must_use]
    pub fn at(&self, indentation_mm: f64) -> f64 {
        if indentation_mm <= 0.0 {
            return 0.0;
        }
        let u = indentation_mm / STEP_MM;
        let k = u.floor() as usize;
        match (self.values.get(k), self.values.get(k + 1)) {
            (Some(a), Some(b)) => a + (b - a) * (u - k as f64),
            (Some(a), None) => *a,
            _ => self.values.last().copied().unwrap_or(0.0),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A linear elastic force `k d` pushed at `v`: the QLV ramp response has the closed
    /// form `k v (t + sum g_i tau_i (1 - exp(-t / tau_i)))` at `t = d / v`.
    #[test]
    fn a_linear_boundary_follows_the_closed_form_ramp_response() {
        let (k, v) = (0.8, 3.0);
        let terms = [PronyTerm { g: 2.571, tau_s: 0.19 }, PronyTerm { g: 0.4, tau_s: 5.0 }];
        let r = RampResponse::new(&|d| k * d, &terms, v, 15.0);
        for d in [0.01, 0.37, 1.0, 4.2, 13.9] {
            let t = d / v;
            let want = k * v * (t + terms.iter().map(|p| p.g * p.tau_s * (1.0 - (-t / p.tau_s).exp())).sum::<f64>());
            let got = r.at(d);
            assert!((got - want).abs() <= 1e-9 * want.abs().max(1.0), "at {d} mm: {got} N, closed form {want} N");
        }
        // without terms: the elastic force itself; before contact: nothing
        let plain = RampResponse::new(&|d| k * d * d, &[], v, 2.0);
        assert!((plain.at(1.5) - k * 2.25).abs() < 1e-12 && plain.at(-1.0) == 0.0);
    }
}
