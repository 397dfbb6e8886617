//! A tissue stack from a published piecewise force-depth model (`needle
//! calibrate-published`): a table of polynomial pieces, each the axial force against
//! the depth inside it, grouped into anatomical layers (format: `pieces.csv` of
//! `coeffs/<set>/measured/<source>/`, its README says where every row comes from).
//!
//! No measured curve, so no puncture search: the published layers fix the boundaries and
//! every value follows from the published force `F(d)` by these rules (each layer `j`,
//! top `t_j`, sampled every [`STEP_MM`] along the depth, `before_j` the shaft friction
//! of the layers above over their whole thickness):
//!
//! 1. thickness: the sum of the layer's published piece thicknesses;
//! 2. puncture: where the published force stops rising from the layer's top (`p_j`, the
//!    peak before its drop; it may lie in the layer below, whose rise then starts past
//!    it), the puncture force is `F(p_j) - before_j`;
//! 3. stiffness scale: the least-squares `s` of `s g(d - t_j)` against
//!    `F(d) - before_j - c_{j-1}` over `t_j < d <= p_j` (`g` the library's deflection at
//!    scale 1, the scaling law; `c_{j-1}` the cutting force of the layer above, which the
//!    insertion model carries onto the boundary: the published model, too, starts each
//!    rise from the level reached before it);
//! 4. cutting and friction: non-negative least squares of `c + f (d - t_j)` against
//!    `F(d) - before_j` over the layer past `p_j` (none: both 0), `f` kept only when it
//!    lowers the sum of squares by more than f64 round-off;
//! 5. a layer whose published force does not rise from its start (the epidural space's
//!    0 N; the fat, which starts past the skin's peak and only falls), or whose peak
//!    `F(p_j) - before_j` does not exceed the cutting force carried onto it (the muscle:
//!    its published peak, 4.35 N, lies below the fat's cutting force), has no boundary
//!    force of its own: it punctures at contact (the
//!    smallest positive normal f32 as its puncture force, [`NO_RESISTANCE_N`]: the
//!    format refuses 0) and takes the stiffness scale of the layer above (its upper
//!    boundary is that layer's lower surface; the scale sets its track's hold);
//! 6. as `needle calibrate`: friction all Coulomb, stick band
//!    [`STICK_BAND_MM_PER_S`](crate::STICK_BAND_MM_PER_S), track stiffness `3 s mu0`.
use crate::events::Puncture;
use crate::fit::{Fit, LayerFit};
use crate::lsq;
use crate::measured::Point;
use anyhow::{bail, Context, Result};
use std::path::Path;

/// Sampling step of the published force along the depth, mm (the calibrator's scan step).
pub const STEP_MM: f64 = crate::fit::SCAN_STEP_MM;

/// The puncture force of a boundary the published model gives no force (rule 5), N:
/// the smallest positive normal f32 (the tissue format refuses 0).
pub const NO_RESISTANCE_N: f64 = f32::MIN_POSITIVE as f64;

/// One published piece: `F(x) = c0 + c1 x + c2 x² + c3 x³`, `x` mm from the piece's top.
#[derive(Debug, Clone, PartialEq)]
pub struct Piece {
    /// The piece's name in its source.
    pub piece: String,
    /// The anatomical layer it belongs to (consecutive pieces of one layer form it).
    pub layer: String,
    /// Its thickness, mm.
    pub thickness_mm: f64,
    /// `c0` N, `c1` N/mm, `c2` N/mm², `c3` N/mm³.
    pub coeffs: [f64; 4],
    /// 1-based line of the row in its file.
    pub line: usize,
}

impl Piece {
    /// The published force `x_mm` below the piece's top, N.
    #[must_use]
    pub fn force_n(&self, x_mm: f64) -> f64 {
        let [c0, c1, c2, c3] = self.coeffs;
        c0 + x_mm * (c1 + x_mm * (c2 + x_mm * c3))
    }
}

/// The columns of a pieces file.
pub const COLUMNS: [&str; 7] = ["piece", "layer", "thickness_mm", "c0_n", "c1_n_per_mm", "c2_n_per_mm2", "c3_n_per_mm3"];

