//! The mesh study (run by `needle fe verify --mesh`, and by its edge study
//! `crate::verify::edge` with the needle's edge radius as a parameter): the centre pose on every level of
//! `campaign.mesh_study` (coarse to fine, each a 2x refinement of the one before) and the
//! half-model poses of `campaign.mesh_study_poses` on the committed level and its
//! refinement (the level after it, or `campaign.mesh_reference` for a committed level
//! off the ladder: [`crate::spec::mesh_study`]). Runs of the committed level are the committed `fe/<pose>.csv`; the others
//! are solved through the campaign's machinery into `fe/mesh/<level>/` (with a manifest:
//! an interrupted study resumes, a solved run is read, not solved again).
//!
//! Reported: the absolute change of Fy at full depth between levels (the centre's, with
//! Richardson's estimate when the finest three are in the asymptotic range, else the
//! ratio of successive changes), and per pose and pair of levels the shape comparison of
//! [`shape`] (judged: the goal of issue 42).

use super::shape::{self, ShapeComparison};
use crate::pose_rows::{same_depths, PoseRows};
use crate::spec::{Campaign, Role};
use anyhow::{Context, Result};
use needle_contract::FY;
use serde::Serialize;
use std::path::{Path, PathBuf};

/// Sub-folder of `<set>/fe/` with the study's runs, one folder per level.
pub const MESH_DIR: &str = "mesh";

/// Sub-folder of `<set>/fe/` with the edge study's runs: `edge/r<radius>mm/<level>/`
/// ([`edge_dir`]).
pub const EDGE_DIR: &str = "edge";

/// The edge study's folder of radius `radius_mm` in `<set>/fe/edge/`: `r0p4mm`.
pub fn edge_dir(radius_mm: f64) -> String {
    format!("r{}mm", crate::spec::visco::decimal_tag(radius_mm))
}

/// The folder of `level`'s runs in `<set_dir>/fe/`: with an edge radius the edge study's
/// `edge/r<radius>mm/<level>/`; with the campaign's needle `fe/` itself on the committed
/// level (the campaign's runs) and the mesh study's `mesh/<level>/` on another.
pub fn run_dir(c: &Campaign, set_dir: &Path, level: &str, edge_radius_mm: Option<f64>) -> PathBuf {
    let fe = set_dir.join("fe");
    match edge_radius_mm {
        Some(r) => fe.join(EDGE_DIR).join(edge_dir(r)).join(level),
        None if level == c.campaign.mesh => fe,
        None => fe.join(MESH_DIR).join(level),
    }
}

/// What the study runs on.
#[derive(Debug, Clone)]
pub struct MeshOptions {
    /// The set folder.
    pub set_dir: PathBuf,
    /// Solver threads of each run.
    pub threads: usize,
    /// Solve the runs that are not up to date (false: compare what is there).
    pub solve: bool,
    /// The edge study at this needle edge radius, mm (`campaign.edge_study_radii_mm`):
    /// the centre on every level and `campaign.edge_study_poses` on the committed level
    /// and its refinement (the committed one solved too), into
    /// `fe/edge/<edge_dir>/<level>/`. `None`: the mesh study of the campaign's needle.
    pub edge_radius_mm: Option<f64>,
}

/// One run of the study.
#[derive(Debug, Clone, Serialize)]
pub struct LevelRun {
    /// Pose name.
    pub pose: String,
    /// Mesh level name.
    pub level: String,
    /// Element size of the fine region (`fine_size_mm`), mm.
    pub element_mm: f64,
    /// Tissue elements of the model (0: no run).
    pub tissue_elements: u64,
    /// Fy at full depth, N.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub fy_n: Option<f64>,
    /// Wall time of the solve (the manifest's), s.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub wall_s: Option<f64>,
    /// Why there is no result.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub failure: Option<String>,
    /// The attempts that failed before the one that solved it (the manifest's `retry`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub retry: Option<String>,
}

