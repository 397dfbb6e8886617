//! The stack from the trials' fits (steps 2-5 of the module docs of [`super`]): the
//! values, each with its uncertainty, and the tissue file's layers.
use super::friction::{self, LayerFriction};
use super::hold::{self, HoldFit};
use super::intervals;
use super::stats::Spread;
use super::trials::{self, Trial};
use super::TrialsOptions;
use anyhow::Result;
use needle_codegen::tissue as file;
use std::path::Path;

/// The fitted stack and what it came from.
#[derive(Debug, Clone)]
pub struct Fitted {
    /// The tissue file's contents.
    pub stack: file::Stack,
    /// Per layer, `(key, note)`: the uncertainty written beside each value.
    pub uncertainty: Vec<Vec<(&'static str, String)>>,
    /// The punctures per trial the stack was fitted for.
    pub punctures: usize,
    /// The friction per punctured layer.
    pub friction: Vec<LayerFriction>,
    /// After the last puncture and the hold.
    pub hold: HoldFit,
    /// The stick band, mm/s.
    pub stick_band_mm_per_s: f64,
    /// The shaft's presliding distance over the trials (mm; `None`: no withdrawal shows
    /// one, the stack keeps the Karnopp friction).
    pub presliding_mm: Option<Spread>,
    /// Per layer, `(key, spread over the trials)` of the values fitted per trial: what
    /// `needle stack sample` draws within ([`crate::spread`]).
    pub spread: Vec<Vec<(&'static str, Spread)>>,
}

/// Half the slowest measured speed, at most [`crate::STICK_BAND_MM_PER_S`]: the stick
/// band lies below every measured speed, so each renders its fitted sliding level.
#[must_use]
pub fn stick_band(trials: &[Trial]) -> f64 {
    let slowest = trials
        .iter()
        .flat_map(|t| [t.phases.insertion_speed_mm_per_s.abs(), t.phases.withdrawal_speed_mm_per_s.abs()])
        .filter(|v| *v > 0.0)
        .fold(f64::INFINITY, f64::min);
    (0.5 * slowest).min(crate::STICK_BAND_MM_PER_S)
}

/// The per-layer values before they become a file.
struct Values {
    bounds: Vec<f64>,
    scale: Vec<Spread>,
    puncture: Vec<Spread>,
    cutting: Vec<Spread>,
}

/// Fits the stack (module docs of [`super`]).
///
/// # Errors
/// The format refuses the stack (a value out of its range).
pub fn fit(ts: &[Trial], opts: &TrialsOptions<'_>, diameter: f64, u: &dyn Fn(f64) -> f64, notes: &mut Vec<String>) -> Result<Fitted> {
    let (n, count_notes) = trials::puncture_count(ts);
    notes.extend(count_notes);
    let used: Vec<Trial> = ts.iter().filter(|t| t.events.len() >= n).cloned().collect();
    let mean_of = |f: &dyn Fn(&Trial) -> Option<f64>| Spread::of(used.iter().filter_map(f).collect());
    // the first boundary's shape (issue 64): the trials' fitted member (their median) and
    // softening (their means), the scale through each trial's first peak with it
    let shape = first_shape(&used);
    let lambda = diameter / f64::from(needle_haptics::insertion::FE_NEEDLE_DIAMETER_MM);
    let member = needle_haptics::float::family::FamilyMember::new(shape.weight as f32);
    let u0 = |d: f64| u(d) * member.map_or(1.0, |m| f64::from(needle_haptics::float::family::ratio((d / lambda) as f32, &m).0));
    // today's fit gives the first layer and the first guess of the boundaries
    let mut v = Values {
        bounds: (0..n).map(|k| if k == 0 { 0.0 } else { mean_of(&|t| t.fit.layers.get(k).map(|l| l.boundary_mm)).mean }).collect(),
        // the first boundary's scale through each trial's first peak (today's shape, at
        // today's onset: the model punctures where and at the force the trial did)
        scale: vec![mean_of(&|t| {
            t.peak(0).map(|(p, f)| f / (u0(p - t.onset_mm()) * (1.0 - shape.fraction))).filter(|s| s.is_finite() && *s > 0.0)
        })],
        puncture: vec![mean_of(&|t| t.peak(0).map(|p| p.1))],
        cutting: Vec::new(),
    };
    let mut fr = friction_or_insertion(&used, &v.bounds, f64::INFINITY, None, n, notes);
    for _pass in 0..2 {
        intervals_pass(&used, n, &mut v, &fr, u);
        fr = friction_or_insertion(&used, &v.bounds, f64::INFINITY, None, n, notes);
    }
    let mut hold = hold::fit(&used, n, &v.bounds, &fr, u);
    // the model has no shaft friction below the boundary it deflects: once more with it
    if let Some(b) = hold.boundary_mm {
        fr = friction_or_insertion(&used, &v.bounds, b, None, n, notes);
        hold = hold::fit(&used, n, &v.bounds, &fr, u);
    }
    if hold.holds == 0 {
        notes.push("no trial has a hold: no Prony terms fitted (the stack is elastic)".into());
    }
    let band = stick_band(ts);
    let presliding = shaft_fit(&used, n, &v.bounds, band, u, (&mut hold, &mut fr), notes);
    let last_depth = ts.iter().flat_map(|t| t.samples.iter().map(|s| s.position_mm - t.onset_mm())).fold(0.0, f64::max);
    let largest = ts.iter().flat_map(|t| t.samples.iter().map(|s| s.force_n)).fold(0.0, f64::max);
    let source = source(opts, ts, band);
    let parts = Parts { n, v: &v, presliding: presliding.as_ref(), shape: &shape, band, last_depth, largest, opts, source: &source };
    let (layers, uncertainty, spread) = build(&parts, &fr, &hold);
    let stack = checked_stack(opts, ts.len(), diameter, layers)?;
    Ok(Fitted { stack, uncertainty, punctures: n, friction: fr, hold, stick_band_mm_per_s: band, presliding_mm: presliding, spread })
}

/// What the file's layers are made of.
struct Parts<'a> {
    n: usize,
    v: &'a Values,
    presliding: Option<&'a Spread>,
    shape: &'a FirstShape,
    band: f64,
    last_depth: f64,
    largest: f64,
    opts: &'a TrialsOptions<'a>,
    source: &'a str,
}

/// The file's layers of `p`, each value's uncertainty notes and the spreads.
#[allow(clippy::type_complexity)]
fn build(
    p: &Parts<'_>,
    fr: &[LayerFriction],
    hold: &HoldFit,
) -> (Vec<file::Layer>, Vec<Vec<(&'static str, String)>>, Vec<Vec<(&'static str, Spread)>>) {
    let (n, v) = (p.n, p.v);
    let mut layers = Vec::new();
    let (mut uncertainty, mut spread) = (Vec::new(), Vec::new());
    for j in 0..n {
        let below = v.bounds.get(j + 1).copied().or(hold.boundary_mm).unwrap_or(p.last_depth.max(v.bounds[j] + 1.0));
        let cutting =
            if j + 1 == n { hold.per_trial.cutting_n.clone() } else { v.cutting.get(j).cloned().unwrap_or(Spread::of(Vec::new())) };
        let cutting_n = if j + 1 == n { hold.cutting_n } else { cutting.mean };
        let f = fr.get(j).cloned().unwrap_or_else(zero_friction);
        spread.push(spreads(v.scale[j].clone(), v.puncture[j].clone(), Some(cutting.clone()), &f));
        let (mut l, mut notes) =
            layer(j, n, below - v.bounds[j], v.scale[j].clone(), v.puncture[j].clone(), (cutting_n, cutting), &f, p.band, p.opts, p.source);
        if let Some(pre) = p.presliding {
            with_presliding(&mut l, &mut notes, pre, hold);
        }
        if j == 0 {
            l.family_weight = p.shape.weight;
            l.softening_fraction = p.shape.fraction;
            l.softening_onset_ratio = p.shape.onset_ratio;
        }
        layers.push(l);
        uncertainty.push(notes);
    }
    if let (Some(b), Some(f)) = (hold.boundary_mm, fr.last()) {
        let (l, notes) = bottom_layer(n, p.last_depth - b + 1.0, p.largest, hold, f, p.band, p.opts, p.source);
        let scale = Spread { mean: hold.scale, ..hold.per_trial.scale.clone() };
        spread.push(spreads(scale, Spread::of(Vec::new()), None, f));
        layers.push(l);
        uncertainty.push(notes);
    }
    (layers, uncertainty, spread)
}

/// The stack of `layers`, checked by the tissue format's reader as the file will be read.
fn checked_stack(opts: &TrialsOptions<'_>, trials: usize, diameter: f64, layers: Vec<file::Layer>) -> Result<file::Stack> {
    let stack = file::Stack {
        format: file::TISSUE_FORMAT,
        name: opts.name.clone(),
        description: format!("calibrated by needle calibrate --trials on {trials} trials ({diameter} mm needle)"),
        needle_diameter_mm: diameter,
        layers,
    };
    file::parse_stack_str(&stack.to_toml(""), Path::new(&format!("{}.toml", stack.name)))
        .map_err(|e| anyhow::anyhow!("the calibrated stack is refused by the tissue format: {e}"))?;
    Ok(stack)
}

/// The shaft's presliding (the `hold` and `presliding` modules): its distance from the
/// withdrawals' onsets, then twice the shaft's terms from the holds (the relaxation's
/// columns carry the cutting force of the fit before; the arms slip at the stick band's
/// edge `band`, so the held force relaxes by the same share at every sliding speed)
/// and the
/// withdrawals' friction with the model's turn-over (and, when no boundary deflects, the
/// shaft reaching the stage's depth), then the terms once more; `None` (said in `notes`)
/// when no withdrawal turns the force over.
fn shaft_fit(
    used: &[Trial],
    n: usize,
    bounds: &[f64],
    band: f64,
    u: &dyn Fn(f64) -> f64,
    (hold, fr): (&mut HoldFit, &mut Vec<LayerFriction>),
    notes: &mut Vec<String>,
) -> Option<Spread> {
    let Some(p) = super::presliding::distance(used) else {
        notes.push(
            "no trial has a withdrawal that turns the force over: no presliding fitted (the shaft's friction is zero at rest)".into(),
        );
        return None;
    };
    for pass in 0..3 {
        let guess = hold::ShaftGuess { presliding_mm: p.mean, cutting_n: hold.cutting_n, slip_speed_mm_per_s: band };
        *hold = hold::fit_with_shaft(used, n, bounds, fr, u, hold, &guess);
        if pass < 2 {
            let long_term = 1.0 / (1.0 + hold.shaft_prony.iter().map(|t| t.0).sum::<f64>());
            let tv = friction::Turnover { presliding_mm: p.mean, long_term };
            *fr = friction_or_insertion(used, bounds, hold.boundary_mm.unwrap_or(f64::INFINITY), Some(&tv), n, notes);
        }
    }
    Some(p)
}

/// A punctured layer's presliding: the distance over the trials and the shaft's terms of
/// the hold's fit, each with its uncertainty.
fn with_presliding(l: &mut file::Layer, notes: &mut Vec<(&'static str, String)>, p: &Spread, hold: &HoldFit) {
    l.presliding_mm = Some(p.mean);
    l.relaxation_slip_mm = hold.shaft_slip_mm;
    l.shaft_prony = hold.shaft_prony.iter().map(|&(g, tau_s)| file::PronyTerm { g, tau_s }).collect();
    notes.push(("presliding_mm", format!("{} (the withdrawals' onsets: travel to the midpoint of the turn-over)", p.note("mm"))));
    if l.relaxation_slip_mm.is_some() {
        notes.push((
            "relaxation_slip_mm",
            "the stick band's edge times the shortest shaft time constant: each term slips at every speed above the stick band".into(),
        ));
    }
    if !l.shaft_prony.is_empty() {
        let g: Vec<String> =
            hold.shaft_g.iter().zip(&hold.shaft_prony).map(|(s, (_, tau))| format!("g(tau {tau:.3} s) {}", s.note("-"))).collect();
        let below = if hold.prony.is_empty() { "no boundary below" } else { "the boundary below relaxes through the same terms" };
        notes.push(("shaft_prony", format!("{} (the holds; {below})", g.join("; "))));
    }
}

/// A layer's spreads over the trials: its scale, puncture force and cutting force (those
/// fitted per trial: an empty spread is left out) and its Coulomb friction when the
/// friction has no viscous term (the per-trial levels are then Coulomb levels).
fn spreads(scale: Spread, puncture: Spread, cutting: Option<Spread>, f: &LayerFriction) -> Vec<(&'static str, Spread)> {
    let friction = (f.viscous_n_s_per_mm2 == 0.0).then(|| f.levels.clone());
    [
        ("stiffness_scale", Some(scale)),
        ("puncture_force_n", Some(puncture)),
        ("cutting_force_n", cutting),
        ("friction_coulomb_n_per_mm", friction),
    ]
    .into_iter()
    .filter_map(|(k, s)| s.filter(|s| !s.values.is_empty()).map(|s| (k, s)))
    .collect()
}

/// The first boundary's shape over the trials.
struct FirstShape {
    weight: f64,
    fraction: f64,
    onset_ratio: f64,
}

/// The median of the trials' fitted members and the means of their softenings (each
/// trial's [`crate::shape`] fit); the paper's tissue without softening when none has one.
fn first_shape(ts: &[Trial]) -> FirstShape {
    let firsts: Vec<&crate::fit::LayerFit> = ts.iter().filter_map(|t| t.fit.layers.first()).collect();
    let mut weights: Vec<f64> = firsts.iter().map(|l| l.family_weight).collect();
    weights.sort_by(f64::total_cmp);
    let weight = weights.get(weights.len() / 2).copied().unwrap_or(1.0);
    let n = firsts.len().max(1) as f64;
    let fraction = firsts.iter().map(|l| l.softening.fraction).sum::<f64>() / n;
    let softened: Vec<f64> = firsts.iter().filter(|l| l.softening.fraction > 0.0).map(|l| l.softening.onset_ratio).collect();
    let onset_ratio = if fraction > 0.0 && !softened.is_empty() { softened.iter().sum::<f64>() / softened.len() as f64 } else { 0.0 };
    FirstShape { weight, fraction: if onset_ratio > 0.0 || fraction == 0.0 { fraction } else { 0.0 }, onset_ratio }
}

/// The layer below the last puncture: deflected, never punctured, with the holds' Prony
/// terms.
#[allow(clippy::too_many_arguments)]
fn bottom_layer(
    n: usize,
    thickness_mm: f64,
    largest: f64,
    hold: &HoldFit,
    f: &LayerFriction,
    band: f64,
    opts: &TrialsOptions<'_>,
    source: &str,
) -> (file::Layer, Vec<(&'static str, String)>) {
    let scale = Spread { mean: hold.scale, ..hold.per_trial.scale.clone() };
    let (mut l, mut notes) =
        layer(n, n + 1, thickness_mm, scale, Spread::of(vec![2.0 * largest]), (0.0, Spread::of(Vec::new())), f, band, opts, source);
    l.name = "below the last puncture (deflected, never punctured)".into();
    l.puncture_force_n = 2.0 * largest;
    notes.retain(|(k, _)| *k != "puncture_force_n" && *k != "cutting_force_n");
    notes.push(("puncture_force_n", format!("not punctured in any trial: twice the largest measured force, {largest:.3} N")));
    l.prony = hold.prony.iter().map(|&(g, tau_s)| file::PronyTerm { g, tau_s }).collect();
    if !l.prony.is_empty() {
        let tied = hold.prony == hold.shaft_prony;
        l.prony_source = Some(format!(
            "needle calibrate --trials: fitted to the holds of {} trials (the library's QLV filter, FEBio's normalisation){}",
            hold.holds,
            if tied { "; the shaft's terms: one relaxation function for the tissue" } else { "" }
        ));
        let per = if tied { &hold.shaft_g } else { &hold.per_trial.g };
        let g: Vec<String> = per.iter().zip(&hold.prony).map(|(s, (_, tau))| format!("g(tau {tau:.3} s) {}", s.note("-"))).collect();
        notes.push(("prony", g.join("; ")));
    }
    (l, notes)
}

fn zero_friction() -> LayerFriction {
    LayerFriction { coulomb_n_per_mm: 0.0, coulomb_se: None, viscous_n_s_per_mm2: 0.0, viscous_se: None, levels: Spread::of(Vec::new()) }
}

/// The friction from the withdrawals, or (no trial has one) today's from the insertion,
/// said in `notes`.
fn friction_or_insertion(
    used: &[Trial],
    bounds: &[f64],
    next_mm: f64,
    turnover: Option<&friction::Turnover>,
    n: usize,
    notes: &mut Vec<String>,
) -> Vec<LayerFriction> {
    if let Some(f) = friction::fit(used, bounds, next_mm, turnover) {
        return f;
    }
    let msg = "no trial has a withdrawal that pulls the needle back: the friction is fitted on the insertion (all Coulomb at its speed)"
        .to_string();
    if !notes.contains(&msg) {
        notes.push(msg);
    }
    (0..n)
        .map(|j| {
            let levels = Spread::of(used.iter().filter_map(|t| t.fit.layers.get(j).map(|l| l.friction_n_per_mm)).collect());
            LayerFriction { coulomb_n_per_mm: levels.mean, coulomb_se: levels.se, viscous_n_s_per_mm2: 0.0, viscous_se: None, levels }
        })
        .collect()
}

/// The intervals between punctures (each layer directly under another), per trial: the
/// boundaries, puncture forces and cutting forces their means, the scale the one with
/// which the model reaches the mean puncture force at the trials' mean puncture depth.
fn intervals_pass(used: &[Trial], n: usize, v: &mut Values, fr: &[LayerFriction], u: &dyn Fn(f64) -> f64) {
    v.scale.truncate(1);
    v.puncture.truncate(1);
    v.cutting.clear();
    for k in 0..n.saturating_sub(1) {
        let bounds = v.bounds[..=k].to_vec();
        let fits: Vec<intervals::IntervalFit> =
            used.iter().filter_map(|t| intervals::fit(t, k, &bounds, &fr[..=k.min(fr.len() - 1)], u)).collect();
        let col = |f: &dyn Fn(&intervals::IntervalFit) -> f64| Spread::of(fits.iter().map(f).collect());
        if let Some(b) = v.bounds.get_mut(k + 1) {
            if !fits.is_empty() {
                *b = col(&|f| f.boundary_mm).mean;
            }
        }
        let (cutting, mut scale, puncture) = (col(&|f| f.cutting_n), col(&|f| f.scale), col(&|f| f.puncture_n));
        // the scale through the trials' mean peak: the model punctures at their mean
        // depth (the mean of the per-trial scales does not, the surrogate being curved)
        let peak = col(&|f| f.peak_mm).mean;
        let through = (puncture.mean - cutting.mean) / intervals::indent(u, peak - v.bounds[k + 1]);
        if !fits.is_empty() && through.is_finite() && through > 0.0 {
            scale.mean = through;
        }
        v.cutting.push(cutting);
        v.scale.push(scale);
        v.puncture.push(puncture);
    }
}

/// One file layer and its uncertainty notes.
#[allow(clippy::too_many_arguments)]
fn layer(
    j: usize,
    n: usize,
    thickness_mm: f64,
    scale: Spread,
    puncture: Spread,
    cutting: (f64, Spread),
    f: &LayerFriction,
    band: f64,
    opts: &TrialsOptions<'_>,
    source: &str,
) -> (file::Layer, Vec<(&'static str, String)>) {
    let sliding = |v: f64| f.coulomb_n_per_mm + f.viscous_n_s_per_mm2 * v;
    let name = if j == 0 {
        "surface to the first internal boundary".into()
    } else if j + 1 == n {
        format!("below internal boundary {j}")
    } else {
        format!("internal boundary {j} down")
    };
    let l = file::Layer {
        name,
        thickness_mm,
        stiffness_scale: scale.mean,
        puncture_force_n: puncture.mean,
        cutting_force_n: cutting.0,
        friction_static_n_per_mm: sliding(band),
        friction_coulomb_n_per_mm: f.coulomb_n_per_mm,
        friction_viscous_n_s_per_mm2: f.viscous_n_s_per_mm2,
        stick_band_mm_per_s: band,
        track_stiffness_n_per_mm2: crate::WINKLER_E_PER_MU * scale.mean * opts.fe_shear_modulus_n_per_mm2,
        source: source.to_string(),
        prony: Vec::new(),
        prony_source: None,
        family_weight: 1.0,
        family_weight_range: None,
        softening_fraction: 0.0,
        softening_onset_ratio: 0.0,
        softening_fraction_range: None,
        presliding_mm: None,
        relaxation_slip_mm: None,
        tent_n_per_mm: None,
        shaft_prony: Vec::new(),
    };
    let se = |s: Option<f64>, unit: &str, k: usize| match s {
        Some(se) => format!("+- {se:.3e} {unit} (regression over {k} trials)"),
        None => format!("no uncertainty: fitted on {k} trial(s) or one speed"),
    };
    let k = f.levels.values.len();
    let notes = vec![
        ("stiffness_scale", scale.note("-")),
        ("puncture_force_n", puncture.note("N")),
        ("cutting_force_n", cutting.1.note("N")),
        (
            "friction_coulomb_n_per_mm",
            if f.viscous_n_s_per_mm2 == 0.0 && f.viscous_se.is_none() { f.levels.note("N/mm") } else { se(f.coulomb_se, "N/mm", k) },
        ),
        ("friction_viscous_n_s_per_mm2", se(f.viscous_se, "N s/mm^2", k)),
    ];
    (l, notes)
}

fn source(opts: &TrialsOptions<'_>, ts: &[Trial], band: f64) -> String {
    let speeds: Vec<String> = ts.iter().map(|t| format!("{:.2}", t.phases.insertion_speed_mm_per_s)).collect();
    format!(
        "needle calibrate --trials on {} trials at {} mm/s: pre-puncture shape and first puncture from each trial's insertion (today's model), friction from the withdrawals (static = sliding level at the stick band's edge, {band:.3} mm/s, assumed; with a tissue tent the level holding the lifted tissue, see its line), each layer below a puncture and its cutting from the intervals, Prony terms from the holds; values are means or joint fits over the trials; track stiffness = E = 3 s mu0 (Winkler subgrade k ~ E, Vesic 1961); needle {} mm",
        ts.len(),
        speeds.join(", "),
        opts.needle_diameter_mm.first().copied().unwrap_or(0.0)
    )
}
