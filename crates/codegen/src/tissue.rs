//! Tissue stacks, `coeffs/<set>/tissue/<name>.toml`: the layers a needle passes from the
//! surface down, each with its stiffness scale against the set's FE tissue, puncture,
//! cutting, shaft friction and track stiffness (format: `coeffs/README.md`, "Tissue
//! stacks"). Parsed and checked here (every refusal names the file and the line), so
//! that `build.rs` and `needle calibrate` refuse the same files in the same words, and
//! rendered into the library's `tissue_stacks.rs`.
#![allow(clippy::cast_precision_loss)]
use crate::error::CodegenError;
use crate::literal::f32_literal;
use serde::{Deserialize, Serialize};
use std::ops::Range;
use std::path::{Path, PathBuf};
use toml::Spanned;

pub use needle_contract::{
    MAX_PRONY_TERMS, MAX_TISSUE_LAYERS as MAX_LAYERS, PRESLIDING_MM_RANGE, PRONY_G_SUM_MAX, RELAXATION_SLIP_MM_RANGE,
    SOFTENING_FRACTION_MAX, TENT_N_PER_MM_RANGE, TISSUE_FORMAT, TISSUE_FORMATS_READ,
};
/// The folder of a set that holds its tissue stacks.
pub const TISSUE_DIR: &str = "tissue";
/// File name of the generated stacks in the output folder.
pub const RUST_TISSUE_FILE: &str = "tissue_stacks.rs";

/// One layer, from its upper boundary down (units in the names).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Layer {
    /// What the layer is ("capsule", "ligamentum flavum").
    pub name: String,
    /// Thickness along the block's vertical, mm (> 0; the last layer extends below it).
    pub thickness_mm: f64,
    /// Stiffness scale s against the set's FE tissue (> 0): the layer's upper boundary
    /// deflects with s times the FE surrogate's wrench (the scaling law).
    pub stiffness_scale: f64,
    /// Axial force at which the upper boundary is punctured, N (> 0).
    pub puncture_force_n: f64,
    /// Axial force at the tip while it cuts through the layer, N (>= 0).
    pub cutting_force_n: f64,
    /// Karnopp static friction level per mm of shaft in the layer, N/mm (>= 0).
    pub friction_static_n_per_mm: f64,
    /// Karnopp Coulomb (sliding) friction level per mm of shaft, N/mm (>= 0).
    pub friction_coulomb_n_per_mm: f64,
    /// Viscous friction per mm of shaft, N per (mm/s) per mm (>= 0).
    pub friction_viscous_n_s_per_mm2: f64,
    /// Half width of the stick band of axial speed, mm/s (> 0): below it the friction
    /// rises linearly from zero to the static level.
    pub stick_band_mm_per_s: f64,
    /// Lateral stiffness of the cut track per mm of shaft in the layer, N/mm per mm (>= 0).
    pub track_stiffness_n_per_mm2: f64,
    /// Where the values come from (a citation, or the `needle calibrate` run).
    pub source: String,
    /// The relaxation function's Prony terms (0 to [`MAX_PRONY_TERMS`]; none: elastic), in
    /// the long-term normalisation `G(t) = 1 + sum g_i exp(-t / tau_i)`.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub prony: Vec<PronyTerm>,
    /// Where the Prony terms come from (a citation; required with terms), or why the
    /// layer has none.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub prony_source: Option<String>,
    /// Format 2: the weight `w` of the material family's member the boundary deflects as
    /// (`family.toml`; 1, the default: the paper's tissue), within the members the set's FE
    /// covers.
    #[serde(default = "one", skip_serializing_if = "is_one")]
    pub family_weight: f64,
    /// Format 2: the weights whose fit was as good within the calibration's tolerance (its
    /// fitted range), `[low, high]`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub family_weight_range: Option<[f64; 2]>,
    /// Format 2: the share of the boundary's force lost at its puncture (the pre-puncture
    /// softening; 0, the default: none), `0 <= fraction <` [`SOFTENING_FRACTION_MAX`].
    #[serde(default, skip_serializing_if = "is_zero")]
    pub softening_fraction: f64,
    /// Format 2: where the softening starts, as a share of the force that punctures
    /// (`0 <= ratio < 1`).
    #[serde(default, skip_serializing_if = "is_zero")]
    pub softening_onset_ratio: f64,
    /// Format 2: the fitted range of `softening_fraction`, `[low, high]`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub softening_fraction_range: Option<[f64; 2]>,
    /// Format 2: the shaft's presliding distance, mm, within [`PRESLIDING_MM_RANGE`]
    /// (none, the default: the Karnopp friction, zero at rest): a needle at rest keeps
    /// its shaft friction and cutting force, a reversal turns them over within twice it
    /// (compiled in only with the library's `shaft-presliding` feature).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub presliding_mm: Option<f64>,
    /// Format 2: the distance within which the relaxing part of the held force (each
    /// `shaft_prony` term) is loaded, mm, within [`RELAXATION_SLIP_MM_RANGE`] (default:
    /// `presliding_mm`; needs it): sliding faster than it over a term's time constant keeps
    /// the term at its slip, so the held force relaxes by the same share at any such speed.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub relaxation_slip_mm: Option<f64>,
    /// Format 2: the relaxation of the held shaft force and cutting (0 to
    /// [`MAX_PRONY_TERMS`], long-term normalisation; needs `presliding_mm`).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub shaft_prony: Vec<PronyTerm>,
    /// Format 2: the tissue's tent stiffness, N/mm, within [`TENT_N_PER_MM_RANGE`]
    /// (none, the default: the bristles move with the needle; needs `presliding_mm`): the
    /// layer's tissue around the shaft, a spring in series with its friction, turns the
    /// held force over within about the force's change over it and is lifted with a
    /// withdrawing needle, lengthening the shaft in the layer.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tent_n_per_mm: Option<f64>,
}

