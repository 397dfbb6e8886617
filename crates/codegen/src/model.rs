//! Reading and validating `model.toml` (format in `coeffs/README.md`).
use crate::contract::{COMPONENTS, DEPTH_MAX_MM, FORMAT, HALF_RANGES, ODD, SWEEPS};
use crate::error::CodegenError;
use needle_contract::COMPONENT_COUNT;
use needle_contract::{DEGREE, TERMS};
use serde::Deserialize;
use std::ops::Range;
use std::path::Path;
use toml::Spanned;

/// One baseline polynomial `B_c(u)` (centred, vertical needle), validated.
#[derive(Debug, Clone, PartialEq)]
pub struct Baseline {
    /// Component index (0..5, order of [`COMPONENTS`]).
    pub component: usize,
    /// f64 coefficients; `coeffs[i]` multiplies `u^i`.
    pub coeffs: [f64; TERMS],
    /// The f32 the firmware uses: the nearest f32 of each `coeffs[i]`.
    pub coeffs_f32: [f32; TERMS],
    /// RMS fit residual, in the component's unit (N or N*mm).
    pub residual_rms: f64,
    /// Maximum absolute fit residual, in the component's unit.
    pub residual_max: f64,
    /// 1-based line of its `[[baseline]]` header in the model file (0 when unfitted).
    pub line: usize,
}

/// One deviation matrix `D_kc(t, u)`, validated.
#[derive(Debug, Clone, PartialEq)]
pub struct Matrix {
    /// Sweep index (0..3, order of [`SWEEPS`]).
    pub sweep: usize,
    /// Component index (0..5).
    pub component: usize,
    /// The component changes sign under the sweep's mirror.
    pub odd: bool,
    /// f64 coefficients; `rows[i][j]` multiplies `u^i * t^j`.
    pub rows: [[f64; TERMS]; TERMS],
    /// The nearest f32 of each `rows[i][j]`.
    pub rows_f32: [[f32; TERMS]; TERMS],
    /// RMS residual of (centre run + deviation) against FE over the sweep, in the
    /// component's unit.
    pub residual_rms: f64,
    /// Maximum absolute residual, same definition and unit.
    pub residual_max: f64,
    /// 1-based line of its `[[matrix]]` entry in the model file (0 when unfitted).
    pub line: usize,
}

/// One cross term of the coupled form, validated: `w_c += m(n) * P(u)`.
#[derive(Debug, Clone, PartialEq)]
pub struct Cross {
    /// Component index (0..5).
    pub component: usize,
    /// Exponents of `(xi, zeta, alpha, beta)` = `(x/12, z/12, theta_x/15, theta_z/15)`.
    pub exponents: [u8; 4],
    /// f64 coefficients of `P`; `coeffs[i]` multiplies `u^i`.
    pub coeffs: Vec<f64>,
    /// The nearest f32 of each coefficient.
    pub coeffs_f32: Vec<f32>,
    /// 1-based line of its `[[cross]]` header in the model file.
    pub line: usize,
}

/// The coupled form's `[coupled]` table, validated.
#[derive(Debug, Clone, PartialEq)]
pub struct Coupled {
    /// Largest total degree of a cross monomial (2..=4).
    pub max_degree: u8,
    /// Degree of every cross term's depth polynomial (2..=4).
    pub depth_degree: u8,
    /// Training runs the cross terms were fitted on.
    pub training_runs: usize,
    /// Cross-validated RMS error per component, % of `scale`.
    pub cv_rms_pct: [f64; COMPONENT_COUNT],
    /// The scale of `cv_rms_pct` per component: peak |Fy| of the training runs (N), times
    /// the lever arm for the moments (N*mm).
    pub scale: [f64; COMPONENT_COUNT],
}

