//! `family.toml` (coeffs/README.md, "The material family"): the family's surrogate, from
//! the centre runs of `[family]` (`fe/family/`, issue 64).
//!
//! The law: a member of weight `w` (the paper's Ogden terms x `w`, a soft term x `1 - w`,
//! `needle_set::spec::family`) gives the reference's force times a ratio,
//! `F_w(d) = F_paper(d) g(d, w)`, where `F_paper` is the centre run of the paper's own
//! tissue on the same mesh (`centre_paper`) and
//!
//! `g(d, w) = 1 + (1 - w) sum_{j=0..=DEPTH_DEGREE} sum_{k=0..=WEIGHT_DEGREE} a_jk u^j t^k`,
//! `u = d / depth_max_mm`, `t = sqrt(w)`:
//!
//! exactly 1 at `w = 1` (the paper's tissue, so a stack without a family weight keeps its
//! values), a polynomial in depth and in `sqrt(w)` (the members are spaced about evenly
//! in it). The coefficients are a least-squares fit over every must point of the fitted
//! members, each point weighted by `F_paper(d) / peak |F_w|` so that the residual is the
//! force error as a fraction of the member's peak: the figure [`MemberCheck`] reports,
//! for the fitted members and for `family.held_out` (members it was not fitted on).
//! The six-axis pose dependence is carried over by the same ratio (the library's wrench
//! at a pose times `g`), checked by the half-model runs `family.check_poses`
//! ([`crate::family_poses`]).
use crate::lsq;
use anyhow::{bail, Context, Result};
use nalgebra::{DMatrix, DVector};
use needle_contract::FY;
use needle_set::manifest::{read_manifest, Manifest, MANIFEST};
use needle_set::partial;
use needle_set::results::{content_sha256, parse_csv, Row};
use needle_set::set_folder::{SetFolder, FAMILY_DIR};
use needle_set::spec::family::runs::{apply, FamilyRun};
use needle_set::spec::{Campaign, PoseSpec};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// The file's name, the law's degrees in depth and in `t = sqrt(w)`, its coefficient
/// count (`a_jk` at `j * (WEIGHT_DEGREE + 1) + k`): the generator's, which reads the file.
pub use needle_codegen::family::{DEPTH_DEGREE, FILE, TERMS, WEIGHT_DEGREE};
/// Must points shallower than this are not fitted: the forces there are below 1 % of
/// the peak and their ratio is the solver's noise.
pub const MIN_DEPTH_MM: f64 = 0.25;

/// One member's centre run, read and checked against its manifest entry.
#[derive(Debug, Clone, PartialEq)]
pub struct MemberRun {
    /// The member's weight of the paper's terms.
    pub weight: f64,
    /// Depth (mm) and Fy (N) at every must point.
    pub fy: Vec<(f64, f64)>,
    /// SHA-256 of its CSV.
    pub csv_sha256: String,
    /// Whether the run reached the family's depth (false: the must points of its furthest
    /// failed attempt, its `.partial.csv`).
    pub complete: bool,
}

/// How the law meets one member's run.
#[derive(Debug, Clone, PartialEq)]
pub struct MemberCheck {
    /// The member's weight.
    pub weight: f64,
    /// Whether the law was fitted on it (false: held out, or a partial run).
    pub fitted: bool,
    /// Whether its run reached the family's depth (false: a partial record).
    pub complete: bool,
    /// Deepest depth compared, mm.
    pub depth_mm: f64,
    /// RMS over its must points of `F_paper g - F_w`, % of the run's peak |Fy|.
    pub rms_pct: f64,
    /// Largest |F_paper g - F_w|, % of the run's peak |Fy|.
    pub max_pct: f64,
}

/// The fitted family law.
#[derive(Debug, Clone, PartialEq)]
pub struct FamilyLaw {
    /// SHA-256 of the reference run's CSV.
    pub reference_sha256: String,
    /// The fitted members: weight and SHA-256 of the CSV.
    pub fitted: Vec<(f64, String)>,
    /// Deepest depth of the law, mm: the reference run's (`family.depth_mm`); past it the
    /// library holds `g` at its value there.
    pub depth_max_mm: f64,
    /// `a_jk`, at `j * (WEIGHT_DEGREE + 1) + k`.
    pub coeffs: [f64; TERMS],
    /// The law against every member run present.
    pub checks: Vec<MemberCheck>,
}