fn one() -> f64 {
    1.0
}

#[allow(clippy::trivially_copy_pass_by_ref, clippy::float_cmp)] // serde's skip_serializing_if signature; exact default
fn is_one(v: &f64) -> bool {
    *v == 1.0
}

#[allow(clippy::trivially_copy_pass_by_ref)] // serde's skip_serializing_if signature
fn is_zero(v: &f64) -> bool {
    *v == 0.0
}

/// One Prony term of a layer's relaxation function (long-term normalisation).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PronyTerm {
    /// Weight relative to the long-term response (>= 0).
    pub g: f64,
    /// Time constant, s (> 0).
    pub tau_s: f64,
}

/// A stack as read from its file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Stack {
    /// Format version, [`TISSUE_FORMAT`].
    pub format: i64,
    /// Short name: the file's stem, a Rust identifier once upper-cased.
    pub name: String,
    /// One line on what the stack is.
    pub description: String,
    /// Diameter of the needle the values belong to, mm (> 0): the library scales the FE
    /// surrogate from the set's needle to this one by geometric similarity.
    pub needle_diameter_mm: f64,
    /// The layers from the surface down (1 to [`MAX_LAYERS`]).
    #[serde(rename = "layer")]
    pub layers: Vec<Layer>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawStack {
    format: Spanned<i64>,
    name: Spanned<String>,
    description: String,
    needle_diameter_mm: Spanned<f64>,
    #[serde(rename = "layer")]
    layers: Spanned<Vec<Spanned<RawLayer>>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawLayer {
    name: String,
    thickness_mm: Spanned<f64>,
    stiffness_scale: Spanned<f64>,
    puncture_force_n: Spanned<f64>,
    cutting_force_n: Spanned<f64>,
    friction_static_n_per_mm: Spanned<f64>,
    friction_coulomb_n_per_mm: Spanned<f64>,
    friction_viscous_n_s_per_mm2: Spanned<f64>,
    stick_band_mm_per_s: Spanned<f64>,
    track_stiffness_n_per_mm2: Spanned<f64>,
    source: String,
    prony: Option<Spanned<Vec<Spanned<RawProny>>>>,
    prony_source: Option<Spanned<String>>,
    family_weight: Option<Spanned<f64>>,
    family_weight_range: Option<Spanned<[f64; 2]>>,
    softening_fraction: Option<Spanned<f64>>,
    softening_onset_ratio: Option<Spanned<f64>>,
    softening_fraction_range: Option<Spanned<[f64; 2]>>,
    presliding_mm: Option<Spanned<f64>>,
    relaxation_slip_mm: Option<Spanned<f64>>,
    shaft_prony: Option<Spanned<Vec<Spanned<RawProny>>>>,
    tent_n_per_mm: Option<Spanned<f64>>,
}

#[derive(Deserialize, Clone)]
#[serde(deny_unknown_fields)]
struct RawProny {
    g: Spanned<f64>,
    tau_s: Spanned<f64>,
}

/// What a value must be.
#[derive(Clone, Copy)]
enum Bound {
    Positive,
    NonNegative,
}

/// Reads and checks the tissue file at `path`.
///
/// # Errors
/// Unreadable file, invalid TOML, a missing or unknown field, or a value out of its
/// range (a thickness, scale, puncture force or stick band <= 0, a force, friction or
/// stiffness < 0, a name that is not an identifier), each with its line.
pub fn parse_stack(path: &Path) -> Result<Stack, CodegenError> {
    let text = std::fs::read_to_string(path).map_err(|e| CodegenError::file(path, format!("cannot read the tissue file: {e}")))?;
    parse_stack_str(&text, path)
}

/// Checks `text`, the contents of the tissue file `path` (used in the messages).
///
/// # Errors
/// As [`parse_stack`].
pub fn parse_stack_str(text: &str, path: &Path) -> Result<Stack, CodegenError> {
    parse_stack_str_in(text, path, &FamilyDomain::ANY)
}

/// The members of the material family a set's FE covers (`family.toml`'s fitted
/// weights, to the paper's tissue at 1): a layer's `family_weight` outside is refused
/// (not extrapolated).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FamilyDomain {
    /// The smallest weight, `0 ..= 1`.
    pub weight_min: f64,
}

impl FamilyDomain {
    /// Every weight `0 ..= 1` (a file read outside a set).
    pub const ANY: Self = Self { weight_min: 0.0 };
    /// Only the paper's tissue (a set without a family law).
    pub const PAPER_ONLY: Self = Self { weight_min: 1.0 };
}

/// The members the set `set_dir`'s FE covers: from the smallest fitted weight of its
/// `family.toml` to 1, only the paper's tissue without one.
///
/// # Errors
/// As [`crate::family::parse`], for a set with a `family.toml`.
pub fn domain_of_set(set_dir: &Path) -> Result<FamilyDomain, CodegenError> {
    let path = set_dir.join(crate::family::FILE);
    if !path.is_file() {
        return Ok(FamilyDomain::PAPER_ONLY);
    }
    Ok(FamilyDomain { weight_min: crate::family::parse(&path)?.weight_min })
}

/// Reads and checks the tissue file at `path` as a file of a set whose family covers
/// `domain`.
///
/// # Errors
/// As [`parse_stack`], and a `family_weight` outside `domain`.
pub fn parse_stack_in(path: &Path, domain: &FamilyDomain) -> Result<Stack, CodegenError> {
    let text = std::fs::read_to_string(path).map_err(|e| CodegenError::file(path, format!("cannot read the tissue file: {e}")))?;
    parse_stack_str_in(&text, path, domain)
}

