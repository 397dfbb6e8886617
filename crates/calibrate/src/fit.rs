//! The stack's values from a measured curve: contact onset and the first boundary's
//! stiffness scale (pre-puncture), then per interval between punctures the cutting
//! force and friction of the layer being cut and the next boundary's depth and scale.
//! Each scale is one linear least-squares coefficient against the FE surrogate's curve
//! (the scaling law); a depth (onset, boundary) is scanned on a grid and the one with
//! the smallest sum of squares kept.
use crate::events::Puncture;
use crate::lsq;
use crate::measured::Point;

/// Grid step of the onset and boundary scans, mm.
pub const SCAN_STEP_MM: f64 = 0.01;
/// The onset is the least-squares best among those whose model curve crosses the onset
/// threshold ([`crate::replay::ONSET_FRACTION`] of the first puncture force) within this
/// distance of the measured curve's crossing, mm (the unconstrained best when none does):
/// contact onset is a goal of its own, which the least squares over the whole rise,
/// weighted by the larger forces, would trade away.
pub const ONSET_MATCH_MM: f64 = 0.25;

/// The fitted values of one layer (boundary from the surface, mm of tip depth).
#[derive(Debug, Clone, PartialEq)]
pub struct LayerFit {
    /// Depth of the layer's upper boundary below the surface, mm.
    pub boundary_mm: f64,
    /// Stiffness scale of the boundary.
    pub scale: f64,
    /// The puncture threshold, N: the measured peak force less the model's shaft
    /// friction there (so the model's whole force at the puncture is the measured
    /// peak); the fitted deflection force at the peak when the friction is larger.
    pub puncture_force_n: f64,
    /// Cutting force while cutting the layer, N.
    pub cutting_force_n: f64,
    /// Friction per mm of shaft in the layer at the measured speed, N/mm.
    pub friction_n_per_mm: f64,
}

/// The whole fit.
#[derive(Debug, Clone, PartialEq)]
pub struct Fit {
    /// Needle position at contact (depth 0), mm.
    pub onset_mm: f64,
    /// The layers, from the surface down.
    pub layers: Vec<LayerFit>,
    /// Depth of the last point, mm (the last layer's thickness reaches it).
    pub last_depth_mm: f64,
}

/// Fits the stack. `surrogate(depth_mm)` is the axial force of a boundary indented by
/// `depth_mm` with scale 1 (the library's [`deflection`](needle_haptics::insertion::deflection)
/// at the measured pose and needle).
#[must_use]
pub fn fit(points: &[Point], punctures: &[Puncture], surrogate: &dyn Fn(f64) -> f64) -> Fit {
    let first_peak = punctures.first().map_or(points.len() - 1, |p| p.peak);
    let pre: Vec<&Point> = points.iter().take(first_peak + 1).collect();
    let peak0 = pre.last().map_or(0.0, |p| p.position_mm);
    let start = points.iter().map(|p| p.position_mm).fold(f64::INFINITY, f64::min);
    let peak_force = pre.last().map_or(0.0, |p| p.force_n);
    let threshold = crate::replay::ONSET_FRACTION * peak_force;
    let measured_crossing = crate::replay::measured_onset(points, first_peak, threshold);
    // (sse, onset, scale) of the best candidate whose model crosses the onset threshold
    // within ONSET_MATCH_MM of the measured crossing, and of the best of all
    let (mut matched, mut any) = ((f64::INFINITY, start, 0.0), (f64::INFINITY, start, 0.0));
    for onset in scan(start, peak0) {
        let column: Vec<f64> = pre.iter().map(|p| indent(surrogate, p.position_mm - onset)).collect();
        let rhs: Vec<f64> = pre.iter().map(|p| p.force_n).collect();
        let (x, sse) = lsq::non_negative(&[column], &rhs);
        if sse < any.0 {
            any = (sse, onset, x[0]);
        }
        let crossing = crossing_depth(surrogate, threshold, x[0], peak0 - onset).map(|d| onset + d);
        let near = matches!((crossing, measured_crossing), (Some(c), Some(m)) if (c - m).abs() <= ONSET_MATCH_MM);
        if near && sse < matched.0 {
            matched = (sse, onset, x[0]);
        }
    }
    let (_, onset, scale0) = if matched.0.is_finite() { matched } else { any };
    let mut layers = vec![LayerFit {
        boundary_mm: 0.0,
        scale: scale0,
        puncture_force_n: pre.last().map_or(0.0, |p| p.force_n),
        cutting_force_n: 0.0,
        friction_n_per_mm: 0.0,
    }];
    let depth = |i: usize| points.get(i).map_or(0.0, |p| p.position_mm - onset);
    for (k, event) in punctures.iter().enumerate() {
        let next_peak = punctures.get(k + 1).map(|p| p.peak);
        let end = next_peak.unwrap_or(points.len() - 1);
        let interval: Vec<(f64, f64)> =
            (event.bottom..=end).filter_map(|i| points.get(i)).map(|p| (p.position_mm - onset, p.force_n)).collect();
        let before: f64 = layers.windows(2).map(|w| w[0].friction_n_per_mm * (w[1].boundary_mm - w[0].boundary_mm)).sum();
        let top = layers.last().map_or(0.0, |l| l.boundary_mm);
        let fitted = interval_fit(&interval, top, before, next_peak.map(|p| (depth(event.bottom), depth(p))), surrogate);
        if let Some(current) = layers.last_mut() {
            current.cutting_force_n = fitted.cutting_n;
            current.friction_n_per_mm = fitted.friction_n_per_mm;
        }
        if let Some((boundary, scale)) = fitted.next {
            let friction = before + fitted.friction_n_per_mm * (boundary - top);
            let measured = points.get(end).map_or(0.0, |p| p.force_n);
            let deflection = scale * indent(surrogate, depth(end) - boundary);
            // the model punctures when deflection plus the carried cutting force reach it
            let puncture = if measured - friction > 0.0 { measured - friction } else { deflection + fitted.cutting_n };
            layers.push(LayerFit {
                boundary_mm: boundary,
                scale,
                puncture_force_n: puncture,
                cutting_force_n: 0.0,
                friction_n_per_mm: 0.0,
            });
        }
    }
    Fit { onset_mm: onset, layers, last_depth_mm: depth(points.len() - 1) }
}