/// The study.
#[derive(Debug, Clone, Serialize)]
pub struct MeshReport {
    /// The engine of the set.
    pub engine: String,
    /// Mesh level of the committed data.
    pub committed: String,
    /// Its 2x refinement (the next level of the study).
    pub refined: String,
    /// Depth of the comparison, mm (full depth).
    pub depth_mm: f64,
    /// Every run, levels coarse to fine, the centre first.
    pub levels: Vec<LevelRun>,
    /// The centre's (Fy committed - Fy refined) / Fy refined at full depth, %.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub difference_percent: Option<f64>,
    /// The centre's changes of Fy at full depth between the finest three levels, the
    /// finer over the coarser: below 1 and positive in the asymptotic range.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub ratio_of_changes: Option<f64>,
    /// "in the asymptotic range" or "not in the asymptotic range" (or why unknown).
    pub asymptotic: String,
    /// Richardson extrapolation of the centre's Fy from the finest three levels, N.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub richardson_fy_n: Option<f64>,
    /// The observed order of convergence of that extrapolation.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub richardson_order: Option<f64>,
    /// (Fy committed - Richardson) / Richardson, %.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub committed_vs_richardson_percent: Option<f64>,
    /// Goals of the shape comparisons, % of peak |Fy|: RMS and largest.
    pub shape_goal_percent: [f64; 2],
    /// Every pose's shape comparison between successive levels it was run on.
    pub shape: Vec<ShapeComparison>,
    /// Per pose on three successive levels (the centre): how the shape difference
    /// changes under refinement.
    pub shape_trend: Vec<ShapeTrend>,
}

/// One pose on three successive levels: the shape difference of the finer pair over the
/// coarser pair's (below 1: the shape converges; the absolute level's counterpart is the
/// ratio of successive changes of Fy).
#[derive(Debug, Clone, Serialize)]
pub struct ShapeTrend {
    /// Pose name.
    pub pose: String,
    /// The three levels, coarse to fine.
    pub levels: [String; 3],
    /// Worst component RMS after the best scale, coarser pair then finer pair, %.
    pub worst_rms_percent: [f64; 2],
    /// Largest difference after the best scale, coarser pair then finer pair, %.
    pub worst_max_percent: [f64; 2],
    /// Finer pair's worst RMS over the coarser pair's.
    pub rms_ratio: f64,
    /// Finer pair's largest difference over the coarser pair's.
    pub max_ratio: f64,
}

/// The trends of `shape`: each pair of comparisons of one pose that share a level.
pub fn shape_trends(shape: &[ShapeComparison]) -> Vec<ShapeTrend> {
    let mut out = Vec::new();
    for a in shape {
        for b in shape.iter().filter(|b| b.pose == a.pose && b.coarse == a.fine) {
            out.push(ShapeTrend {
                pose: a.pose.clone(),
                levels: [a.coarse.clone(), a.fine.clone(), b.fine.clone()],
                worst_rms_percent: [a.worst_rms_percent, b.worst_rms_percent],
                worst_max_percent: [a.worst_max_percent, b.worst_max_percent],
                rms_ratio: b.worst_rms_percent / a.worst_rms_percent,
                max_ratio: b.worst_max_percent / a.worst_max_percent,
            });
        }
    }
    out
}

impl std::fmt::Display for ShapeTrend {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "shape trend {:>6} {} -> {} -> {}: worst RMS {:.2}% -> {:.2}% (ratio {:.3}), largest {:.2}% -> {:.2}% (ratio {:.3}): {}",
            self.pose,
            self.levels[0],
            self.levels[1],
            self.levels[2],
            self.worst_rms_percent[0],
            self.worst_rms_percent[1],
            self.rms_ratio,
            self.worst_max_percent[0],
            self.worst_max_percent[1],
            self.max_ratio,
            if self.rms_ratio < 1.0 && self.max_ratio < 1.0 {
                "the shape difference shrinks"
            } else {
                "the shape difference does not shrink"
            }
        )
    }
}