/// [`parse_stack_str`] for a file of a set whose family covers `domain`.
///
/// # Errors
/// As [`parse_stack_str`], and a `family_weight` outside `domain`.
pub fn parse_stack_str_in(text: &str, path: &Path, domain: &FamilyDomain) -> Result<Stack, CodegenError> {
    let raw: RawStack = toml::from_str(text).map_err(|e| {
        let offset = e.span().map_or(text.trim_end().len(), |s| s.start);
        CodegenError::at(path, text, offset, e.message().trim_end())
    })?;
    let err = |span: Range<usize>, m: String| CodegenError::at(path, text, span.start, m);
    let format = *raw.format.get_ref();
    if !TISSUE_FORMATS_READ.contains(&format) {
        return Err(err(raw.format.span(), format!("format = {format}: this build reads tissue formats 1 and 2")));
    }
    let name = raw.name.get_ref();
    if !is_stack_name(name) {
        return Err(err(raw.name.span(), format!("name = {name:?}: {STACK_NAME_RULE}")));
    }
    check(&raw.needle_diameter_mm, "needle_diameter_mm", Bound::Positive, &err)?;
    let layers_span = raw.layers.span();
    let raw_layers = raw.layers.into_inner();
    if raw_layers.is_empty() || raw_layers.len() > MAX_LAYERS {
        return Err(err(layers_span, format!("{} [[layer]] entries: a stack has 1 to {MAX_LAYERS}", raw_layers.len())));
    }
    let layers = raw_layers.into_iter().map(|l| layer(l.into_inner(), format, domain, &err)).collect::<Result<Vec<_>, _>>()?;
    Ok(Stack { format, name: name.clone(), description: raw.description, needle_diameter_mm: *raw.needle_diameter_mm.get_ref(), layers })
}

fn layer(
    l: RawLayer,
    format: i64,
    domain: &FamilyDomain,
    err: &dyn Fn(Range<usize>, String) -> CodegenError,
) -> Result<Layer, CodegenError> {
    use Bound::{NonNegative, Positive};
    let shape = shape(&l, format, domain, err)?;
    let (presliding_mm, relaxation_slip_mm, shaft_prony, tent_n_per_mm) = presliding_fields(&l, format, err)?;
    let (prony, prony_span) = match l.prony {
        None => (Vec::new(), l.thickness_mm.span()),
        Some(p) => {
            let span = p.span();
            (prony(p, err)?, span)
        }
    };
    if !prony.is_empty() && l.prony_source.as_ref().is_none_or(|s| s.get_ref().trim().is_empty()) {
        return Err(err(
            prony_span,
            format!("layer {:?}: prony terms need prony_source = \"the published measurement they come from\"", l.name),
        ));
    }
    Ok(Layer {
        prony,
        presliding_mm,
        relaxation_slip_mm,
        shaft_prony,
        tent_n_per_mm,
        prony_source: l.prony_source.map(Spanned::into_inner),
        thickness_mm: check(&l.thickness_mm, "thickness_mm", Positive, err)?,
        stiffness_scale: check(&l.stiffness_scale, "stiffness_scale", Positive, err)?,
        puncture_force_n: check(&l.puncture_force_n, "puncture_force_n", Positive, err)?,
        cutting_force_n: check(&l.cutting_force_n, "cutting_force_n", NonNegative, err)?,
        friction_static_n_per_mm: check(&l.friction_static_n_per_mm, "friction_static_n_per_mm", NonNegative, err)?,
        friction_coulomb_n_per_mm: check(&l.friction_coulomb_n_per_mm, "friction_coulomb_n_per_mm", NonNegative, err)?,
        friction_viscous_n_s_per_mm2: check(&l.friction_viscous_n_s_per_mm2, "friction_viscous_n_s_per_mm2", NonNegative, err)?,
        stick_band_mm_per_s: check(&l.stick_band_mm_per_s, "stick_band_mm_per_s", Positive, err)?,
        track_stiffness_n_per_mm2: check(&l.track_stiffness_n_per_mm2, "track_stiffness_n_per_mm2", NonNegative, err)?,
        name: l.name,
        source: l.source,
        family_weight: shape.family_weight,
        family_weight_range: shape.family_weight_range,
        softening_fraction: shape.softening_fraction,
        softening_onset_ratio: shape.softening_onset_ratio,
        softening_fraction_range: shape.softening_fraction_range,
    })
}

/// A layer's format 2 fields, checked.
struct Shape {
    family_weight: f64,
    family_weight_range: Option<[f64; 2]>,
    softening_fraction: f64,
    softening_onset_ratio: f64,
    softening_fraction_range: Option<[f64; 2]>,
}

