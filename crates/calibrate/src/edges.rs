//! A fitted value on the edge of the range its fit scans (issue 64, bad input): the best
//! fit may lie beyond the range (a member the FE does not cover, a softening that starts
//! earlier or later than any scanned), so the calibration says so, naming the parameter,
//! its value, the range and its unit. A value is on an edge when it lies closer to it
//! than the fit's grid step there (for a scanned value: on the edge's grid point).
//!
//! The values checked, each as [`crate::shape`] scans it:
//! - the family member's weight `w` ([`SQRT_WEIGHTS`]: 0.01 to 1, the members the FE
//!   covers). `w = 1` is also the paper's tissue, which the fit keeps when another member
//!   is not better by more than [`crate::shape::RANGE_SSE_RATIO`] (the simplest model):
//!   there it warns only when the least-squares best is the paper's tissue as well
//!   ([`ShapeFit::least_squares_weight`]), else the data do not pin `w` to the edge.
//! - the softening's onset ratio `r0` ([`ONSET_RATIOS`]), when the fit softens.
//!
//! The softening's fraction `δ` is not: it is solved, not scanned, from 0 (no softening,
//! the simplest model) up to [`crate::shape::MAX_FRACTION`] exclusive, which the fit
//! never returns (a candidate there is dropped), so no fit lies on its edge.
use crate::shape::{ShapeFit, ONSET_RATIOS, SQRT_WEIGHTS};
use std::fmt;

/// Which end of its range a value lies on.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Edge {
    /// The smallest value scanned.
    Lower,
    /// The largest value scanned.
    Upper,
}

impl Edge {
    /// `"lower"` or `"upper"`.
    #[must_use]
    pub fn word(self) -> &'static str {
        match self {
            Edge::Lower => "lower",
            Edge::Upper => "upper",
        }
    }
}

/// A fitted value on its range's edge.
#[derive(Debug, Clone, PartialEq)]
pub struct EdgeWarning {
    /// The tissue file's key of the value (`family_weight`, `softening_onset_ratio`).
    pub key: &'static str,
    /// What the value is, in words.
    pub parameter: &'static str,
    /// The fitted value.
    pub value: f64,
    /// The range the fit scans, `[low, high]`.
    pub range: [f64; 2],
    /// The value's unit.
    pub unit: &'static str,
    /// The fit's grid step at that edge.
    pub step: f64,
    /// Which edge.
    pub edge: Edge,
    /// What lies beyond that edge.
    pub beyond: &'static str,
    /// Over several trials: how many of the trials' own fits lie on that edge, and of how
    /// many (`None`: one curve).
    pub trials_on_edge: Option<(usize, usize)>,
}

impl fmt::Display for EdgeWarning {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{} = {} ({}) lies on the {} edge of its range {} to {} {} (fit's grid step there {}{})",
            self.key,
            number(self.value),
            self.parameter,
            self.edge.word(),
            number(self.range[0]),
            number(self.range[1]),
            self.unit,
            number(self.step),
            match self.trials_on_edge {
                Some((k, n)) => format!("; {k} of {n} trials' own fits there"),
                None => String::new(),
            }
        )?;
        write!(f, ": the best fit may lie beyond it ({})", self.beyond)
    }
}

/// A value as people write it: at most four significant digits, no trailing zeros.
fn number(v: f64) -> String {
    let s = format!("{v:.4}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    if s == "-0" {
        "0".into()
    } else {
        s.into()
    }
}

/// The member weight's range, `[w_min, 1]`.
#[must_use]
pub fn weight_range() -> [f64; 2] {
    let lo = SQRT_WEIGHTS.first().copied().unwrap_or(1.0);
    let hi = SQRT_WEIGHTS.last().copied().unwrap_or(1.0);
    [lo * lo, hi * hi]
}

/// The weight grid's step at `edge`.
fn weight_step(edge: Edge) -> f64 {
    let n = SQRT_WEIGHTS.len();
    let (a, b) = match edge {
        Edge::Lower => (SQRT_WEIGHTS.first(), SQRT_WEIGHTS.get(1)),
        Edge::Upper => (SQRT_WEIGHTS.get(n.saturating_sub(2)), SQRT_WEIGHTS.last()),
    };
    match (a, b) {
        (Some(a), Some(b)) => (b * b - a * a).abs(),
        _ => 0.0,
    }
}

/// The onset ratio's range and its grid step.
fn onset_ratio_range() -> ([f64; 2], f64) {
    let lo = ONSET_RATIOS.first().copied().unwrap_or(0.0);
    let hi = ONSET_RATIOS.last().copied().unwrap_or(0.0);
    let step = match (ONSET_RATIOS.first(), ONSET_RATIOS.get(1)) {
        (Some(a), Some(b)) => b - a,
        _ => 0.0,
    };
    ([lo, hi], step)
}