/// `g(d, w)` of `coeffs` (the module's law), in f64; `depth_mm` is not clamped here.
#[must_use]
pub fn ratio(coeffs: &[f64; TERMS], depth_max_mm: f64, depth_mm: f64, weight: f64) -> f64 {
    let u = depth_mm / depth_max_mm;
    let t = weight.max(0.0).sqrt();
    let mut sum = 0.0;
    for j in (0..=DEPTH_DEGREE).rev() {
        let mut col = 0.0;
        for k in (0..=WEIGHT_DEGREE).rev() {
            col = col * t + coeffs[j * (WEIGHT_DEGREE + 1) + k];
        }
        sum = sum * u + col;
    }
    1.0 + (1.0 - weight) * sum
}

/// The family's runs of `set` that are present and current (complete, or the must points
/// of a run that failed every attempt so far): the reference and the members, in
/// `family.weight`'s order; `None` without a `[family]` section or without a reference run.
///
/// # Errors
/// An unreadable manifest or CSV, a CSV that is not the one its entry was written for,
/// or a run solved from another spec (each names its file).
pub fn read_runs(set: &SetFolder) -> Result<Option<(MemberRun, Vec<MemberRun>)>> {
    let c = set.campaign();
    let Some(f) = &c.family else { return Ok(None) };
    let (dir, manifest) = read_family_manifest(set)?;
    let Some(reference) = read_run(c, &manifest, &dir, FamilyRun::Reference)? else { return Ok(None) };
    let mut members = Vec::new();
    for &weight in &f.weight {
        if let Some(run) = read_run(c, &manifest, &dir, FamilyRun::Centre { weight })? {
            members.push(run);
        }
    }
    Ok(Some((reference, members)))
}

/// The run of `[family.fitted]` (`FamilyRun::fitted`: the calibrated layer's member and
/// scale read from its stack), its Fy against depth, as [`read_runs`] reads a member's:
/// vouched by its manifest entry's hash (the stack's values are in it), or its
/// `.partial.csv` when it failed; `None` without the section or a result.
///
/// # Errors
/// The stack cannot be read ([`FamilyRun::fitted`]), and [`read_runs`]'s.
pub fn read_fitted_run(set: &SetFolder) -> Result<Option<MemberRun>> {
    let c = set.campaign();
    let Some(f) = &c.family else { return Ok(None) };
    let Some(run) = FamilyRun::fitted(f, set.dir())? else { return Ok(None) };
    let (dir, manifest) = read_family_manifest(set)?;
    read_run(c, &manifest, &dir, run)
}

/// The family's folder `fe/family/` of `set` and its manifest (empty when there is none yet).
///
/// # Errors
/// An unreadable or malformed manifest (with its path).
pub(crate) fn read_family_manifest(set: &SetFolder) -> Result<(PathBuf, Manifest)> {
    let dir = set.fe_dir().join(FAMILY_DIR);
    let manifest_path = dir.join(MANIFEST);
    let manifest = if manifest_path.is_file() {
        read_manifest(&manifest_path).with_context(|| format!("{}", manifest_path.display()))?
    } else {
        Manifest::default()
    };
    Ok((dir, manifest))
}

/// One family run's must points as read from `fe/family/`, vouched for by their hash.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct VouchedRun {
    /// Every row of the CSV (depth 0 first).
    pub rows: Vec<Row>,
    /// SHA-256 of the CSV.
    pub csv_sha256: String,
    /// Whether the run reached its depth (false: its `.partial.csv`).
    pub complete: bool,
}

/// What vouches for a run's CSV bytes: its manifest entry's or its partial record's hash.
type Vouch<'a> = Box<dyn Fn(&[u8]) -> bool + 'a>;