/// Reads the pieces, in file order (other columns ignored).
///
/// # Errors
/// Unreadable file, a missing column, a value that is not a finite number, a thickness
/// that is not > 0 (`FILE:LINE: column NAME: ...`), no piece, a layer whose pieces are
/// not consecutive.
pub fn read_pieces(path: &Path) -> Result<Vec<Piece>> {
    let mut reader =
        csv::ReaderBuilder::new().trim(csv::Trim::All).from_path(path).with_context(|| format!("{}: cannot read", path.display()))?;
    let header = reader.headers().with_context(|| format!("{}:1: cannot read the header", path.display()))?.clone();
    let mut index = [0usize; 7];
    for (slot, name) in index.iter_mut().zip(COLUMNS) {
        *slot = header
            .iter()
            .position(|h| h == name)
            .with_context(|| format!("{}:1: no column {name:?} (needed: {COLUMNS:?})", path.display()))?;
    }
    let mut pieces: Vec<Piece> = Vec::new();
    for record in reader.records() {
        let record = record.with_context(|| format!("{}: malformed CSV", path.display()))?;
        let line = record.position().map_or(0, |p| p.line() as usize);
        let text = |k: usize| record.get(index[k]).unwrap_or("").to_string();
        let number = |k: usize| -> Result<f64> {
            let t = text(k);
            let v: f64 =
                t.parse().map_err(|_| anyhow::anyhow!("{}:{line}: column {}: {t:?} is not a number", path.display(), COLUMNS[k]))?;
            if !v.is_finite() {
                bail!("{}:{line}: column {}: {t:?} is not finite", path.display(), COLUMNS[k]);
            }
            Ok(v)
        };
        let thickness_mm = number(2)?;
        if thickness_mm <= 0.0 {
            bail!("{}:{line}: column thickness_mm: {thickness_mm} must be > 0", path.display());
        }
        let layer = text(1);
        let seen_before = pieces.iter().any(|p| p.layer == layer) && pieces.last().is_some_and(|p| p.layer != layer);
        if seen_before {
            bail!("{}:{line}: layer {layer:?}: its pieces must be consecutive", path.display());
        }
        pieces.push(Piece { piece: text(0), layer, thickness_mm, coeffs: [number(3)?, number(4)?, number(5)?, number(6)?], line });
    }
    if pieces.is_empty() {
        bail!("{}: no piece", path.display());
    }
    Ok(pieces)
}

/// The published force sampled every [`STEP_MM`] from the surface to the last piece's
/// bottom, as measured points (`line` 0): at a boundary between pieces both the upper
/// piece's end and the lower piece's start, so a published jump stays a jump.
#[must_use]
pub fn sample(pieces: &[Piece]) -> Vec<Point> {
    samples(pieces).into_iter().map(|s| Point { position_mm: s.depth_mm, force_n: s.force_n, line: 0 }).collect()
}

/// One sample of the published force and the index of its piece.
struct Sample {
    depth_mm: f64,
    force_n: f64,
    piece: usize,
}

fn samples(pieces: &[Piece]) -> Vec<Sample> {
    let mut out = Vec::new();
    let mut top = 0.0;
    for (i, p) in pieces.iter().enumerate() {
        let n = (p.thickness_mm / STEP_MM).round().max(1.0) as usize;
        for k in 0..=n {
            let x = (k as f64 * STEP_MM).min(p.thickness_mm);
            out.push(Sample { depth_mm: top + x, force_n: p.force_n(x), piece: i });
        }
        top += p.thickness_mm;
    }
    out
}

/// One derived layer: its name, the fitted values and what the rules found.
#[derive(Debug, Clone, PartialEq)]
pub struct Derived {
    /// The anatomical layer.
    pub name: String,
    /// Its thickness, mm (rule 1).
    pub thickness_mm: f64,
    /// The values in the calibrator's form (boundary, scale, puncture, cutting, friction).
    pub fit: LayerFit,
    /// Index in [`sample`]'s points of the force the puncture drops from: the rise's
    /// peak, or for a layer without a rise (rule 5) the last sample above it.
    pub peak: usize,
    /// Whether the published force rises from the layer's start (rule 5 if not).
    pub rises: bool,
}