/// Which edge of `range` `value` lies on (closer than `step(edge)`), if any.
fn on_edge(value: f64, range: [f64; 2], step: impl Fn(Edge) -> f64) -> Option<Edge> {
    // a grid point one step inside is not on the edge (rounding of the squares aside)
    let near = |edge: f64, s: f64| (value - edge).abs() < s * (1.0 - 1e-9);
    if near(range[0], step(Edge::Lower)) {
        Some(Edge::Lower)
    } else if near(range[1], step(Edge::Upper)) {
        Some(Edge::Upper)
    } else {
        None
    }
}

/// The member weight's warning for `w`, if it lies on an edge; `paper_pinned`: whether
/// the least-squares best is the paper's tissue too (the upper edge warns only then).
#[must_use]
pub fn weight_warning(w: f64, paper_pinned: bool) -> Option<EdgeWarning> {
    let range = weight_range();
    let edge = on_edge(w, range, weight_step)?;
    if edge == Edge::Upper && !paper_pinned {
        return None;
    }
    Some(EdgeWarning {
        key: "family_weight",
        parameter: "the material family's member: weight of the paper's Ogden terms",
        value: w,
        range,
        unit: "(dimensionless)",
        step: weight_step(edge),
        edge,
        beyond: match edge {
            Edge::Lower => "the measured curve stiffens less than the softest member the FE covers; a softer member needs FE runs below this weight and a family law fitted on them",
            Edge::Upper => "the measured curve stiffens as much as the paper's material or more; the family has no stiffer member",
        },
        trials_on_edge: None,
    })
}

/// The softening onset ratio's warning for `r0`, if the fit softens and `r0` lies on an
/// edge.
#[must_use]
pub fn onset_ratio_warning(fraction: f64, r0: f64) -> Option<EdgeWarning> {
    if fraction <= 0.0 {
        return None;
    }
    let (range, step) = onset_ratio_range();
    let edge = on_edge(r0, range, |_| step)?;
    Some(EdgeWarning {
        key: "softening_onset_ratio",
        parameter: "where the pre-puncture softening starts, fraction of the elastic force at the puncture",
        value: r0,
        range,
        unit: "(fraction)",
        step,
        edge,
        beyond: match edge {
            Edge::Lower => "the measured force flattens from further below the puncture than the softening scans",
            Edge::Upper => "the measured force flattens only in the last moments before the puncture",
        },
        trials_on_edge: None,
    })
}

/// The warnings of one shape fit, member first.
#[must_use]
pub fn of_shape(fit: &ShapeFit) -> Vec<EdgeWarning> {
    let pinned = on_edge(fit.least_squares_weight, weight_range(), weight_step) == Some(Edge::Upper);
    weight_warning(fit.weight, pinned).into_iter().chain(onset_ratio_warning(fit.softening.fraction, fit.softening.onset_ratio)).collect()
}

/// The warnings of a stack fitted on several trials: its first layer's member `w` and
/// softening (`fraction`, `r0`: the trials' median and means), each with how many of the
/// trials' own fits lie on the same edge (`fits`: each trial's warnings, its fit's
/// `edges`). The paper's tissue warns when one of the trials' fits is pinned to it.
#[must_use]
pub fn of_trials(w: f64, fraction: f64, r0: f64, fits: &[&[EdgeWarning]]) -> Vec<EdgeWarning> {
    let count = |key: &str, edge: Edge| fits.iter().filter(|f| f.iter().any(|e| e.key == key && e.edge == edge)).count();
    let pinned = count("family_weight", Edge::Upper) > 0;
    weight_warning(w, pinned)
        .into_iter()
        .chain(onset_ratio_warning(fraction, r0))
        .map(|mut e| {
            e.trials_on_edge = Some((count(e.key, e.edge), fits.len()));
            e
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_edge_grid_point_warns_its_neighbour_does_not() {
        let [lo, hi] = weight_range();
        let w = weight_warning(lo, false).expect("the softest member is on the edge");
        assert_eq!((w.edge, w.key), (Edge::Lower, "family_weight"));
        let text = w.to_string();
        assert!(text.contains("family_weight = 0.01") && text.contains("range 0.01 to 1"), "{text}");
        let next = SQRT_WEIGHTS[1] * SQRT_WEIGHTS[1];
        assert_eq!(weight_warning(next, false), None, "w = {next} is one grid step inside");
        assert_eq!(weight_warning(hi, false), None, "the paper's tissue kept as the simplest model");
        assert_eq!(weight_warning(hi, true).map(|w| w.edge), Some(Edge::Upper));
        assert_eq!(onset_ratio_warning(0.0, ONSET_RATIOS[0]), None, "no softening: no onset");
        assert_eq!(onset_ratio_warning(0.2, ONSET_RATIOS[0]).map(|w| w.edge), Some(Edge::Lower));
        assert_eq!(onset_ratio_warning(0.2, ONSET_RATIOS[1]), None);
    }
}