impl MeshReport {
    /// Every study run present and the committed level within the shape goals against its
    /// refinement for every pose.
    pub fn ok(&self) -> bool {
        self.levels.iter().all(|l| l.failure.is_none())
            && self.shape.iter().filter(|s| s.coarse == self.committed && s.fine == self.refined).all(ShapeComparison::ok)
    }
}

/// Richardson extrapolation of f(h) from values at h, h/2, h/4 (coarse to fine): the
/// limit and the observed order, or `None` when the differences do not shrink with the
/// same sign (no asymptotic range).
pub fn richardson(f1: f64, f2: f64, f3: f64) -> Option<(f64, f64)> {
    let (d1, d2) = (f1 - f2, f2 - f3);
    if !(d1.is_finite() && d2.is_finite()) || d1 == 0.0 || d2 == 0.0 || d1.signum() != d2.signum() || d2.abs() >= d1.abs() {
        return None;
    }
    let p = (d1 / d2).ln() / 2f64.ln();
    Some((f3 - d2 / (2f64.powf(p) - 1.0), p))
}

/// The study's levels, coarse to fine, each with the poses it runs.
type StudyPlan = Vec<(String, Vec<String>)>;

/// The study's plan (the centre on every level of the ladder, and on the committed level
/// when it is off the ladder, just before its reference; `extra` on the judged pair), the
/// judged level and its reference. The edge study (`edge`) runs on the ladder only, its
/// pair is [`Campaign::edge_study_pair`].
fn plan_study(c: &Campaign, extra: &[String], edge: bool) -> Result<(StudyPlan, String, String)> {
    let centre = c.pose.iter().find(|p| p.role == Role::Centre).context("no pose with role centre in the spec")?;
    let mut levels = c.mesh_study();
    let (judged, refined) = if edge { c.edge_study_pair() } else { c.mesh_study_pair() }.map_err(anyhow::Error::msg)?;
    if !levels.contains(&judged) {
        let k = levels.iter().position(|l| *l == refined).unwrap_or(levels.len());
        levels.insert(k, judged.clone());
    }
    let plan = levels
        .iter()
        .map(|level| {
            let mut poses = vec![centre.name.clone()];
            if *level == judged || *level == refined {
                poses.extend(extra.iter().cloned());
            }
            (level.clone(), poses)
        })
        .collect();
    Ok((plan, judged, refined))
}

/// The runs of one level the study asks its runner for.
#[derive(Debug, Clone, Copy)]
pub struct LevelRuns<'a> {
    /// The mesh level.
    pub level: &'a str,
    /// The poses, exact names.
    pub poses: &'a [String],
    /// Their output folder ([`run_dir`]).
    pub out_dir: &'a Path,
    /// Solve what is not up to date (else read what is there): `o.solve`, never for the
    /// committed level's campaign runs.
    pub solve: bool,
}

