//! A fitted value over several trials: its mean, standard deviation (the spread of the
//! tissue and the rig) and standard error of the mean (the fitted uncertainty), and the
//! small non-negative least squares of the whole-trial fit on normal equations.
use nalgebra::{DMatrix, DVector};

/// A value fitted per trial, summarised.
#[derive(Debug, Clone, PartialEq)]
pub struct Spread {
    /// Mean over the trials.
    pub mean: f64,
    /// Sample standard deviation over the trials (0 for one trial).
    pub sd: f64,
    /// Standard error of the mean, `sd / sqrt(n)` (`None` for one trial: no uncertainty
    /// can be told from one).
    pub se: Option<f64>,
    /// The per-trial values.
    pub values: Vec<f64>,
}

impl Spread {
    /// The summary of `values` (empty: a mean of 0 and no uncertainty).
    #[must_use]
    pub fn of(values: Vec<f64>) -> Self {
        let n = values.len() as f64;
        if values.is_empty() {
            return Self { mean: 0.0, sd: 0.0, se: None, values };
        }
        let mean = values.iter().sum::<f64>() / n;
        let sd = if values.len() > 1 { (values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt() } else { 0.0 };
        let se = (values.len() > 1).then(|| sd / n.sqrt());
        Self { mean, sd, se, values }
    }

    /// `± se (sd over n trials)` with `unit`, for a comment beside the value.
    #[must_use]
    pub fn note(&self, unit: &str) -> String {
        match self.se {
            Some(se) => format!("+- {se:.3e} {unit} (standard error; sd {:.3e} over {} trials)", self.sd, self.values.len()),
            None => format!("no uncertainty: fitted on {} trial", self.values.len()),
        }
    }
}

/// The normal equations of a least-squares problem: `AᵀA`, `Aᵀb` and `bᵀb`, summed row
/// by row (so that rows of several trials add up without holding them).
#[derive(Debug, Clone, PartialEq)]
pub struct Normal {
    ata: Vec<f64>,
    atb: Vec<f64>,
    btb: f64,
    n: usize,
}

impl Normal {
    /// `n` columns, no rows yet.
    #[must_use]
    pub fn new(n: usize) -> Self {
        Self { ata: vec![0.0; n * n], atb: vec![0.0; n], btb: 0.0, n }
    }

    /// Adds the row `a` (its `n` values) with right-hand side `b`.
    pub fn add(&mut self, a: &[f64], b: f64) {
        for (i, ai) in a.iter().enumerate().take(self.n) {
            for (j, aj) in a.iter().enumerate().take(self.n) {
                self.ata[i * self.n + j] += ai * aj;
            }
            self.atb[i] += ai * b;
        }
        self.btb += b * b;
    }

    /// Adds another's rows (the same columns).
    pub fn merge(&mut self, o: &Self) {
        for (a, b) in self.ata.iter_mut().zip(&o.ata) {
            *a += b;
        }
        for (a, b) in self.atb.iter_mut().zip(&o.atb) {
            *a += b;
        }
        self.btb += o.btb;
    }

    /// The columns `keep` only (in that order).
    #[must_use]
    pub fn select(&self, keep: &[usize]) -> Self {
        let n = keep.len();
        let mut out = Self::new(n);
        for (i, &ki) in keep.iter().enumerate() {
            for (j, &kj) in keep.iter().enumerate() {
                out.ata[i * n + j] = self.ata.get(ki * self.n + kj).copied().unwrap_or(0.0);
            }
            out.atb[i] = self.atb.get(ki).copied().unwrap_or(0.0);
        }
        out.btb = self.btb;
        out
    }

    /// The normal equations of new columns, each a combination of these: new column `k`
    /// is `sum_i m[k][i]` times column `i`.
    #[must_use]
    pub fn combine(&self, m: &[Vec<f64>]) -> Self {
        let n = m.len();
        let mut out = Self::new(n);
        for (a, ma) in m.iter().enumerate() {
            for (b, mb) in m.iter().enumerate() {
                let mut q = 0.0;
                for (i, x) in ma.iter().enumerate().filter(|(_, x)| **x != 0.0) {
                    for (j, y) in mb.iter().enumerate().filter(|(_, y)| **y != 0.0) {
                        q += x * self.ata.get(i * self.n + j).copied().unwrap_or(0.0) * y;
                    }
                }
                out.ata[a * n + b] = q;
            }
            out.atb[a] = ma.iter().enumerate().map(|(i, x)| x * self.atb.get(i).copied().unwrap_or(0.0)).sum();
        }
        out.btb = self.btb;
        out
    }

    /// The first `n - 1` unknowns `>= 0` minimising `|A x - b|²` with the last fixed at 1,
    /// and the sum of squares.
    #[must_use]
    pub fn with_last_fixed(&self) -> (Vec<f64>, f64) {
        let n = self.n;
        if n == 0 {
            return (Vec::new(), self.btb);
        }
        let k = n - 1;
        let mut reduced = Self::new(k);
        for i in 0..k {
            for j in 0..k {
                reduced.ata[i * k + j] = self.ata[i * n + j];
            }
            reduced.atb[i] = self.atb[i] - self.ata[i * n + k];
        }
        reduced.btb = self.btb - 2.0 * self.atb[k] + self.ata[k * n + k];
        let (x, sse) = reduced.non_negative();
        (x, sse)
    }

    /// `x >= 0` minimising `|A x - b|²` (every subset of free columns tried: exact for the
    /// few columns of a layer) and the sum of squares.
    #[must_use]
    pub fn non_negative(&self) -> (Vec<f64>, f64) {
        let n = self.n;
        let mut best = (vec![0.0; n], self.btb);
        for mask in 1u32..(1 << n) {
            let active: Vec<usize> = (0..n).filter(|k| mask & (1 << k) != 0).collect();
            let m = DMatrix::from_fn(active.len(), active.len(), |r, c| self.ata[active[r] * n + active[c]]);
            let rhs = DVector::from_iterator(active.len(), active.iter().map(|&k| self.atb[k]));
            let Some(sol) = m.lu().solve(&rhs) else { continue };
            if sol.iter().any(|v| !v.is_finite() || *v < 0.0) {
                continue;
            }
            let mut x = vec![0.0; n];
            for (k, &col) in active.iter().enumerate() {
                x[col] = sol[k];
            }
            let sse = self.sse(&x);
            if sse < best.1 {
                best = (x, sse);
            }
        }
        best
    }

    /// `|A x - b|²` from the normal equations.
    #[must_use]
    pub fn sse(&self, x: &[f64]) -> f64 {
        let n = self.n;
        let mut q = self.btb;
        for i in 0..n {
            q -= 2.0 * x[i] * self.atb[i];
            for j in 0..n {
                q += x[i] * self.ata[i * n + j] * x[j];
            }
        }
        q.max(0.0)
    }
}