/// The format 2 fields of `l`: refused in a format 1 file; the weight within `domain` and
/// 1, the softening fraction `0 ..` [`SOFTENING_FRACTION_MAX`], its onset ratio `0 .. 1`,
/// each range `[low, high]` with `low <= high` around its value.
fn shape(
    l: &RawLayer,
    format: i64,
    domain: &FamilyDomain,
    err: &dyn Fn(Range<usize>, String) -> CodegenError,
) -> Result<Shape, CodegenError> {
    let scalars = [
        ("family_weight", &l.family_weight),
        ("softening_fraction", &l.softening_fraction),
        ("softening_onset_ratio", &l.softening_onset_ratio),
    ];
    let ranges = [("family_weight_range", &l.family_weight_range), ("softening_fraction_range", &l.softening_fraction_range)];
    if format < 2 {
        let first = scalars
            .iter()
            .find_map(|(k, v)| v.as_ref().map(|v| (*k, v.span())))
            .or_else(|| ranges.iter().find_map(|(k, v)| v.as_ref().map(|v| (*k, v.span()))));
        if let Some((key, span)) = first {
            return Err(err(
                span,
                format!("{key}: a format 2 field (the material family and the pre-puncture softening); write format = 2"),
            ));
        }
    }
    let within =
        |v: &Option<Spanned<f64>>, key: &str, default: f64, lo: f64, hi: f64, hi_open: bool, what: &str| -> Result<f64, CodegenError> {
            let Some(v) = v else { return Ok(default) };
            let x = *v.get_ref();
            let ok = x.is_finite() && x >= lo && if hi_open { x < hi } else { x <= hi };
            if ok {
                Ok(x)
            } else {
                Err(err(v.span(), format!("{key} = {x}: {what}")))
            }
        };
    let family_weight = within(
        &l.family_weight,
        "family_weight",
        1.0,
        domain.weight_min,
        1.0,
        false,
        &format!(
            "outside the members the set's FE covers, {} to 1 (family.toml's fitted weights to the paper's tissue): not extrapolated",
            domain.weight_min
        ),
    )?;
    let softening_fraction = within(
        &l.softening_fraction,
        "softening_fraction",
        0.0,
        0.0,
        SOFTENING_FRACTION_MAX,
        true,
        &format!("must be from 0 to below {SOFTENING_FRACTION_MAX}"),
    )?;
    let softening_onset_ratio =
        within(&l.softening_onset_ratio, "softening_onset_ratio", 0.0, 0.0, 1.0, true, "must be from 0 to below 1")?;
    let range = |r: &Option<Spanned<[f64; 2]>>, key: &str, value: f64| -> Result<Option<[f64; 2]>, CodegenError> {
        let Some(r) = r else { return Ok(None) };
        let [lo, hi] = *r.get_ref();
        if lo.is_finite() && hi.is_finite() && lo <= value && value <= hi {
            Ok(Some([lo, hi]))
        } else {
            Err(err(r.span(), format!("{key} = [{lo}, {hi}]: must be finite, low <= high, around the value {value}")))
        }
    };
    Ok(Shape {
        family_weight,
        family_weight_range: range(&l.family_weight_range, "family_weight_range", family_weight)?,
        softening_fraction,
        softening_onset_ratio,
        softening_fraction_range: range(&l.softening_fraction_range, "softening_fraction_range", softening_fraction)?,
    })
}

/// A layer's presliding fields, checked: the distance, the relaxation's slip distance,
/// the shaft's terms.
type PreslidingFields = (Option<f64>, Option<f64>, Vec<PronyTerm>, Option<f64>);

/// The presliding fields of `l` (format 2): the distances within [`PRESLIDING_MM_RANGE`]
/// and [`RELAXATION_SLIP_MM_RANGE`],
/// the tent's stiffness within [`TENT_N_PER_MM_RANGE`],
/// the shaft's Prony terms checked as a layer's, each only with a presliding distance.
fn presliding_fields(
    l: &RawLayer,
    format: i64,
    err: &dyn Fn(Range<usize>, String) -> CodegenError,
) -> Result<PreslidingFields, CodegenError> {
    let spans = [
        l.presliding_mm.as_ref().map(Spanned::span),
        l.relaxation_slip_mm.as_ref().map(Spanned::span),
        l.shaft_prony.as_ref().map(Spanned::span),
        l.tent_n_per_mm.as_ref().map(Spanned::span),
    ];
    if format < 2 {
        if let Some(span) = spans.into_iter().flatten().next() {
            return Err(err(
                span,
                "presliding_mm, relaxation_slip_mm, shaft_prony, tent_n_per_mm: format 2 fields (the shaft's presliding); write format = 2"
                    .into(),
            ));
        }
    }
    let in_range = |v: &Spanned<f64>, key: &str, (lo, hi): (f64, f64), unit: &str| -> Result<f64, CodegenError> {
        let x = *v.get_ref();
        if x.is_finite() && (lo..=hi).contains(&x) {
            Ok(x)
        } else {
            Err(err(v.span(), format!("{key} = {x}: must be from {lo} to {hi} {unit} (leave it out for none)")))
        }
    };
    let distance = l.presliding_mm.as_ref().map(|v| in_range(v, "presliding_mm", PRESLIDING_MM_RANGE, "mm")).transpose()?;
    let slip = l.relaxation_slip_mm.as_ref().map(|v| in_range(v, "relaxation_slip_mm", RELAXATION_SLIP_MM_RANGE, "mm")).transpose()?;
    if let (None, Some(v)) = (distance, &l.relaxation_slip_mm) {
        return Err(err(v.span(), format!("layer {:?}: relaxation_slip_mm needs presliding_mm", l.name)));
    }
    let terms = match l.shaft_prony.clone() {
        None => Vec::new(),
        Some(p) => {
            let span = p.span();
            let terms = prony(p, err)?;
            if distance.is_none() && !terms.is_empty() {
                return Err(err(span, format!("layer {:?}: shaft_prony needs presliding_mm (the held force it relaxes)", l.name)));
            }
            terms
        }
    };
    let tent = l.tent_n_per_mm.as_ref().map(|v| in_range(v, "tent_n_per_mm", TENT_N_PER_MM_RANGE, "N/mm")).transpose()?;
    if let (None, Some(v)) = (distance, &l.tent_n_per_mm) {
        return Err(err(v.span(), format!("layer {:?}: tent_n_per_mm needs presliding_mm (the friction it is in series with)", l.name)));
    }
    Ok((distance, slip, terms, tent))
}