struct IntervalFit {
    cutting_n: f64,
    friction_n_per_mm: f64,
    next: Option<(f64, f64)>,
}

/// One interval after a puncture: the tip cuts the layer below `top` (friction `before`
/// from the layers above), then, when `scan` gives the range of the next boundary,
/// deflects that boundary until the interval's last point, the cutting force carried
/// onto it (the insertion model's carried cutting: the cutting column is 1 over the
/// whole interval).
fn interval_fit(
    points: &[(f64, f64)],
    top: f64,
    before: f64,
    scan_range: Option<(f64, f64)>,
    surrogate: &dyn Fn(f64) -> f64,
) -> IntervalFit {
    let rhs: Vec<f64> = points.iter().map(|(_, f)| f - before).collect();
    let Some((lo, hi)) = scan_range else {
        let columns = vec![vec![1.0; points.len()], points.iter().map(|(d, _)| d - top).collect()];
        let (x, _) = lsq::non_negative(&columns, &rhs);
        return IntervalFit { cutting_n: x[0], friction_n_per_mm: x[1], next: None };
    };
    let mut best: Option<(f64, IntervalFit)> = None;
    for boundary in scan(lo.max(top), hi) {
        let columns = vec![
            vec![1.0; points.len()],
            points.iter().map(|(d, _)| d.min(boundary) - top).collect(),
            points.iter().map(|(d, _)| indent(surrogate, d - boundary)).collect(),
        ];
        let (x, sse) = lsq::non_negative(&columns, &rhs);
        if best.as_ref().is_none_or(|(s, _)| sse < *s) && x[2] > 0.0 {
            best = Some((sse, IntervalFit { cutting_n: x[0], friction_n_per_mm: x[1], next: Some((boundary, x[2])) }));
        }
    }
    best.map_or(IntervalFit { cutting_n: 0.0, friction_n_per_mm: 0.0, next: None }, |(_, f)| f)
}

/// The surrogate at `depth_mm` of indentation, zero before contact.
fn indent(surrogate: &dyn Fn(f64) -> f64, depth_mm: f64) -> f64 {
    if depth_mm > 0.0 {
        surrogate(depth_mm)
    } else {
        0.0
    }
}

/// The depth (below `max_mm`) where `scale` times the surrogate first reaches
/// `threshold_n`, by bisection on the monotone pre-puncture curve; `None` if it never does.
fn crossing_depth(surrogate: &dyn Fn(f64) -> f64, threshold_n: f64, scale: f64, max_mm: f64) -> Option<f64> {
    if scale <= 0.0 || max_mm <= 0.0 || scale * surrogate(max_mm) < threshold_n {
        return None;
    }
    let (mut lo, mut hi) = (0.0, max_mm);
    for _ in 0..40 {
        let mid = 0.5 * (lo + hi);
        if scale * indent(surrogate, mid) < threshold_n {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    Some(hi)
}

/// `lo, lo + step, ...` below `hi`.
fn scan(lo: f64, hi: f64) -> impl Iterator<Item = f64> {
    let n = ((hi - lo) / SCAN_STEP_MM).floor().max(0.0) as usize;
    (0..n).map(move |k| lo + SCAN_STEP_MM * k as f64)
}
