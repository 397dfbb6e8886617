//! The axial force of a viscoelastic boundary indented at a steady speed: the elastic
//! surrogate through the layer's relaxation function, the library's own filter
//! (`needle_haptics::viscoelastic::Qlv`, f32) stepped once per tick of the replay's
//! configuration (`InsertionConfig::DEFAULT_1KHZ`), as the insertion model steps it.
//! `needle calibrate-published --with-prony` fits a layer with Prony terms against this
//! curve, so that its filtered force follows the published one at the replay speed (the
//! published model names no speed; coeffs/default/measured/davidor2023-epidural/README.md).

use anyhow::{anyhow, Result};
use needle_codegen::tissue::PronyTerm;
use needle_haptics::insertion::InsertionConfig;
use needle_haptics::viscoelastic::{PronyTerm as Term, PronyTerms, Qlv};

/// The response at every tick from contact.
#[derive(Debug, Clone, PartialEq)]
pub struct RampResponse {
    /// Indentation per tick, mm.
    step_mm: f64,
    values: Vec<f64>,
}

impl RampResponse {
    /// The response of `elastic(indentation_mm)` (N, 0 at contact) with `terms` (the
    /// tissue file's, long-term normalisation) at `speed_mm_per_s` (> 0), from contact to
    /// `max_mm` of indentation.
    ///
    /// # Errors
    /// The library refuses the terms.
    pub fn new(elastic: &dyn Fn(f64) -> f64, terms: &[PronyTerm], speed_mm_per_s: f64, max_mm: f64) -> Result<Self> {
        let tick_s = InsertionConfig::DEFAULT_1KHZ.period_s;
        let lib: Vec<Term> = terms.iter().map(|t| Term { g: t.g as f32, tau_s: t.tau_s as f32 }).collect();
        let lib = PronyTerms::new(&lib).map_err(|e| anyhow!("Prony terms {terms:?}: {e}"))?;
        let mut filter = Qlv::new(&lib, tick_s).map_err(|e| anyhow!("Prony terms {terms:?}: {e}"))?;
        let step_mm = speed_mm_per_s * f64::from(tick_s);
        let ticks = (max_mm.max(0.0) / step_mm).ceil() as usize;
        let values = (0..=ticks).map(|k| f64::from(filter.step(elastic(k as f64 * step_mm) as f32))).collect();
        Ok(Self { step_mm, values })
    }

    /// The response at `indentation_mm` (linear between ticks; 0 before contact, the last
    /// tick's past the end).
    #[must_use]
    pub fn at(&self, indentation_mm: f64) -> f64 {
        if indentation_mm <= 0.0 {
            return 0.0;
        }
        let u = indentation_mm / self.step_mm;
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
    /// form `k v (t + sum g_i tau_i (1 - exp(-t / tau_i)))` at `t = d / v`, which the
    /// library's recursion reproduces exactly for an input linear over each tick; the
    /// bound is f32's rounding accumulated over up to 4,640 ticks (measured: 4.9e-6 of the
    /// force at most).
    #[test]
    fn a_linear_boundary_follows_the_closed_form_ramp_response() {
        let (k, v) = (0.8, 3.0);
        let terms = [PronyTerm { g: 2.571, tau_s: 0.19 }, PronyTerm { g: 0.4, tau_s: 5.0 }];
        let r = RampResponse::new(&|d| k * d, &terms, v, 15.0).expect("terms");
        let mut worst = 0.0f64;
        for d in [0.012, 0.369, 0.999, 4.2, 13.92] {
            let t = d / v;
            let want = k * v * (t + terms.iter().map(|p| p.g * p.tau_s * (1.0 - (-t / p.tau_s).exp())).sum::<f64>());
            let got = r.at(d);
            worst = worst.max((got - want).abs() / want.abs());
            assert!((got - want).abs() <= 2e-5 * want.abs(), "at {d} mm: {got} N, closed form {want} N");
        }
        println!("largest relative error against the closed form: {worst:e}");
        // without terms: the elastic force itself; before contact: nothing
        let plain = RampResponse::new(&|d| k * d * d, &[], v, 2.0).expect("no terms");
        assert!((plain.at(1.5) - k * 2.25).abs() < 1e-6 && plain.at(-1.0) == 0.0);
        assert!(RampResponse::new(&|d| d, &[PronyTerm { g: -1.0, tau_s: 1.0 }], v, 1.0).is_err(), "refused by the library");
    }
}