/// The Prony terms: at most [`MAX_PRONY_TERMS`], each `g >= 0` and `tau_s > 0`, the sum
/// of `g` at most [`PRONY_G_SUM_MAX`] (the checks of the library's `PronyTerms::new`).
fn prony(p: Spanned<Vec<Spanned<RawProny>>>, err: &dyn Fn(Range<usize>, String) -> CodegenError) -> Result<Vec<PronyTerm>, CodegenError> {
    let span = p.span();
    let terms = p.into_inner();
    if terms.len() > MAX_PRONY_TERMS {
        return Err(err(span, format!("{} prony terms: a layer has at most {MAX_PRONY_TERMS}", terms.len())));
    }
    let mut out = Vec::with_capacity(terms.len());
    for t in terms {
        let t = t.into_inner();
        let g = check(&t.g, "prony g", Bound::NonNegative, err)?;
        let tau_s = check(&t.tau_s, "prony tau_s", Bound::Positive, err)?;
        out.push(PronyTerm { g, tau_s });
    }
    // the library checks the sum of the f32 weights: so does the build
    #[allow(clippy::cast_possible_truncation)]
    let sum: f64 = out.iter().map(|t| f64::from(t.g as f32)).sum();
    if sum > PRONY_G_SUM_MAX {
        return Err(err(
            span,
            format!(
                "prony: sum of g = {sum}: must be <= {PRONY_G_SUM_MAX} (long-term normalisation; instantaneous at most 10 times long-term)"
            ),
        ));
    }
    Ok(out)
}

/// The value, if it is finite, within f32's range and inside `bound`.
fn check(v: &Spanned<f64>, key: &str, bound: Bound, err: &dyn Fn(Range<usize>, String) -> CodegenError) -> Result<f64, CodegenError> {
    let x = *v.get_ref();
    let (ok, what) = match bound {
        Bound::Positive => (x > 0.0, "> 0"),
        Bound::NonNegative => (x >= 0.0, ">= 0"),
    };
    if !x.is_finite() || x.abs() > f64::from(f32::MAX) || !ok {
        return Err(err(v.span(), format!("{key} = {x}: must be finite and {what}")));
    }
    Ok(x)
}

impl Stack {
    /// The file text of this stack (what `needle calibrate` writes), with `header` as
    /// leading comment lines.
    #[must_use]
    pub fn to_toml(&self, header: &str) -> String {
        let mut out: String = header.lines().map(|l| format!("# {l}\n").replace("# \n", "#\n")).collect();
        // plain data with string keys: serialising cannot fail
        out.push_str(&toml::to_string(self).unwrap_or_default());
        out
    }
}

/// The tissue files of the set `set_dir` (`tissue/*.toml`, by name), checked.
///
/// # Errors
/// The rule of a stack's name, as messages say it.
pub const STACK_NAME_RULE: &str = "a stack name is lower-case ASCII letters, digits and '_', starting with a letter";

/// Whether `name` can name a stack ([`STACK_NAME_RULE`]: it becomes a Rust constant).
#[must_use]
pub fn is_stack_name(name: &str) -> bool {
    name.chars().next().is_some_and(|c| c.is_ascii_lowercase())
        && name.chars().all(|c| c.is_ascii_lowercase() || c.is_ascii_digit() || c == '_')
}

/// A file that [`parse_stack`] refuses, a stem that is not the stack's `name`, or an
/// unreadable folder.
pub fn read_stacks(set_dir: &Path) -> Result<Vec<(PathBuf, Stack)>, CodegenError> {
    let dir = set_dir.join(TISSUE_DIR);
    if !dir.is_dir() {
        return Ok(Vec::new());
    }
    let entries = std::fs::read_dir(&dir).map_err(|e| CodegenError::file(&dir, format!("cannot list: {e}")))?;
    let mut paths: Vec<PathBuf> = entries.flatten().map(|e| e.path()).filter(|p| p.extension().is_some_and(|x| x == "toml")).collect();
    paths.sort();
    let domain = domain_of_set(set_dir)?;
    let mut stacks = Vec::with_capacity(paths.len());
    for path in paths {
        let stack = parse_stack_in(&path, &domain)?;
        let stem = path.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
        if stem != stack.name {
            return Err(CodegenError::file(
                &path,
                format!("name = {:?}: a tissue file is named after its stack ({}.toml)", stack.name, stack.name),
            ));
        }
        stacks.push((path, stack));
    }
    Ok(stacks)
}

/// The set's FE needle, from `campaign.toml` `[needle]`: what the stacks are scaled from.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FeNeedle {
    /// Shaft diameter, mm.
    pub diameter_mm: f64,
    /// Distance of the wrench's reference point (the hub) from the tip, mm.
    pub reference_from_tip_mm: f64,
}

/// The `[needle]` of `<set>/campaign.toml`, or `None` when the set has no campaign file.
///
/// # Errors
/// The file is unreadable, or `[needle] diameter_mm` / `reference_from_tip_mm` is
/// missing or not a positive number.
pub fn read_fe_needle(set_dir: &Path) -> Result<Option<FeNeedle>, CodegenError> {
    let path = set_dir.join("campaign.toml");
    if !path.is_file() {
        return Ok(None);
    }
    let text = std::fs::read_to_string(&path).map_err(|e| CodegenError::file(&path, format!("cannot read: {e}")))?;
    let value: toml::Table = toml::from_str(&text).map_err(|e| {
        let offset = e.span().map_or(text.trim_end().len(), |s| s.start);
        CodegenError::at(&path, &text, offset, e.message().trim_end())
    })?;
    let get = |key: &str| {
        value
            .get("needle")
            .and_then(|n| n.get(key))
            .and_then(|v| v.as_float().or_else(|| v.as_integer().map(|i| i as f64)))
            .filter(|v| v.is_finite() && *v > 0.0)
            .ok_or_else(|| CodegenError::file(&path, format!("[needle] {key}: missing or not a number > 0")))
    };
    Ok(Some(FeNeedle { diameter_mm: get("diameter_mm")?, reference_from_tip_mm: get("reference_from_tip_mm")? }))
}