/// The layers of `pieces` by the module's rules; `surrogate(layer, depth_mm)` is the axial
/// force of the named layer's boundary indented by `depth_mm` at scale 1 (with its
/// relaxation function at the replay speed when it has one: `crate::ramp`).
///
/// # Errors
/// A first layer without a rise (nothing to take a scale from), or a fitted scale that is
/// not finite and > 0.
pub fn derive(pieces: &[Piece], surrogate: &dyn Fn(&str, f64) -> f64) -> Result<Vec<Derived>> {
    let all = samples(pieces);
    let mut out: Vec<Derived> = Vec::new();
    let (mut top, mut first_piece, mut after_peak) = (0.0, 0, 0);
    while let Some(first) = pieces.get(first_piece) {
        let count = pieces.iter().skip(first_piece).take_while(|p| p.layer == first.layer).count();
        let in_layer = |s: &Sample| s.piece >= first_piece && s.piece < first_piece + count;
        let thickness_mm: f64 = pieces.iter().skip(first_piece).take(count).map(|p| p.thickness_mm).sum();
        let before: f64 = out.iter().map(|l| l.fit.friction_n_per_mm * l.thickness_mm).sum();
        // the layer starts at its top, or past the peak of the layer above when that lies in it
        let start = all.iter().position(in_layer).unwrap_or(all.len()).max(after_peak);
        let mut peak = start;
        while all.get(peak + 1).zip(all.get(peak)).is_some_and(|(next, here)| next.force_n > here.force_n) {
            peak += 1;
        }
        let peak_force = all.get(peak).map_or(0.0, |s| s.force_n);
        let carried = out.last().map_or(0.0, |l| l.fit.cutting_force_n);
        let rises = peak > start && peak_force - before - carried > 0.0;
        let (scale, puncture_force_n, drop_from) = if rises {
            let (sg, gg) = all.get(start + 1..=peak).unwrap_or(&[]).iter().fold((0.0, 0.0), |(sg, gg), s| {
                let g = surrogate(&first.layer, s.depth_mm - top);
                (sg + g * (s.force_n - before - carried), gg + g * g)
            });
            (sg / gg, peak_force - before, peak)
        } else {
            let above = out.last().with_context(|| format!("layer {:?}: the first layer's published force never rises", first.layer))?;
            (above.fit.scale, NO_RESISTANCE_N, start.saturating_sub(1))
        };
        if !(scale.is_finite() && scale > 0.0) {
            bail!("layer {:?}: fitted stiffness scale {scale}: must be finite and > 0", first.layer);
        }
        let advance: Vec<&Sample> = all.iter().skip(peak + 1).take_while(|s| in_layer(s)).collect();
        let (cutting_force_n, friction_n_per_mm) = if advance.is_empty() {
            (0.0, 0.0)
        } else {
            let columns = vec![vec![1.0; advance.len()], advance.iter().map(|s| s.depth_mm - top).collect()];
            let rhs: Vec<f64> = advance.iter().map(|s| s.force_n - before).collect();
            let (x, sse) = lsq::non_negative(&columns, &rhs);
            // the friction column only when it lowers the sum of squares by more than
            // f64 round-off (a constant published force gives it ~1e-16 N/mm otherwise)
            let (c, sse_c) = lsq::non_negative(&columns[..1], &rhs);
            let round_off = f64::EPSILON * rhs.iter().map(|r| r * r).sum::<f64>();
            if sse_c <= sse + round_off {
                (c.first().copied().unwrap_or(0.0), 0.0)
            } else {
                (x.first().copied().unwrap_or(0.0), x.get(1).copied().unwrap_or(0.0))
            }
        };
        out.push(Derived {
            name: first.layer.clone(),
            thickness_mm,
            fit: LayerFit::plain(top, scale, puncture_force_n, cutting_force_n, friction_n_per_mm),
            peak: drop_from,
            rises,
        });
        after_peak = peak + 1;
        top += thickness_mm;
        first_piece += count;
    }
    Ok(out)
}

/// The derived layers as the calibrator's fit (contact onset at depth 0).
#[must_use]
pub fn as_fit(layers: &[Derived]) -> Fit {
    let last_depth_mm = layers.iter().map(|l| l.thickness_mm).sum();
    Fit { onset_mm: 0.0, layers: layers.iter().map(|l| l.fit.clone()).collect(), last_depth_mm, edges: Vec::new() }
}

/// The published punctures among [`sample`]'s points: each layer's `peak`, the next
/// point as the drop's bottom.
#[must_use]
pub fn events(points: &[Point], layers: &[Derived]) -> Vec<Puncture> {
    layers.iter().map(|l| Puncture { peak: l.peak, bottom: (l.peak + 1).min(points.len().saturating_sub(1)) }).collect()
}
