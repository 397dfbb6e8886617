//! The stack's values from a measured curve: contact onset and the first boundary's
//! shape (scale, material family member, pre-puncture softening: [`crate::shape`]), then
//! per interval between punctures the cutting force and friction of the layer being cut
//! and the next boundary's depth and scale (as the first boundary's member). Each scale
//! is one linear least-squares coefficient against the FE surrogate's curve (the
//! scaling law); a depth (onset, boundary) is scanned on a grid and the one with the
//! smallest sum of squares kept.
use crate::events::Puncture;
use crate::lsq;
use crate::measured::Point;
use crate::shape::{self, Softening};
use needle_haptics::float::family::{ratio, FamilyMember};

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
    /// The material family's member the boundary deflects as (1: the paper's tissue).
    pub family_weight: f64,
    /// Its fitted range ([`shape::ShapeFit::weight_range`]); `None`: not fitted.
    pub family_weight_range: Option<[f64; 2]>,
    /// The boundary's pre-puncture softening ([`Softening::NONE`]: none).
    pub softening: Softening,
    /// The softening fraction's fitted range; `None`: not fitted.
    pub softening_fraction_range: Option<[f64; 2]>,
}

impl LayerFit {
    /// A layer of the paper's tissue without softening (the shape fit's defaults).
    #[must_use]
    pub fn plain(boundary_mm: f64, scale: f64, puncture_force_n: f64, cutting_force_n: f64, friction_n_per_mm: f64) -> Self {
        Self {
            boundary_mm,
            scale,
            puncture_force_n,
            cutting_force_n,
            friction_n_per_mm,
            family_weight: 1.0,
            family_weight_range: None,
            softening: Softening::NONE,
            softening_fraction_range: None,
        }
    }
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
    /// The first boundary's shape values that lie on their range's edge
    /// ([`crate::edges::of_shape`]).
    pub edges: Vec<crate::edges::EdgeWarning>,
}

/// Fits the stack. `surrogate(depth_mm)` is the axial force of a boundary indented by
/// `depth_mm` with scale 1 (the library's [`deflection`](needle_haptics::insertion::deflection)
/// at the measured pose and needle), `similarity` the needle's `λ`. The first boundary's
/// shape (contact onset, scale, family member, softening) is [`shape::fit`]'s; the
/// boundaries below deflect as the same member (one tissue), without softening.
#[must_use]
pub fn fit(points: &[Point], punctures: &[Puncture], surrogate: &dyn Fn(f64) -> f64, similarity: f64) -> Fit {
    fit_with_progress(points, punctures, surrogate, similarity, &mut |_, _| {})
}

/// [`fit`], telling `progress` how far the scans are.
#[must_use]
pub fn fit_with_progress(
    points: &[Point],
    punctures: &[Puncture],
    surrogate: &dyn Fn(f64) -> f64,
    similarity: f64,
    progress: Progress<'_>,
) -> Fit {
    let first_peak = punctures.first().map_or(points.len() - 1, |p| p.peak);
    let pre: Vec<Point> = points.iter().take(first_peak + 1).copied().collect();
    let start = points.iter().map(|p| p.position_mm).fold(f64::INFINITY, f64::min);
    let total = scan_count(points, punctures, start, start);
    let mut done = 0;
    let Some(first) = shape::fit(&thin(&pre), surrogate, similarity) else {
        let last_depth_mm = points.last().map_or(0.0, |p| p.position_mm - start);
        return Fit { onset_mm: start, layers: Vec::new(), last_depth_mm, edges: Vec::new() };
    };
    let onset = first.onset_mm;
    let member = FamilyMember::new(first.weight as f32);
    // the boundaries below deflect as the same member
    let member_surrogate = |d: f64| match &member {
        Some(m) => surrogate(d) * f64::from(ratio((d / similarity) as f32, m).0),
        None => surrogate(d),
    };
    let surrogate: &dyn Fn(f64) -> f64 = &member_surrogate;
    let mut layers = vec![LayerFit {
        family_weight: first.weight,
        family_weight_range: Some(first.weight_range),
        softening: first.softening,
        softening_fraction_range: Some(first.fraction_range),
        ..LayerFit::plain(0.0, first.scale, pre.last().map_or(0.0, |p| p.force_n), 0.0, 0.0)
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
            layers.push(LayerFit { family_weight: first.weight, ..LayerFit::plain(boundary, scale, puncture, 0.0, 0.0) });
        }
    }
    Fit { onset_mm: onset, layers, last_depth_mm: depth(points.len() - 1), edges: crate::edges::of_shape(&first) }
}

/// How many candidates the scans of [`fit_with_progress`] try (an onset scan from
/// `start` to `peak0`, then each interval's boundary), for its progress.
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

/// `lo, lo + step, ...` below `hi`: [`SCAN_STEP_MM`], or the step of
/// [`MAX_SCAN_CANDIDATES`] over a longer range.
fn scan(lo: f64, hi: f64) -> impl ExactSizeIterator<Item = f64> {
    let step = SCAN_STEP_MM.max((hi - lo) / MAX_SCAN_CANDIDATES as f64);
    let n = if step.is_finite() { ((hi - lo) / step).floor().clamp(0.0, MAX_SCAN_CANDIDATES as f64) as usize } else { 0 };
    (0..n).map(move |k| lo + step * k as f64)
}