/// The initial shear modulus `mu0 = sum of [tissue] mu_n_per_mm2` of `<set>/campaign.toml`
/// (N/mm²), or `None` without a campaign file.
///
/// # Errors
/// The file is unreadable, or `mu_n_per_mm2` is missing, not a list of numbers, or sums
/// to a value that is not finite and > 0.
pub fn read_fe_shear_modulus(set_dir: &Path) -> Result<Option<f64>, CodegenError> {
    let path = set_dir.join("campaign.toml");
    if !path.is_file() {
        return Ok(None);
    }
    let text = std::fs::read_to_string(&path).map_err(|e| CodegenError::file(&path, format!("cannot read: {e}")))?;
    let value: toml::Table = toml::from_str(&text).map_err(|e| {
        let offset = e.span().map_or(text.trim_end().len(), |s| s.start);
        CodegenError::at(&path, &text, offset, e.message().trim_end())
    })?;
    let mu: Option<f64> = value
        .get("tissue")
        .and_then(|t| t.get("mu_n_per_mm2"))
        .and_then(|m| m.as_array())
        .map(|a| a.iter().map(|v| v.as_float().unwrap_or(f64::NAN)).sum());
    match mu {
        Some(m) if m.is_finite() && m > 0.0 => Ok(Some(m)),
        _ => Err(CodegenError::file(&path, "[tissue] mu_n_per_mm2: missing, not numbers, or a sum that is not > 0")),
    }
}

/// The Rust source of the stacks: one `pub const <NAME>: Stack` each and `ALL`, using the
/// library's `Stack` and `Layer` types (every value an exact f32 literal).
///
/// A stack with a Prony term on any layer is compiled only with the library's
/// `viscoelastic` feature (`#[cfg(feature = "viscoelastic")]` on its constant), and `ALL`
/// has two forms: every stack with the feature, the elastic stacks alone without it. An
/// elastic build therefore never holds a stack it would have to render without its
/// relaxation.
#[must_use]
pub fn render_rust_stacks(stacks: &[(PathBuf, Stack)], needle: Option<FeNeedle>) -> String {
    let mut out = String::from("// Generated by needle-codegen from the set's tissue/*.toml: do not edit.\n\n");
    let (d, r) = needle.map_or(("f32::NAN".to_string(), "f32::NAN".to_string()), |n| (lit(n.diameter_mm), lit(n.reference_from_tip_mm)));
    out.push_str(&format!("/// Diameter of the set's FE needle, mm (`campaign.toml` `[needle] diameter_mm`; NaN: no campaign file).\npub const FE_NEEDLE_DIAMETER_MM: f32 = {d};\n"));
    out.push_str(&format!("/// The model's moment reference (the hub) from the tip, mm (`[needle] reference_from_tip_mm`).\npub const HUB_FROM_TIP_MM: f32 = {r};\n\n"));
    for (path, s) in stacks {
        let file = path.file_name().map(|f| f.to_string_lossy().into_owned()).unwrap_or_default();
        out.push_str(&format!("/// `{}` (tissue/{file}): {}\n", s.name, s.description.replace('\n', " ")));
        out.push_str(&gate(&needs(s)));
        out.push_str(&format!("pub const {}: Stack<'static> = Stack {{\n", s.name.to_uppercase()));
        out.push_str(&format!("    name: {:?},\n    needle_diameter_mm: {},\n    layers: &[\n", s.name, lit(s.needle_diameter_mm)));
        for l in &s.layers {
            out.push_str(&format!(
                "        Layer {{ thickness_mm: {}, stiffness_scale: {}, puncture_force_n: {}, cutting_force_n: {}, friction: Karnopp {{ static_n_per_mm: {}, coulomb_n_per_mm: {}, viscous_n_s_per_mm2: {}, stick_band_mm_per_s: {} }}, track_stiffness_n_per_mm2: {}, prony: {}, family: {}, softening: {}, {PRESLIDING_ONLY} presliding: {} }}, // {}\n",
                lit(l.thickness_mm),
                lit(l.stiffness_scale),
                lit(l.puncture_force_n),
                lit(l.cutting_force_n),
                lit(l.friction_static_n_per_mm),
                lit(l.friction_coulomb_n_per_mm),
                lit(l.friction_viscous_n_s_per_mm2),
                lit(l.stick_band_mm_per_s),
                lit(l.track_stiffness_n_per_mm2),
                render_prony(&l.prony),
                render_family(l.family_weight),
                render_softening(l.softening_fraction, l.softening_onset_ratio),
                render_presliding(l.presliding_mm, l.relaxation_slip_mm, &l.shaft_prony, l.tent_n_per_mm),
                l.name.replace('\n', " ")
            ));
        }
        out.push_str("    ],\n};\n\n");
    }
    let names = |keep: &dyn Fn(&Stack) -> bool| -> Vec<String> {
        stacks.iter().filter(|(_, s)| keep(s)).map(|(_, s)| s.name.to_uppercase()).collect()
    };
    let all = names(&|_| true);
    let all_const = |names: &[String]| format!("pub const ALL: [Stack<'static>; {}] = [{}];\n", names.len(), names.join(", "));
    let shape_used = stacks.iter().any(|(_, s)| shaped(s));
    let presliding_used = stacks.iter().any(|(_, s)| has_presliding(s));
    if shape_used || presliding_used {
        // one ALL per combination of the features that gate a stack, each listing the
        // stacks it compiles (the `viscoelastic` feature always among them with `tissue-shape`)
        let gating: Vec<usize> = (0..FEATURES.len())
            .filter(|&k| [shape_used || stacks.iter().any(|(_, s)| !elastic(s)), shape_used, presliding_used][k])
            .collect();
        for combination in 0..1usize << gating.len() {
            // each ALL its own doc line (the library denies missing docs)
            out.push_str("/// Every stack of the set that this build compiles in, by file name (stacks with Prony terms need the `viscoelastic` feature, with a family member or a softening `tissue-shape`");
            out.push_str(if presliding_used { ", with a presliding `shaft-presliding`).\n" } else { ").\n" });
            let on = |i: usize| combination >> (gating.len() - 1 - i) & 1 == 1;
            let cfgs: Vec<String> = gating
                .iter()
                .enumerate()
                .map(|(i, &k)| if on(i) { format!("feature = \"{}\"", FEATURES[k]) } else { format!("not(feature = \"{}\")", FEATURES[k]) })
                .collect();
            out.push_str(&format!("#[cfg(all({}))]\n", cfgs.join(", ")));
            let compiled = |s: &Stack| gating.iter().enumerate().all(|(i, &k)| on(i) || !needs(s)[k]);
            out.push_str(&all_const(&names(&compiled)));
        }
    } else if stacks.iter().all(|(_, s)| elastic(s)) {
        out.push_str(&format!("/// Every stack of the set, by file name.\n{}", all_const(&all)));
    } else {
        out.push_str(&format!("/// Every stack of the set, by file name.\n{VISCOELASTIC_ONLY}\n{}", all_const(&all)));
        out.push_str(&format!(
            "/// The stacks of the set without Prony terms, by file name (a build without the `viscoelastic` feature).\n#[cfg(not(feature = \"viscoelastic\"))]\n{}",
            all_const(&names(&elastic))
        ));
    }
    out
}