/// The family run of `pose` (a renamed pose of [`apply`]'s, solved with `campaign` on
/// `mesh`) in `dir`: its result, or when it failed every attempt so far the must points of
/// its furthest attempt (a current `.partial.csv`: converged FE states, only not as deep as
/// asked); `None` when there is neither.
///
/// # Errors
/// A result whose manifest entry is missing or stale, a CSV that is not the one its entry
/// or partial record was written for, or an unreadable CSV (each names its file).
pub(crate) fn read_vouched(
    campaign: &Campaign,
    manifest: &Manifest,
    dir: &Path,
    pose: &PoseSpec,
    mesh: &str,
) -> Result<Option<VouchedRun>> {
    let path = dir.join(format!("{}.csv", pose.name));
    // the CSV and what vouches for its bytes: its manifest entry, or its partial record
    let (path, vouched, complete): (_, Vouch<'_>, _) = if path.is_file() {
        let entry = manifest
            .current_entry(campaign, pose, mesh)
            .map_err(|why| anyhow::anyhow!("{}: {why}: rerun it with needle fe run --family --only {}", path.display(), pose.name))?;
        (path, Box::new(move |b: &[u8]| entry.content_matches(b)), true)
    } else {
        let Some(record) = partial::read_current_record(dir, &pose.name, &campaign.run_hash(pose, mesh)) else { return Ok(None) };
        (partial::paths(dir, &pose.name).0, Box::new(move |b: &[u8]| content_sha256(b) == record.csv_sha256), false)
    };
    let bytes = std::fs::read(&path).with_context(|| format!("{}: cannot read", path.display()))?;
    if !vouched(&bytes) {
        bail!(
            "{}: content changed since the FE run wrote it (not the csv_sha256 of its {MANIFEST} entry or .partial.toml)",
            path.display()
        );
    }
    let rows: Vec<Row> = parse_csv(&String::from_utf8_lossy(&bytes), &path)?;
    Ok(Some(VouchedRun { rows, csv_sha256: content_sha256(&bytes), complete }))
}

/// The centre run of `run` ([`read_vouched`]), its Fy against depth.
fn read_run(c: &Campaign, manifest: &Manifest, dir: &Path, run: FamilyRun) -> Result<Option<MemberRun>> {
    let Some(f) = &c.family else { return Ok(None) };
    let (campaign, poses, mesh) = apply(c, f, run);
    let Some(pose) = poses.first() else { return Ok(None) };
    let Some(v) = read_vouched(&campaign, manifest, dir, pose, &mesh)? else { return Ok(None) };
    let fy = v.rows.iter().map(|r| (r.depth_mm, r.wrench[FY])).collect();
    Ok(Some(MemberRun { weight: run.weight().unwrap_or(1.0), fy, csv_sha256: v.csv_sha256, complete: v.complete }))
}

impl MemberRun {
    /// Fy at `depth_mm`, when it is one of the run's must points (the family's runs share
    /// their load steps).
    #[must_use]
    pub fn fy_at(&self, depth_mm: f64) -> Option<f64> {
        self.fy.iter().find(|(d, _)| (d - depth_mm).abs() < 1e-9).map(|&(_, f)| f)
    }

    /// The deepest must point the run reached, mm.
    #[must_use]
    pub fn deepest_mm(&self) -> f64 {
        self.fy.iter().map(|p| p.0).fold(0.0, f64::max)
    }
}

/// What [`fit`] made of a set's family runs.
#[derive(Debug, Clone, PartialEq)]
pub enum FamilyFit {
    /// No `[family]` section, or no reference run yet: nothing to fit, no file.
    None,
    /// Runs are present but too few to fit the law (the reason, for `needle fit` to print):
    /// no file is written, the set's earlier `family.toml` stays as it is.
    Pending(String),
    /// The law.
    Law(FamilyLaw),
}

