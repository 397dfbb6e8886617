//! The stack's values from a measured curve: contact onset and the first boundary's
//! stiffness scale (pre-puncture), then per interval between punctures the cutting
//! force and friction of the layer being cut and the next boundary's depth and scale.
//! Each scale is one linear least-squares coefficient against the FE surrogate's curve
//! (the scaling law); a depth (onset, boundary) is scanned on a grid and the one with
//! the smallest sum of squares kept.
use crate::events::Puncture;
use crate::lsq;
use crate::measured::Point;

/// Grid step of the onset and boundary scans, mm (coarser over a range longer than
/// [`MAX_SCAN_CANDIDATES`] steps).
pub const SCAN_STEP_MM: f64 = 0.01;
/// Most candidates of one scan (onset, or one boundary): the step grows over a longer
/// range, so the time of a fit is bounded whatever the curve's span.
pub const MAX_SCAN_CANDIDATES: usize = 5_000;
/// Most points a scan compares each candidate with (evenly thinned beyond: every k-th);
/// the chosen candidate's coefficients are then fitted on all points. The shipped curves
/// have fewer, so this bounds the time of a dense recording without changing them.
pub const MAX_SCAN_POINTS: usize = 1_000;

/// Progress of a fit: `(candidates scanned, candidates in all)`, called after each.
pub type Progress<'a> = &'a mut dyn FnMut(usize, usize);
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
    fit_with_progress(points, punctures, surrogate, &mut |_, _| {})
}

/// [`fit`], telling `progress` how far the scans are.
#[must_use]
pub fn fit_with_progress(points: &[Point], punctures: &[Puncture], surrogate: &dyn Fn(f64) -> f64, progress: Progress<'_>) -> Fit {
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
    let total = scan_count(points, punctures, start, peak0);
    let mut done = 0;
    let pre_scan = thin(&pre);
    let rhs: Vec<f64> = pre_scan.iter().map(|p| p.force_n).collect();
    for onset in scan(start, peak0) {
        let column: Vec<f64> = pre_scan.iter().map(|p| indent(surrogate, p.position_mm - onset)).collect();
        let (x, sse) = lsq::non_negative(&[column], &rhs);
        if sse < any.0 {
            any = (sse, onset, x[0]);
        }
        let crossing = crossing_depth(surrogate, threshold, x[0], peak0 - onset).map(|d| onset + d);
        let near = matches!((crossing, measured_crossing), (Some(c), Some(m)) if (c - m).abs() <= ONSET_MATCH_MM);
        if near && sse < matched.0 {
            matched = (sse, onset, x[0]);
        }
        done += 1;
        progress(done, total);
    }
    let (_, onset, mut scale0) = if matched.0.is_finite() { matched } else { any };
    if pre_scan.len() < pre.len() {
        // the chosen onset's scale on every point
        let column: Vec<f64> = pre.iter().map(|p| indent(surrogate, p.position_mm - onset)).collect();
        let rhs: Vec<f64> = pre.iter().map(|p| p.force_n).collect();
        scale0 = lsq::non_negative(&[column], &rhs).0[0];
    }
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
        let range = next_peak.map(|p| (depth(event.bottom), depth(p)));
        let fitted = interval_fit(&interval, top, before, range, surrogate, &mut |n| {
            done += n;
            progress(done.min(total), total);
        });
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

/// How many candidates the scans of [`fit_with_progress`] try (the onset's, then each
/// interval's boundary), for its progress.
fn scan_count(points: &[Point], punctures: &[Puncture], start: f64, peak0: f64) -> usize {
    let intervals = punctures.iter().enumerate().filter_map(|(k, e)| {
        let next = punctures.get(k + 1)?;
        Some(scan(points.get(e.bottom)?.position_mm - start, points.get(next.peak)?.position_mm - start).count())
    });
    scan(start, peak0).count() + intervals.sum::<usize>()
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
    scanned: &mut dyn FnMut(usize),
) -> IntervalFit {
    let Some((lo, hi)) = scan_range else {
        let rhs: Vec<f64> = points.iter().map(|(_, f)| f - before).collect();
        let columns = vec![vec![1.0; points.len()], points.iter().map(|(d, _)| d - top).collect()];
        let (x, _) = lsq::non_negative(&columns, &rhs);
        return IntervalFit { cutting_n: x[0], friction_n_per_mm: x[1], next: None };
    };
    let with_boundary = |points: &[(f64, f64)], boundary: f64| {
        let rhs: Vec<f64> = points.iter().map(|(_, f)| f - before).collect();
        let columns = vec![
            vec![1.0; points.len()],
            points.iter().map(|(d, _)| d.min(boundary) - top).collect(),
            points.iter().map(|(d, _)| indent(surrogate, d - boundary)).collect(),
        ];
        let (x, sse) = lsq::non_negative(&columns, &rhs);
        (sse, IntervalFit { cutting_n: x[0], friction_n_per_mm: x[1], next: Some((boundary, x[2])) })
    };
    let sparse = thin(points);
    let mut best: Option<(f64, IntervalFit)> = None;
    let lo = lo.max(top);
    for boundary in scan(lo, hi) {
        let (sse, f) = with_boundary(&sparse, boundary);
        if best.as_ref().is_none_or(|(s, _)| sse < *s) && f.next.is_some_and(|(_, s)| s > 0.0) {
            best = Some((sse, f));
        }
        scanned(1);
    }
    match best {
        // the chosen boundary's coefficients on every point
        Some((_, f)) if sparse.len() < points.len() => {
            let boundary = f.next.map_or(lo, |(b, _)| b);
            let (_, full) = with_boundary(points, boundary);
            if full.next.is_some_and(|(_, s)| s > 0.0) {
                full
            } else {
                f
            }
        }
        Some((_, f)) => f,
        None => IntervalFit { cutting_n: 0.0, friction_n_per_mm: 0.0, next: None },
    }
}

/// `points`, or every k-th of them when there are more than [`MAX_SCAN_POINTS`] (the
/// last one kept).
fn thin<T: Copy>(points: &[T]) -> Vec<T> {
    let every = points.len().div_ceil(MAX_SCAN_POINTS).max(1);
    if every == 1 {
        return points.to_vec();
    }
    let mut out: Vec<T> = points.iter().step_by(every).copied().collect();
    if !(points.len() - 1).is_multiple_of(every) {
        out.extend(points.last().copied());
    }
    out
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

/// `lo, lo + step, ...` below `hi`: [`SCAN_STEP_MM`], or the step of
/// [`MAX_SCAN_CANDIDATES`] over a longer range.
fn scan(lo: f64, hi: f64) -> impl ExactSizeIterator<Item = f64> {
    let step = SCAN_STEP_MM.max((hi - lo) / MAX_SCAN_CANDIDATES as f64);
    let n = if step.is_finite() { ((hi - lo) / step).floor().clamp(0.0, MAX_SCAN_CANDIDATES as f64) as usize } else { 0 };
    (0..n).map(move |k| lo + step * k as f64)
}