/// A layer's family member: `FamilyMember::PAPER` at 1, else the weight and its square
/// root as f32 literals (IEEE `sqrt` is correctly rounded, so the f64 root rounded to f32
/// is the library's `sqrtf` of the f32 weight: `FamilyMember::from_parts` holds it).
#[allow(clippy::float_cmp, clippy::cast_possible_truncation)]
fn render_family(weight: f64) -> String {
    if weight == 1.0 {
        return "FamilyMember::PAPER".into();
    }
    let w = weight as f32;
    format!("FamilyMember::from_build({}, {})", f32_literal(w), f32_literal(f64::from(w).sqrt() as f32))
}

/// A layer's softening: `Softening::NONE` without one.
#[allow(clippy::float_cmp, clippy::cast_possible_truncation)]
fn render_softening(fraction: f64, onset_ratio: f64) -> String {
    if fraction == 0.0 {
        return "Softening::NONE".into();
    }
    format!("Softening {{ fraction: {}, onset_ratio: {} }}", f32_literal(fraction as f32), f32_literal(onset_ratio as f32))
}

/// The attribute that compiles an item only with the library's `viscoelastic` feature.
const VISCOELASTIC_ONLY: &str = "#[cfg(feature = \"viscoelastic\")]";

/// The attribute that compiles a layer's presliding field (a field of the library's
/// layer only with its `shaft-presliding` feature).
const PRESLIDING_ONLY: &str = "#[cfg(feature = \"shaft-presliding\")]";

/// The library features that gate a stack, in the order of [`needs`].
const FEATURES: [&str; 3] = ["viscoelastic", "tissue-shape", "shaft-presliding"];

/// Which of [`FEATURES`] `stack` needs compiled in: Prony terms, a family member or a
/// softening, a presliding.
fn needs(stack: &Stack) -> [bool; 3] {
    [!elastic(stack), shaped(stack), has_presliding(stack)]
}

/// The attribute that compiles a stack needing `needs` (nothing when it needs none).
fn gate(needs: &[bool; 3]) -> String {
    let on: Vec<String> = FEATURES.iter().zip(needs).filter(|(_, n)| **n).map(|(f, _)| format!("feature = \"{f}\"")).collect();
    match on.len() {
        0 => String::new(),
        1 => format!("#[cfg({})]\n", on.join("")),
        _ => format!("#[cfg(all({}))]\n", on.join(", ")),
    }
}

/// Whether a layer of `stack` has a presliding (compiled in only with the
/// `shaft-presliding` feature).
fn has_presliding(stack: &Stack) -> bool {
    stack.layers.iter().any(|l| l.presliding_mm.is_some())
}

/// A layer's presliding: `Presliding::NONE` without one.
fn render_presliding(distance_mm: Option<f64>, slip_mm: Option<f64>, terms: &[PronyTerm], tent_n_per_mm: Option<f64>) -> String {
    match distance_mm {
        None => "Presliding::NONE".into(),
        Some(d) => format!(
            "Presliding {{ distance_mm: {}, relaxation_slip_mm: {}, shaft_prony: {}, tent_n_per_mm: {} }}",
            lit(d),
            lit(slip_mm.unwrap_or(d)),
            render_prony(terms),
            lit(tent_n_per_mm.unwrap_or(0.0))
        ),
    }
}

/// Whether a layer of `stack` has a family member other than the paper's tissue or a
/// softening (format 2: compiled in only with the `tissue-shape` feature).
#[allow(clippy::float_cmp)]
fn shaped(stack: &Stack) -> bool {
    stack.layers.iter().any(|l| l.family_weight != 1.0 || l.softening_fraction != 0.0)
}

/// Whether no layer of `stack` has a Prony term.
fn elastic(stack: &Stack) -> bool {
    stack.layers.iter().all(|l| l.prony.is_empty())
}

/// A layer's terms as a `PronyTerms` constant expression (checked again at compile time
/// by the library's `PronyTerms::from_array`, which this build's checks match: a
/// refusal there is a compile error, never a run-time path).
fn render_prony(terms: &[PronyTerm]) -> String {
    if terms.is_empty() {
        return "PronyTerms::NONE".to_string();
    }
    let mut items: Vec<String> = terms.iter().map(|t| format!("PronyTerm {{ g: {}, tau_s: {} }}", lit(t.g), lit(t.tau_s))).collect();
    items.resize(MAX_PRONY_TERMS, "PronyTerm { g: 0.0, tau_s: 0.0 }".to_string());
    format!(
        "match PronyTerms::from_array([{}], {}) {{ Some(p) => p, None => panic!(\"prony terms refused by PronyTerms::from_array\") }}",
        items.join(", "),
        terms.len()
    )
}