/// A validated model: everything the generators need.
#[derive(Debug, Clone, PartialEq)]
pub struct Model {
    /// `false` for the placeholder of a set that has no `model.toml` yet (all zero).
    pub fitted: bool,
    /// Name of the set (`set` in model.toml, or the folder's name when unfitted).
    pub set: String,
    /// Hash of the FE files the model was fitted on (empty when unfitted).
    pub fe_sha256: String,
    /// `COMPONENT_COUNT` baselines, component order.
    pub baseline: Vec<Baseline>,
    /// `SWEEPS.len() * COMPONENT_COUNT` deviation matrices, sweep-major then component order.
    pub matrices: Vec<Matrix>,
    /// The coupled form's table (`form = "coupled"`); `None`: the paper form.
    pub coupled: Option<Coupled>,
    /// The coupled form's cross terms, component order then file order (empty for the
    /// paper form).
    pub cross: Vec<Cross>,
}

impl Model {
    /// The placeholder of a set without a fitted model: zero tables, `fitted == false`.
    pub fn unfitted(set: &str) -> Self {
        let baseline = (0..COMPONENT_COUNT)
            .map(|c| Baseline {
                component: c,
                coeffs: [0.0; TERMS],
                coeffs_f32: [0.0; TERMS],
                residual_rms: 0.0,
                residual_max: 0.0,
                line: 0,
            })
            .collect();
        let matrices = (0..SWEEPS.len() * COMPONENT_COUNT)
            .map(|n| Matrix {
                sweep: n / COMPONENT_COUNT,
                component: n % COMPONENT_COUNT,
                odd: ODD[n / COMPONENT_COUNT][n % COMPONENT_COUNT],
                rows: [[0.0; TERMS]; TERMS],
                rows_f32: [[0.0; TERMS]; TERMS],
                residual_rms: 0.0,
                residual_max: 0.0,
                line: 0,
            })
            .collect();
        Self { fitted: false, set: set.to_string(), fe_sha256: String::new(), baseline, matrices, coupled: None, cross: Vec::new() }
    }

    /// The f32 baseline table, `[component][i]`.
    pub fn baseline_f32(&self) -> [[f32; TERMS]; COMPONENT_COUNT] {
        let mut out = [[0.0; TERMS]; COMPONENT_COUNT];
        for (o, b) in out.iter_mut().zip(&self.baseline) {
            *o = b.coeffs_f32;
        }
        out
    }