/// The law fitted on the complete runs of the members of `set` that are not held out (a
/// partial run leaves the law's deep part to the others: with three members, one of them
/// partial, the held-out member 0.1 was off by 2,227 % RMS), checked on every run present.
///
/// # Errors
/// A failed least squares, and [`read_runs`]'s.
pub fn fit(set: &SetFolder) -> Result<FamilyFit> {
    let Some((reference, members)) = read_runs(set)? else { return Ok(FamilyFit::None) };
    if !reference.complete {
        return Ok(FamilyFit::Pending(
            "material family law: not fitted: the reference run centre_paper has not reached the family's depth".into(),
        ));
    }
    let held_out = set.campaign().family.as_ref().map(|f| f.held_out.clone()).unwrap_or_default();
    let (fitted, partial): (Vec<&MemberRun>, Vec<&MemberRun>) =
        members.iter().filter(|m| !held_out.contains(&m.weight)).partition(|m| m.complete);
    if fitted.len() < WEIGHT_DEGREE + 1 {
        let short: Vec<String> = partial.iter().map(|m| format!("{} to {:.2} mm", m.weight, m.deepest_mm())).collect();
        return Ok(FamilyFit::Pending(format!(
            "material family law: not fitted: {} complete member run(s) in fe/{FAMILY_DIR}/ (weights {:?}; partial: {}), the law needs at least {}",
            fitted.len(),
            fitted.iter().map(|m| m.weight).collect::<Vec<_>>(),
            if short.is_empty() { "none".to_string() } else { short.join(", ") },
            WEIGHT_DEGREE + 1
        )));
    }
    let depth_max_mm = reference.deepest_mm();
    let mut rows: Vec<([f64; TERMS], f64)> = Vec::new();
    for m in &fitted {
        let peak = m.fy.iter().map(|p| p.1.abs()).fold(0.0, f64::max);
        for &(d, fw) in m.fy.iter().filter(|p| p.0 >= MIN_DEPTH_MM && p.0 <= depth_max_mm + 1e-9) {
            let Some(fp) = reference.fy_at(d).filter(|f| f.abs() > 0.0) else { continue };
            // (F_w - F_p) / peak = F_p (1 - w) P / peak: the row of P, weighted
            let scale = fp * (1.0 - m.weight) / peak;
            let (u, t) = (d / depth_max_mm, m.weight.sqrt());
            let row = std::array::from_fn(|i| scale * u.powi((i / (WEIGHT_DEGREE + 1)) as i32) * t.powi((i % (WEIGHT_DEGREE + 1)) as i32));
            rows.push((row, (fw - fp) / peak));
        }
    }
    if rows.len() < 2 * TERMS {
        return Ok(FamilyFit::Pending(format!(
            "material family law: not fitted: {} must points in the fitted runs, the law's {TERMS} coefficients need at least {}",
            rows.len(),
            2 * TERMS
        )));
    }
    let a = DMatrix::from_fn(rows.len(), TERMS, |i, k| rows[i].0[k]);
    let b = DVector::from_iterator(rows.len(), rows.iter().map(|r| r.1));
    let solved = lsq::lstsq(&a, &b).context("the family law's least squares")?;
    let coeffs: [f64; TERMS] = std::array::from_fn(|k| solved[k]);
    let is_fitted = |m: &MemberRun| fitted.iter().any(|f| f.weight == m.weight);
    let checks = members.iter().map(|m| check(&reference, m, &coeffs, depth_max_mm, is_fitted(m))).collect();
    let fitted = fitted.iter().map(|m| (m.weight, m.csv_sha256.clone())).collect();
    Ok(FamilyFit::Law(FamilyLaw { reference_sha256: reference.csv_sha256, fitted, depth_max_mm, coeffs, checks }))
}

/// The law against member `m` over its must points down to `depth_max_mm`.
fn check(reference: &MemberRun, m: &MemberRun, coeffs: &[f64; TERMS], depth_max_mm: f64, fitted: bool) -> MemberCheck {
    let peak = m.fy.iter().map(|p| p.1.abs()).fold(0.0, f64::max).max(f64::MIN_POSITIVE);
    let (mut sum, mut max, mut n, mut deepest) = (0.0, 0.0f64, 0usize, 0.0f64);
    for &(d, fw) in m.fy.iter().filter(|p| p.0 > 0.0 && p.0 <= depth_max_mm + 1e-9) {
        let Some(fp) = reference.fy_at(d) else { continue };
        let e = 100.0 * (fp * ratio(coeffs, depth_max_mm, d, m.weight) - fw) / peak;
        sum += e * e;
        max = max.max(e.abs());
        n += 1;
        deepest = deepest.max(d);
    }
    let rms_pct = if n > 0 { (sum / n as f64).sqrt() } else { f64::NAN };
    MemberCheck { weight: m.weight, fitted, complete: m.complete, depth_mm: deepest, rms_pct, max_pct: max }
}