/// The f32 nearest to `v` (the format checks f32's range), as an exact literal.
fn lit(v: f64) -> String {
    #[allow(clippy::cast_possible_truncation)]
    f32_literal(v as f32)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn shipped(name: &str) -> (PathBuf, Stack) {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../coeffs/default/tissue").join(format!("{name}.toml"));
        let stack = parse_stack(&path).expect("a shipped tissue file parses");
        (path, stack)
    }

    #[test]
    fn a_stack_with_terms_is_compiled_only_with_the_viscoelastic_feature() {
        let elastic_stack = shipped("liver");
        let mut visco = shipped("liver");
        visco.1.name = "visco".to_string();
        visco.1.layers.iter_mut().for_each(|l| l.prony = vec![PronyTerm { g: 0.5, tau_s: 0.2 }]);
        let rust = render_rust_stacks(&[elastic_stack.clone(), visco], None);
        let gated = format!("{VISCOELASTIC_ONLY}\npub const VISCO:");
        assert!(rust.contains(&gated), "the stack with terms is not gated:\n{rust}");
        assert!(!rust.contains(&format!("{VISCOELASTIC_ONLY}\npub const LIVER:")), "the elastic stack is gated:\n{rust}");
        assert!(rust.contains(&format!("{VISCOELASTIC_ONLY}\npub const ALL: [Stack<'static>; 2] = [LIVER, VISCO];")), "{rust}");
        assert!(rust.contains("#[cfg(not(feature = \"viscoelastic\"))]\npub const ALL: [Stack<'static>; 1] = [LIVER];"), "{rust}");
        let all_elastic = render_rust_stacks(&[elastic_stack], None);
        // (every layer's presliding field is the feature's: a field, not a gate of the stack)
        let stacks_only = all_elastic.replace(&format!("{PRESLIDING_ONLY} presliding:"), "");
        assert!(!stacks_only.contains("cfg("), "an elastic set needs no feature gate:\n{all_elastic}");
    }

    #[test]
    fn a_stack_with_a_presliding_is_compiled_only_with_the_shaft_presliding_feature() {
        let plain = shipped("liver");
        let mut held = shipped("liver");
        held.1.name = "held".to_string();
        held.1.format = 2;
        held.1.layers.iter_mut().for_each(|l| l.presliding_mm = Some(1.5));
        let rust = render_rust_stacks(&[plain.clone(), held], None);
        assert!(rust.contains("#[cfg(feature = \"shaft-presliding\")]\npub const HELD:"), "the presliding stack is not gated:\n{rust}");
        assert!(!rust.contains("#[cfg(feature = \"shaft-presliding\")]\npub const LIVER:"), "the plain stack is gated:\n{rust}");
        assert!(
            rust.contains("#[cfg(all(feature = \"shaft-presliding\"))]\npub const ALL: [Stack<'static>; 2] = [LIVER, HELD];"),
            "{rust}"
        );
        assert!(rust.contains("#[cfg(all(not(feature = \"shaft-presliding\")))]\npub const ALL: [Stack<'static>; 1] = [LIVER];"), "{rust}");
        assert!(
            rust.contains("#[cfg(feature = \"shaft-presliding\")] presliding: Presliding { distance_mm: 1.5, relaxation_slip_mm: 1.5, shaft_prony: PronyTerms::NONE, tent_n_per_mm: 0.0 }"),
            "the layer's field, its slip distance defaulting to the distance:\n{rust}"
        );
        let plain_only = render_rust_stacks(&[plain], None);
        assert!(plain_only.contains("#[cfg(feature = \"shaft-presliding\")] presliding: Presliding::NONE"), "{plain_only}");
        assert!(!plain_only.contains("#[cfg(all("), "a set without presliding needs no ALL per feature:\n{plain_only}");
    }

    /// The shipped `rig_skin` (a family member, a softening, Prony terms) is compiled only
    /// with both features, and each of the four `ALL`s carries its own doc line (the
    /// library denies missing docs: a shared one left three undocumented).
    #[test]
    fn a_shaped_stack_is_compiled_only_with_the_tissue_shape_feature() {
        let rust = render_rust_stacks(&[shipped("epidural"), shipped("liver"), shipped("rig_skin")], None);
        let both = "#[cfg(all(feature = \"viscoelastic\", feature = \"tissue-shape\"))]\npub const RIG_SKIN:";
        assert!(rust.contains(both), "rig_skin is not gated by both features:\n{rust}");
        let alls: Vec<&str> = rust.lines().filter(|l| l.starts_with("pub const ALL")).collect();
        assert_eq!(
            alls,
            [
                "pub const ALL: [Stack<'static>; 1] = [LIVER];",
                "pub const ALL: [Stack<'static>; 1] = [LIVER];",
                "pub const ALL: [Stack<'static>; 2] = [EPIDURAL, LIVER];",
                "pub const ALL: [Stack<'static>; 3] = [EPIDURAL, LIVER, RIG_SKIN];",
            ]
        );
        let lines: Vec<&str> = rust.lines().collect();
        for (i, _) in lines.iter().enumerate().filter(|(_, l)| l.starts_with("pub const ALL")) {
            assert!(lines.get(i.wrapping_sub(2)).is_some_and(|d| d.starts_with("///")), "ALL at line {} has no doc:\n{rust}", i + 1);
        }
    }
}