    /// The f32 deviation table, `[sweep][component][i][j]`.
    pub fn deviation_f32(&self) -> [[[[f32; TERMS]; TERMS]; COMPONENT_COUNT]; 4] {
        let mut out = [[[[0.0; TERMS]; TERMS]; COMPONENT_COUNT]; 4];
        for m in &self.matrices {
            out[m.sweep][m.component] = m.rows_f32;
        }
        out
    }
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawModel {
    format: Spanned<i64>,
    set: Spanned<String>,
    fe_sha256: Spanned<String>,
    depth_max_mm: Spanned<f64>,
    x_max_mm: Spanned<f64>,
    z_max_mm: Spanned<f64>,
    theta_max_deg: Spanned<f64>,
    #[serde(default)]
    form: Option<Spanned<String>>,
    baseline: Spanned<Vec<Spanned<RawBaseline>>>,
    matrix: Spanned<Vec<Spanned<RawMatrix>>>,
    #[serde(default)]
    coupled: Option<Spanned<RawCoupled>>,
    #[serde(default)]
    cross: Vec<Spanned<RawCross>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawCoupled {
    max_degree: Spanned<i64>,
    depth_degree: Spanned<i64>,
    training_runs: Spanned<i64>,
    cv_rms_pct: Spanned<Vec<Spanned<f64>>>,
    scale: Spanned<Vec<Spanned<f64>>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawCross {
    component: Spanned<String>,
    exponents: Spanned<Vec<Spanned<i64>>>,
    coeffs: Spanned<Vec<Spanned<f64>>>,
    coeffs_f32: Spanned<Vec<Spanned<String>>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawBaseline {
    component: Spanned<String>,
    coeffs: Spanned<Vec<Spanned<f64>>>,
    coeffs_f32: Spanned<Vec<Spanned<String>>>,
    residual_rms: Spanned<f64>,
    residual_max: Spanned<f64>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawMatrix {
    sweep: Spanned<String>,
    component: Spanned<String>,
    odd: Spanned<bool>,
    rows: Spanned<Vec<Spanned<Vec<Spanned<f64>>>>>,
    rows_f32: Spanned<Vec<Spanned<Vec<Spanned<String>>>>>,
    residual_rms: Spanned<f64>,
    residual_max: Spanned<f64>,
}

/// Reads and validates the model file at `path`.
///
/// # Errors
/// An unreadable file, invalid TOML, or any departure from the format of
/// `coeffs/README.md`, with the line it is on.
pub fn parse_model(path: &Path) -> Result<Model, CodegenError> {
    let text = std::fs::read_to_string(path).map_err(|e| CodegenError::file(path, format!("cannot read the model file: {e}")))?;
    parse_model_str(&text, path)
}

/// Validates `text`, the contents of the model file `path` (used in error messages).
///
/// # Errors
/// Invalid TOML, or any departure from the format of `coeffs/README.md`, with the line.
pub fn parse_model_str(text: &str, path: &Path) -> Result<Model, CodegenError> {
    let raw: RawModel = toml::from_str(text).map_err(|e| {
        let end = text.trim_end().len();
        let offset = e.span().map_or(end, |s| s.start);
        let hint = if offset >= end { " (at the end of the file: truncated?)" } else { "" };
        CodegenError::at(path, text, offset, format!("{}{hint}", e.message().trim_end()))
    })?;
    Checker { path, text }.model(raw)
}

struct Checker<'a> {
    path: &'a Path,
    text: &'a str,
}

impl Checker<'_> {
    fn err(&self, span: Range<usize>, message: impl Into<String>) -> CodegenError {
        CodegenError::at(self.path, self.text, span.start, message)
    }

    fn model(&self, raw: RawModel) -> Result<Model, CodegenError> {
        if *raw.format.get_ref() != FORMAT {
            return Err(self.err(
                raw.format.span(),
                format!("format = {}: this build reads model format {FORMAT} (coeffs/README.md)", raw.format.get_ref()),
            ));
        }
        let set = raw.set.get_ref();
        if set.is_empty() || !set.chars().all(|c| c.is_ascii_alphanumeric() || matches!(c, '-' | '_' | '.')) {
            return Err(
                self.err(raw.set.span(), format!("set = {set:?}: a set name is a folder name of ASCII letters, digits, '-', '_' and '.'"))
            );
        }
        let hash = raw.fe_sha256.get_ref();
        if hash.len() != 64 || !hash.chars().all(|c| c.is_ascii_digit() || ('a'..='f').contains(&c)) {
            return Err(self.err(raw.fe_sha256.span(), format!("fe_sha256 = {hash:?}: expected 64 lower-case hex digits (a SHA-256)")));
        }
        let domain = [
            (&raw.depth_max_mm, "depth_max_mm", DEPTH_MAX_MM, "0 <= depth <= 6 mm"),
            (&raw.x_max_mm, "x_max_mm", HALF_RANGES[0], "|x| <= 12 mm"),
            (&raw.z_max_mm, "z_max_mm", HALF_RANGES[1], "|z| <= 12 mm"),
            (&raw.theta_max_deg, "theta_max_deg", HALF_RANGES[2], "|theta_x|, |theta_z| <= 15 deg"),
        ];
        for (value, key, want, what) in domain {
            if *value.get_ref() != want {
                return Err(self.err(
                    value.span(),
                    format!(
                        "{key} = {:?}: the contract's domain is {what} (coeffs/README.md); the evaluator's normalisation is built on it",
                        value.get_ref()
                    ),
                ));
            }
        }

        let baseline_span = raw.baseline.span();
        let baselines = raw.baseline.into_inner();
        self.count(&baselines, COMPONENT_COUNT, "[[baseline]]", baseline_span)?;
        let mut baseline = Vec::with_capacity(COMPONENT_COUNT);
        for (c, entry) in baselines.into_iter().enumerate() {
            let line = crate::error::line_of(self.text, entry.span().start);
            baseline.push(Baseline { line, ..self.baseline(c, entry.into_inner())? });
        }

        let matrix_span = raw.matrix.span();
        let matrices_raw = raw.matrix.into_inner();
        self.count(&matrices_raw, SWEEPS.len() * COMPONENT_COUNT, "[[matrix]]", matrix_span)?;
        let mut matrices = Vec::with_capacity(SWEEPS.len() * COMPONENT_COUNT);
        for (n, entry) in matrices_raw.into_iter().enumerate() {
            let line = crate::error::line_of(self.text, entry.span().start);
            matrices.push(Matrix { line, ..self.matrix(n / COMPONENT_COUNT, n % COMPONENT_COUNT, entry.into_inner())? });
        }

        let (coupled, cross) = self.form(raw.form, raw.coupled, raw.cross)?;
        Ok(Model { fitted: true, set: set.clone(), fe_sha256: hash.clone(), baseline, matrices, coupled, cross })
    }

    /// `form`, `[coupled]` and `[[cross]]`: absent or `"paper"` (then neither table), or
    /// `"coupled"` with both.
    fn form(
        &self,
        form: Option<Spanned<String>>,
        coupled: Option<Spanned<RawCoupled>>,
        cross: Vec<Spanned<RawCross>>,
    ) -> Result<(Option<Coupled>, Vec<Cross>), CodegenError> {
        let is_coupled = match &form {
            None => false,
            Some(f) if f.get_ref() == "paper" => false,
            Some(f) if f.get_ref() == "coupled" => true,
            Some(f) => return Err(self.err(f.span(), format!("form = {:?}: the forms are \"paper\" and \"coupled\"", f.get_ref()))),
        };
        if !is_coupled {
            if let Some(c) = &coupled {
                return Err(self.err(c.span(), "[coupled] belongs to form = \"coupled\" only"));
            }
            if let Some(x) = cross.first() {
                return Err(self.err(x.span(), "[[cross]] belongs to form = \"coupled\" only"));
            }
            return Ok((None, Vec::new()));
        }
        let Some(raw) = coupled else {
            let span = form.map(|f| f.span()).unwrap_or(0..0);
            return Err(self.err(span, "form = \"coupled\" needs a [coupled] table"));
        };
        let raw = raw.into_inner();
        let degree = |v: &Spanned<i64>, key: &str| -> Result<u8, CodegenError> {
            match u8::try_from(*v.get_ref()) {
                Ok(d) if (2..=4).contains(&d) => Ok(d),
                _ => Err(self.err(v.span(), format!("[coupled] {key} = {}: expected 2, 3 or 4", v.get_ref()))),
            }
        };
        let max_degree = degree(&raw.max_degree, "max_degree")?;
        let depth_degree = degree(&raw.depth_degree, "depth_degree")?;
        let training_runs = usize::try_from(*raw.training_runs.get_ref())
            .map_err(|_| self.err(raw.training_runs.span(), "[coupled] training_runs: expected a count >= 0"))?;
        let six = |v: &Spanned<Vec<Spanned<f64>>>, key: &str| -> Result<[f64; COMPONENT_COUNT], CodegenError> {
            let list = v.get_ref();
            if list.len() != COMPONENT_COUNT {
                return Err(
                    self.err(v.span(), format!("[coupled] {key}: {} values, expected {COMPONENT_COUNT} (one per component)", list.len()))
                );
            }
            let mut out = [0.0; COMPONENT_COUNT];
            for (o, x) in out.iter_mut().zip(list) {
                let val = self.finite(x, &format!("[coupled] {key}"))?;
                if val < 0.0 {
                    return Err(self.err(x.span(), format!("[coupled] {key}: {val:?} < 0")));
                }
                *o = val;
            }
            Ok(out)
        };
        let cv_rms_pct = six(&raw.cv_rms_pct, "cv_rms_pct")?;
        let scale = six(&raw.scale, "scale")?;
        let mut terms = Vec::with_capacity(cross.len());
        let mut last_component = 0usize;
        for (n, entry) in cross.into_iter().enumerate() {
            let line = crate::error::line_of(self.text, entry.span().start);
            let x = self.cross_term(n, entry.into_inner(), max_degree, depth_degree, last_component)?;
            last_component = x.component;
            terms.push(Cross { line, ..x });
        }
        Ok((Some(Coupled { max_degree, depth_degree, training_runs, cv_rms_pct, scale }), terms))
    }

    /// One `[[cross]]` entry: a known component not before `after`, a monomial of total
    /// degree 2..=`max_degree` in at least two inputs with the component's mirror parities
    /// (coeffs/README.md, "The coupled form"), `depth_degree + 1` coefficients.
    fn cross_term(&self, n: usize, raw: RawCross, max_degree: u8, depth_degree: u8, after: usize) -> Result<Cross, CodegenError> {
        let name = raw.component.get_ref();
        let Some(c) = COMPONENTS.iter().position(|x| x == name) else {
            return Err(self.err(
                raw.component.span(),
                format!("cross {}: component = {name:?}: unknown (components: {})", n + 1, COMPONENTS.join(", ")),
            ));
        };
        if c < after {
            return Err(self.err(
                raw.component.span(),
                format!("cross {}: component = {name:?} after {:?}: entries are in component order", n + 1, COMPONENTS[after]),
            ));
        }
        let list = raw.exponents.get_ref();
        let mut e = [0u8; 4];
        if list.len() != 4 {
            return Err(self.err(
                raw.exponents.span(),
                format!("cross {} ({name}): {} exponents, expected 4 (x, z, theta_x, theta_z)", n + 1, list.len()),
            ));
        }
        for (o, v) in e.iter_mut().zip(list) {
            *o = u8::try_from(*v.get_ref())
                .ok()
                .filter(|k| *k <= max_degree)
                .ok_or_else(|| self.err(v.span(), format!("cross {} ({name}): exponent {} not in 0..={max_degree}", n + 1, v.get_ref())))?;
        }
        let total: u8 = e.iter().sum();
        let inputs = e.iter().filter(|&&k| k > 0).count();
        let odd_x = (e[0] + e[3]) % 2 == 1;
        let odd_z = (e[1] + e[2]) % 2 == 1;
        if !(2..=max_degree).contains(&total) || inputs < 2 || odd_x != ODD[0][c] || odd_z != ODD[1][c] {
            return Err(self.err(
                raw.exponents.span(),
                format!(
                    "cross {} ({name}): exponents {e:?}: a cross monomial has total degree 2..={max_degree} in at least two inputs, odd in (x, theta_z) exactly when {name} is odd under the x mirror ({}) and odd in (z, theta_x) exactly when it is odd under the z mirror ({})",
                    n + 1,
                    ODD[0][c],
                    ODD[1][c]
                ),
            ));
        }
        let want = usize::from(depth_degree) + 1;
        let label = format!("cross {} ({name}, exponents {e:?})", n + 1);
        let (coeffs, coeffs_f32) =
            self.list(&raw.coeffs, &raw.coeffs_f32, want, &format!("{label}: coeffs"), &format!("{label}: coeffs_f32"))?;
        Ok(Cross { component: c, exponents: e, coeffs, coeffs_f32, line: 0 })
    }

    fn count<T>(&self, entries: &[Spanned<T>], want: usize, what: &str, all: Range<usize>) -> Result<(), CodegenError> {
        if entries.len() == want {
            return Ok(());
        }
        let (offset, hint) = match entries.get(want) {
            // One too many: point at the first extra entry.
            Some(extra) => (extra.span().start, ""),
            // Too few: point at the end of the last one (a truncated file ends there).
            None => (entries.last().map_or(all.start, |e| e.span().end.saturating_sub(1)), " (truncated file?)"),
        };
        Err(CodegenError::at(
            self.path,
            self.text,
            offset,
            format!("{} {what} entries, the contract has exactly {want}{hint}", entries.len()),
        ))
    }

    fn name_at(&self, value: &Spanned<String>, key: &str, names: &[&str], want: usize, order: &str) -> Result<(), CodegenError> {
        let got = value.get_ref();
        let expected = names.get(want).copied().unwrap_or_default();
        if got == expected {
            return Ok(());
        }
        let known = if names.contains(&got.as_str()) { "out of order" } else { "unknown" };
        Err(self.err(value.span(), format!("{key} = {got:?} ({known}): expected {expected:?} here; the order is {order}")))
    }

    fn finite(&self, v: &Spanned<f64>, what: &str) -> Result<f64, CodegenError> {
        let x = *v.get_ref();
        if x.is_finite() {
            Ok(x)
        } else {
            Err(self.err(v.span(), format!("{what} = {x}: every number must be finite")))
        }
    }

    fn residual(&self, v: &Spanned<f64>, what: &str) -> Result<f64, CodegenError> {
        let x = self.finite(v, what)?;
        if x < 0.0 {
            return Err(self.err(v.span(), format!("{what} = {x:?}: a residual is >= 0")));
        }
        Ok(x)
    }

    /// One polynomial: `TERMS` finite f64 and their f32 bit strings, each the nearest f32.
    fn poly(
        &self,
        values: &Spanned<Vec<Spanned<f64>>>,
        bits: &Spanned<Vec<Spanned<String>>>,
        what: &str,
        what_f32: &str,
    ) -> Result<([f64; TERMS], [f32; TERMS]), CodegenError> {
        let (v, b) = self.list(values, bits, TERMS, what, what_f32)?;
        let mut out = [0.0; TERMS];
        let mut out32 = [0.0; TERMS];
        out.copy_from_slice(&v);
        out32.copy_from_slice(&b);
        Ok((out, out32))
    }

    /// `n` finite f64 and their `n` f32 bit strings, each the nearest f32.
    fn list(
        &self,
        values: &Spanned<Vec<Spanned<f64>>>,
        bits: &Spanned<Vec<Spanned<String>>>,
        n: usize,
        what: &str,
        what_f32: &str,
    ) -> Result<(Vec<f64>, Vec<f32>), CodegenError> {
        for (list, name) in [(values.get_ref().len(), what), (bits.get_ref().len(), what_f32)] {
            if list != n {
                let span = if name == what { values.span() } else { bits.span() };
                return Err(self.err(span, format!("{name} has {list} values, expected {n} (powers 0..={})", n - 1)));
            }
        }
        let mut out = vec![0.0; n];
        let mut out32 = vec![0.0; n];
        for (j, ((v, b), (o, o32))) in values.get_ref().iter().zip(bits.get_ref()).zip(out.iter_mut().zip(out32.iter_mut())).enumerate() {
            let x = self.finite(v, &format!("{what}[{j}]"))?;
            let nearest = x as f32;
            if !nearest.is_finite() {
                return Err(self.err(v.span(), format!("{what}[{j}] = {x:?} overflows f32")));
            }
            let text = b.get_ref();
            let parsed = parse_bits(text).ok_or_else(|| {
                self.err(b.span(), format!("{what_f32}[{j}] = {text:?}: expected \"0x\" and 8 lower-case hex digits (f32 bits)"))
            })?;
            if parsed != nearest.to_bits() {
                return Err(self.err(
                    b.span(),
                    format!(
                        "{what_f32}[{j}] = {text} ({:?}) is not the nearest f32 of {what}[{j}] = {x:?}, which is {:#010x} ({nearest:?})",
                        f32::from_bits(parsed),
                        nearest.to_bits()
                    ),
                ));
            }
            *o = x;
            *o32 = nearest;
        }
        Ok((out, out32))
    }

    fn baseline(&self, c: usize, raw: RawBaseline) -> Result<Baseline, CodegenError> {
        self.name_at(&raw.component, "component", &COMPONENTS, c, &COMPONENTS.join(", "))?;
        let name = COMPONENTS[c];
        let (coeffs, coeffs_f32) =
            self.poly(&raw.coeffs, &raw.coeffs_f32, &format!("baseline {name}: coeffs"), &format!("baseline {name}: coeffs_f32"))?;
        Ok(Baseline {
            component: c,
            coeffs,
            coeffs_f32,
            residual_rms: self.residual(&raw.residual_rms, &format!("baseline {name}: residual_rms"))?,
            residual_max: self.residual(&raw.residual_max, &format!("baseline {name}: residual_max"))?,
            line: 0,
        })
    }

    fn matrix(&self, k: usize, c: usize, raw: RawMatrix) -> Result<Matrix, CodegenError> {
        let order = format!("sweep-major ({}), then component ({})", SWEEPS.join(", "), crate::contract::component_range());
        self.name_at(&raw.sweep, "sweep", &SWEEPS, k, &order)?;
        self.name_at(&raw.component, "component", &COMPONENTS, c, &order)?;
        let label = format!("matrix {}/{}", SWEEPS[k], COMPONENTS[c]);
        let odd = ODD[k][c];
        if *raw.odd.get_ref() != odd {
            return Err(self.err(
                raw.odd.span(),
                format!(
                    "{label}: odd = {}, but the contract's mirror table says {odd} (coeffs/README.md, \"Mirror symmetries\")",
                    raw.odd.get_ref()
                ),
            ));
        }
        for (n, name, span) in
            [(raw.rows.get_ref().len(), "rows", raw.rows.span()), (raw.rows_f32.get_ref().len(), "rows_f32", raw.rows_f32.span())]
        {
            if n != TERMS {
                return Err(self.err(span, format!("{label}: {name} has {n} rows, expected {TERMS} (powers of u 0..={DEGREE})")));
            }
        }
        let mut rows = [[0.0; TERMS]; TERMS];
        let mut rows_f32 = [[0.0; TERMS]; TERMS];
        for (i, ((r, b), (o, o32))) in
            raw.rows.get_ref().iter().zip(raw.rows_f32.get_ref()).zip(rows.iter_mut().zip(rows_f32.iter_mut())).enumerate()
        {
            let (row, row32) = self.poly(r, b, &format!("{label}: rows[{i}]"), &format!("{label}: rows_f32[{i}]"))?;
            self.zero_at_sweep_zero(r.span(), &label, i, &row, &row32)?;
            *o = row;
            *o32 = row32;
        }
        Ok(Matrix {
            sweep: k,
            component: c,
            odd,
            rows,
            rows_f32,
            residual_rms: self.residual(&raw.residual_rms, &format!("{label}: residual_rms"))?,
            residual_max: self.residual(&raw.residual_max, &format!("{label}: residual_max"))?,
            line: 0,
        })
    }
}

impl Checker<'_> {
    /// A deviation row vanishes at `t = -1` (sweep value 0; coeffs/README.md, "The
    /// model"): exactly in the contract's f32 Horner (step 4, `h(rows_f32[i], -1)` is a
    /// zero), and in f64 within the f32 rounding that made it exact there: the fitter
    /// writes `rows[i][0] = -q`, `q` the f32 Horner of the other coefficients' nearest f32,
    /// which is within `7 * 2^-24 * sum_j |rows[i][j]|` (four roundings of a coefficient,
    /// three of a sum) of the f64 alternating sum; `2^-21` is 8 such units.
    fn zero_at_sweep_zero(
        &self,
        span: Range<usize>,
        label: &str,
        i: usize,
        row: &[f64; TERMS],
        row32: &[f32; TERMS],
    ) -> Result<(), CodegenError> {
        let [p0, p1, p2, p3, p4] = *row32;
        let t = -1.0_f32;
        let f32_at_zero = (((p4 * t + p3) * t + p2) * t + p1) * t + p0;
        if f32_at_zero != 0.0 {
            return Err(self.err(
                span,
                format!(
                    "{label}: rows_f32[{i}] at t = -1 is {f32_at_zero:e} in f32, not 0: a deviation vanishes at sweep value 0 exactly in the f32 evaluation (rows[i][0] = -(((p4*(-1) + p3)*(-1) + p2)*(-1) + p1)*(-1), each operation rounded in f32)"
                ),
            ));
        }
        let at_zero: f64 = row.iter().zip([1.0, -1.0, 1.0, -1.0, 1.0]).map(|(a, s)| a * s).sum();
        let scale: f64 = row.iter().map(|a| a.abs()).sum();
        if at_zero.abs() > ZERO_AT_SWEEP_ZERO_F64 * scale {
            return Err(self.err(
                span,
                format!(
                    "{label}: rows[{i}] at t = -1 is {at_zero:e} in f64, over 2^-21 * sum_j |rows[{i}][j]| = {:e}: a deviation vanishes at sweep value 0 (rows[i][0] -= sum_j rows[i][j] * (-1)^j, then made exact in f32)",
                    ZERO_AT_SWEEP_ZERO_F64 * scale
                ),
            ));
        }
        Ok(())
    }
}

/// The f64 tolerance of a deviation row at `t = -1`, relative to `sum_j |rows[i][j]|`:
/// `2^-21`, the f32 rounding of the row's exact zero in f32 (`Checker::zero_at_sweep_zero`).
pub const ZERO_AT_SWEEP_ZERO_F64: f64 = 1.0 / (1u32 << 21) as f64;

/// Parses `0x` and exactly 8 lower-case hex digits.
pub fn parse_bits(text: &str) -> Option<u32> {
    let digits = text.strip_prefix("0x")?;
    if digits.len() != 8 || !digits.chars().all(|c| c.is_ascii_digit() || ('a'..='f').contains(&c)) {
        return None;
    }
    u32::from_str_radix(digits, 16).ok()
}

/// The f32 coefficients of a generated file's `coeffs` and `coeffs_f32` keys: exactly `N`
/// finite values within the f32 range, each bit string `0x` + 8 lower-case hex digits and
/// the nearest f32 of its coefficient. `at_coeffs` and `at_bits` make the error of each
/// key (its file and line).
pub(crate) fn nearest_f32s<const N: usize>(
    coeffs: &[f64],
    bits: &[String],
    at_coeffs: &dyn Fn(String) -> CodegenError,
    at_bits: &dyn Fn(String) -> CodegenError,
) -> Result<[f32; N], CodegenError> {
    if coeffs.len() != N || !coeffs.iter().all(|c| c.is_finite() && c.abs() <= f64::from(f32::MAX)) {
        return Err(at_coeffs(format!("coeffs: {} values, expected {N} finite ones", coeffs.len())));
    }
    if bits.len() != N {
        return Err(at_bits(format!("coeffs_f32: {} values, expected {N}", bits.len())));
    }
    let mut out = [0.0f32; N];
    for ((slot, c), b) in out.iter_mut().zip(coeffs).zip(bits) {
        let v = f32::from_bits(parse_bits(b).ok_or_else(|| at_bits(format!("coeffs_f32: {b:?} is not 0x + 8 lower-case hex digits")))?);
        #[allow(clippy::cast_possible_truncation)]
        let nearest = *c as f32;
        if v.to_bits() != nearest.to_bits() {
            return Err(at_bits(format!("coeffs_f32: {b} is not the nearest f32 of {c:?}")));
        }
        *slot = v;
    }
    Ok(out)
}