/// The text of `family.toml`.
#[must_use]
pub fn to_toml(law: &FamilyLaw) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "# generated by `needle fit`; do not edit. Format: coeffs/README.md, \"The material family\".");
    let _ = writeln!(s, "# F_w(d) = F_paper(d) g(d, w), g = 1 + (1 - w) sum_jk coeffs[j * {} + k] u^j t^k,", WEIGHT_DEGREE + 1);
    let _ =
        writeln!(s, "# u = d / depth_max_mm, t = sqrt(w), j = 0..={DEPTH_DEGREE}, k = 0..={WEIGHT_DEGREE}; fitted on fe/{FAMILY_DIR}/.");
    let _ = writeln!(s, "format = 1");
    let _ = writeln!(s, "reference_sha256 = \"{}\"", law.reference_sha256);
    let w: Vec<String> = law.fitted.iter().map(|(w, _)| format!("{w:?}")).collect();
    let _ = writeln!(s, "fitted_weights = [{}]", w.join(", "));
    let h: Vec<String> = law.fitted.iter().map(|(_, h)| format!("\"{h}\"")).collect();
    let _ = writeln!(s, "fitted_sha256 = [{}]", h.join(", "));
    let _ = writeln!(s, "depth_max_mm = {:?}", law.depth_max_mm);
    let _ = writeln!(s, "depth_degree = {DEPTH_DEGREE}");
    let _ = writeln!(s, "weight_degree = {WEIGHT_DEGREE}");
    let list: Vec<String> = law.coeffs.iter().map(|c| format!("{c:?}")).collect();
    let _ = writeln!(s, "coeffs = [{}]", list.join(", "));
    let bits: Vec<String> = law.coeffs.iter().map(|c| format!("\"{}\"", crate::model_file::hex32(*c as f32))).collect();
    let _ = writeln!(s, "coeffs_f32 = [{}]", bits.join(", "));
    for c in &law.checks {
        let _ = writeln!(s, "\n[[check]]");
        let _ = writeln!(s, "weight = {:?}", c.weight);
        let _ = writeln!(s, "fitted = {}", c.fitted);
        let _ = writeln!(s, "complete = {}", c.complete);
        let _ = writeln!(s, "depth_mm = {:?}", c.depth_mm);
        let _ = writeln!(s, "rms_pct = {:?}", c.rms_pct);
        let _ = writeln!(s, "max_pct = {:?}", c.max_pct);
    }
    s
}

/// The lines `needle fit` prints for the law.
#[must_use]
pub fn summary(law: &FamilyLaw) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "material family law F_w(d) = F_paper(d) g(d, w), fitted on weights {:?} to {:.2} mm (|law - FE|, % of the member's peak |Fy|):",
        law.fitted.iter().map(|f| f.0).collect::<Vec<_>>(),
        law.depth_max_mm
    );
    let _ = writeln!(s, "weight      role      run       to mm    rms %    max %");
    for c in &law.checks {
        let role = if c.fitted { "fitted" } else { "held out" };
        let run = if c.complete { "complete" } else { "partial" };
        let _ = writeln!(s, "{:<10} {role:<9} {run:<9} {:6.2} {:8.3} {:8.3}", c.weight, c.depth_mm, c.rms_pct, c.max_pct);
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_law_is_exactly_one_at_the_papers_weight() {
        let coeffs: [f64; TERMS] = std::array::from_fn(|i| 0.37 * (i as f64 + 1.0));
        for d in [0.0, 3.0, 16.2] {
            assert_eq!(ratio(&coeffs, 16.2, d, 1.0), 1.0);
        }
        assert!((ratio(&coeffs, 16.2, 0.0, 0.0) - (1.0 + coeffs[0])).abs() < 1e-15, "u = t = 0 leaves a_00");
    }

    /// What the fitter writes, the generator reads back: the same f32 coefficients and
    /// depth (the format round trip; a field renamed on one side fails here).
    #[test]
    fn the_generator_reads_what_the_fitter_writes() {
        let coeffs: [f64; TERMS] = std::array::from_fn(|i| (i as f64 - 7.0) * 0.123_456_789);
        let check = MemberCheck { weight: 0.1, fitted: false, complete: true, depth_mm: 16.2, rms_pct: 0.5, max_pct: 1.0 };
        let law = FamilyLaw {
            reference_sha256: "ab".repeat(32),
            fitted: vec![(0.05, "cd".repeat(32)), (0.2, "ef".repeat(32))],
            depth_max_mm: 15.9,
            coeffs,
            checks: vec![check],
        };
        let dir = tempfile::tempdir().expect("temp dir");
        let path = dir.path().join(FILE);
        std::fs::write(&path, to_toml(&law)).expect("write");
        let read = needle_codegen::family::parse(&path).expect("the generator reads the fitter's file");
        assert_eq!(read.depth_max_mm, 15.9);
        assert_eq!(read.coeffs_f32.map(f32::to_bits), coeffs.map(|c| (c as f32).to_bits()));
    }
}