/// Run (or resume) the study and compare. `runs` solves (when asked) and reads one
/// level's runs: the campaign's machinery, which the caller hands in
/// (`crate::verify::mesh_study`), so that the study needs no campaign code.
///
/// # Errors
/// The spec, `campaign.mesh_study`, or as `runs` (a failed solve is a run's `failure`).
pub fn mesh_convergence(c: &Campaign, o: &MeshOptions, runs: &mut dyn FnMut(&LevelRuns<'_>) -> Result<PoseRows>) -> Result<MeshReport> {
    let poses = if o.edge_radius_mm.is_some() { &c.campaign.edge_study_poses } else { &c.campaign.mesh_study_poses };
    let (plan, committed, refined) = plan_study(c, poses, o.edge_radius_mm.is_some())?;
    let mut results: Vec<(String, PoseRows)> = Vec::new();
    for (level, poses) in &plan {
        // the committed level's runs of the campaign's needle are the campaign's: read,
        // never solved here
        let campaign_runs = *level == c.campaign.mesh && o.edge_radius_mm.is_none();
        let out_dir = run_dir(c, &o.set_dir, level, o.edge_radius_mm);
        let what = o.edge_radius_mm.map_or("mesh study".to_string(), |r| format!("edge study r = {r} mm"));
        needle_stdx::outln!("{what}, level {level}: {} in {}", poses.join(", "), out_dir.display());
        let rows = runs(&LevelRuns { level, poses, out_dir: &out_dir, solve: o.solve && !campaign_runs })?;
        results.push((level.clone(), rows));
    }
    let levels = level_runs(c, &results)?;
    let shape = shape_comparisons(c, &results, (&committed, &refined));
    for s in &shape {
        needle_stdx::outln!("{s}");
    }
    for t in shape_trends(&shape) {
        needle_stdx::outln!("{t}");
    }
    Ok(report(c, committed, refined, levels, shape, &plan))
}

fn level_runs(c: &Campaign, results: &[(String, PoseRows)]) -> Result<Vec<LevelRun>> {
    let mut out = Vec::new();
    for (level, rows) in results {
        let element_mm = c.mesh_level(level)?.fine_size_mm;
        for (pose, r) in rows {
            let run = LevelRun {
                pose: pose.clone(),
                level: level.clone(),
                element_mm,
                tissue_elements: r.as_ref().map(|r| r.entry.tissue_elements).unwrap_or(0),
                fy_n: r.as_ref().ok().and_then(|r| r.rows.last()).map(|w| w.wrench[FY]),
                wall_s: r.as_ref().ok().map(|r| r.entry.wall_s),
                failure: r.as_ref().err().cloned(),
                retry: r.as_ref().ok().and_then(|r| r.entry.retry.clone()),
            };
            needle_stdx::outln!(
                "  {pose} on {level}: {}",
                match (run.fy_n, &run.failure) {
                    (Some(f), _) => format!(
                        "Fy({} mm) = {f:.6e} N, {} tissue elements, {:.0} s",
                        c.loading.depth_mm,
                        run.tissue_elements,
                        run.wall_s.unwrap_or(0.0)
                    ),
                    (None, f) => format!("no result: {}", f.as_deref().unwrap_or("?")),
                }
            );
            out.push(run);
        }
    }
    Ok(out)
}

/// Each pose between each pair of successive levels of the ladder it has results on, and
/// between the judged pair `(committed, refined)` when the committed level is off the
/// ladder (its refinement is not a 2x one: no trend is drawn through it).
fn shape_comparisons(c: &Campaign, results: &[(String, PoseRows)], judged: (&str, &str)) -> Vec<ShapeComparison> {
    let ladder = c.mesh_study();
    let mut poses: Vec<&String> = results.iter().flat_map(|(_, r)| r.keys()).collect();
    poses.sort();
    poses.dedup();
    let mut out = Vec::new();
    let mut push = |pose: &str, (la, a): (&str, &[crate::results::Row]), (lb, b): (&str, &[crate::results::Row])| {
        if same_depths(a, b) {
            out.push(shape::compare(pose, (la, lb), a, b, c.needle.reference_from_tip_mm));
        }
    };
    for pose in poses {
        let have: Vec<(&str, &[crate::results::Row])> = results
            .iter()
            .filter_map(|(l, r)| r.get(pose).and_then(|r| r.as_ref().ok()).map(|r| (l.as_str(), r.rows.as_slice())))
            .collect();
        let on_ladder: Vec<_> = have.iter().copied().filter(|(l, _)| ladder.iter().any(|k| k == l)).collect();
        for w in on_ladder.windows(2) {
            push(pose, w[0], w[1]);
        }
        if !ladder.iter().any(|k| k == judged.0) {
            let find = |level: &str| have.iter().copied().find(|(l, _)| *l == level);
            if let (Some(a), Some(b)) = (find(judged.0), find(judged.1)) {
                push(pose, a, b);
            }
        }
    }
    out
}

fn report(
    c: &Campaign,
    committed: String,
    refined: String,
    levels: Vec<LevelRun>,
    shape: Vec<ShapeComparison>,
    plan: &[(String, Vec<String>)],
) -> MeshReport {
    let centre = plan.first().and_then(|(_, p)| p.first()).cloned().unwrap_or_default();
    let fy = |level: &str| levels.iter().find(|l| l.level == level && l.pose == centre).and_then(|l| l.fy_n);
    // Richardson's estimate on the ladder's levels only (each a 2x refinement)
    let ladder = c.mesh_study();
    let study: Vec<Option<f64>> = plan.iter().filter(|(l, _)| ladder.contains(l)).map(|(l, _)| fy(l)).collect();
    let difference_percent = fy(&committed).zip(fy(&refined)).map(|(a, b)| 100.0 * (a - b) / b);
    let last3 = match study.as_slice() {
        [.., Some(a), Some(b), Some(d)] => Some((*a, *b, *d)),
        _ => None,
    };
    let rich = last3.and_then(|(a, b, d)| richardson(a, b, d));
    let ratio_of_changes = last3.map(|(a, b, d)| (b - d) / (a - b));
    let asymptotic = match (last3, rich) {
        (None, _) => "unknown: the centre has no result on three levels".to_string(),
        (Some(_), Some(_)) => "in the asymptotic range".to_string(),
        (Some(_), None) => "not in the asymptotic range".to_string(),
    };
    MeshReport {
        engine: c.solver.engine.name().to_string(),
        depth_mm: c.loading.depth_mm,
        difference_percent,
        ratio_of_changes,
        asymptotic,
        richardson_fy_n: rich.map(|r| r.0),
        richardson_order: rich.map(|r| r.1),
        committed_vs_richardson_percent: rich.zip(fy(&committed)).map(|(r, f)| 100.0 * (f - r.0) / r.0),
        shape_goal_percent: [shape::SHAPE_RMS_GOAL_PERCENT, shape::SHAPE_MAX_GOAL_PERCENT],
        committed,
        refined,
        levels,
        shape_trend: shape_trends(&shape),
        shape,
    }
}

#[cfg(test)]
mod tests {
    use super::{plan_study, richardson, shape_comparisons, shape_trends};
    use crate::mesh::shape;
    use crate::results::Row;

    #[test]
    fn a_shape_difference_that_halves_is_a_shrinking_trend() {
        // Fy = d^2 on the finest level; the coarser levels add a bump at 3 mm of 6 % and
        // 2 % of peak |Fy| (a shape change no scale removes)
        let level = |bump: f64| -> Vec<Row> {
            (0..=6)
                .map(f64::from)
                .map(|d| Row { depth_mm: d, wrench: [0.0, d * d + if d == 3.0 { bump * 36.0 } else { 0.0 }, 0.0, 0.0, 0.0, 0.0] })
                .collect()
        };
        let (c, m, f) = (level(0.06), level(0.02), level(0.0));
        let s = vec![shape::compare("p", ("c", "m"), &c, &m, 60.0), shape::compare("p", ("m", "f"), &m, &f, 60.0)];
        let t = shape_trends(&s);
        assert_eq!(t.len(), 1);
        assert_eq!(t[0].levels, ["c".to_string(), "m".into(), "f".into()]);
        assert!(t[0].rms_ratio > 0.4 && t[0].rms_ratio < 0.6, "{}", t[0]);
        assert!(t[0].to_string().ends_with("the shape difference shrinks"), "{}", t[0]);
        let grows = shape_trends(&[s[1].clone(), shape::compare("p", ("f", "g"), &f, &c, 60.0)]);
        assert!(grows[0].rms_ratio > 1.0 && grows[0].to_string().ends_with("does not shrink"), "{}", grows[0]);
    }

    #[test]
    fn richardson_recovers_a_first_and_second_order_limit() {
        // f(h) = 1 + h^2 at h = 4, 2, 1 -> 17, 5, 2: order 2, limit 1
        let (f, p) = richardson(17.0, 5.0, 2.0).expect("asymptotic");
        assert!((f - 1.0).abs() < 1e-12 && (p - 2.0).abs() < 1e-12, "{f} {p}");
        // f(h) = 3 - h at h = 4, 2, 1 -> order 1, limit 3
        let (f, p) = richardson(-1.0, 1.0, 2.0).expect("asymptotic");
        assert!((f - 3.0).abs() < 1e-12 && (p - 1.0).abs() < 1e-12, "{f} {p}");
        assert!(richardson(1.0, 2.0, 1.5).is_none(), "oscillating");
        assert!(richardson(1.0, 1.1, 1.3).is_none(), "growing differences");
    }

    /// The shipped spec with core6 committed, judged against fine, off the ladder
    /// coarse8, needle8, fine; and the shipped set's folder.
    fn off_the_ladder() -> (crate::spec::Campaign, std::path::PathBuf) {
        let set = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../coeffs/default");
        let (mut c, _) = crate::spec::load(&set).expect("the shipped spec");
        c.campaign.mesh = "core6".into();
        c.campaign.mesh_reference = Some("fine".into());
        c.campaign.mesh_study = vec!["coarse8".into(), "needle8".into(), "fine".into()];
        (c, set)
    }

    #[test]
    fn a_committed_level_off_the_ladder_runs_beside_its_reference_and_the_edge_study_on_the_ladder() {
        let (mut c, _) = off_the_ladder();
        let extra = vec!["x+04".to_string()];
        let names = |plan: &[(String, Vec<String>)]| -> Vec<String> { plan.iter().map(|(l, p)| format!("{l}: {}", p.join(" "))).collect() };
        let (plan, judged, refined) = plan_study(&c, &extra, false).expect("the mesh study");
        assert_eq!((judged.as_str(), refined.as_str()), ("core6", "fine"));
        assert_eq!(names(&plan), ["coarse8: centre", "needle8: centre", "core6: centre x+04", "fine: centre x+04"]);
        let (plan, judged, refined) = plan_study(&c, &extra, true).expect("the edge study");
        assert_eq!((judged.as_str(), refined.as_str()), ("needle8", "fine"));
        assert_eq!(names(&plan), ["coarse8: centre", "needle8: centre x+04", "fine: centre x+04"]);
        c.campaign.mesh_reference = None;
        assert!(plan_study(&c, &extra, false).is_err(), "off the ladder without a reference");
    }

    #[test]
    fn a_committed_level_off_the_ladder_is_compared_with_its_reference_and_the_ladder_with_itself() {
        let (c, set) = off_the_ladder();
        let manifest = crate::manifest::read_manifest(&set.join("fe/manifest.toml")).expect("the shipped manifest");
        let entry = manifest.pose.get("centre").expect("the centre's entry").clone();
        let run = |k: f64| crate::pose_rows::Run {
            rows: (0..=6).map(f64::from).map(|d| Row { depth_mm: d, wrench: [0.0, k * d * d, 0.0, 0.0, 0.0, 0.0] }).collect(),
            entry: entry.clone(),
        };
        let results: Vec<(String, crate::pose_rows::PoseRows)> = ["coarse8", "needle8", "core6", "fine"]
            .iter()
            .enumerate()
            .map(|(i, l)| (l.to_string(), [("centre".to_string(), Ok(run(1.0 + 0.1 * i as f64)))].into_iter().collect()))
            .collect();
        let pairs: Vec<String> =
            shape_comparisons(&c, &results, ("core6", "fine")).iter().map(|s| format!("{} {}", s.coarse, s.fine)).collect();
        assert_eq!(pairs, ["coarse8 needle8", "needle8 fine", "core6 fine"]);
        let trends = shape_trends(&shape_comparisons(&c, &results, ("core6", "fine")));
        assert_eq!(trends.len(), 1, "one trend, on the ladder");
        assert_eq!(trends[0].levels, ["coarse8".to_string(), "needle8".into(), "fine".into()]);
    }
}
