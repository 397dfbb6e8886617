//! The mesh-convergence check of `needle fe verify`: the centred vertical needle solved
//! on the levels of `campaign.mesh_study` (coarse to fine, each a 2x refinement of the
//! one before, the committed level and its 2x refinement among them), on the set's
//! engine. Fy at full depth: the change from the committed level to its refinement
//! (goal 2 %), and, with three or more levels, Richardson's estimate of the converged
//! value from the finest three.

use crate::backend::Job;
use crate::engines::backend_for;
use crate::spec::{Campaign, Role};
use anyhow::{bail, Context, Result};
use serde::Serialize;
use std::path::Path;

/// One level of the study.
#[derive(Debug, Clone, Serialize)]
pub struct LevelRun {
    /// Mesh level name.
    pub level: String,
    /// Element size of the fine region (`fine_size_mm`), mm.
    pub element_mm: f64,
    /// Tissue elements of the (quarter) model.
    pub tissue_elements: usize,
    /// Fy at full depth, N (NaN when the run failed).
    pub fy_n: f64,
    /// Wall time of the solve, s.
    pub wall_s: f64,
    /// Solver threads of the solve.
    pub threads: usize,
    /// Why the run failed, when it did.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub failure: Option<String>,
    /// The attempts that failed before the one that solved it (the campaign's retries).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub retry: Option<String>,
}

/// Mesh-convergence result.
#[derive(Debug, Clone, Serialize)]
pub struct MeshReport {
    /// The engine that solved the study.
    pub engine: String,
    /// Mesh level of the committed data.
    pub committed: String,
    /// Its 2x refinement (the next level of the study).
    pub refined: String,
    /// Depth of the comparison, mm (full depth).
    pub depth_mm: f64,
    /// Every level, coarse to fine.
    pub levels: Vec<LevelRun>,
    /// (Fy committed - Fy refined) / Fy refined, %; NaN when a run failed.
    pub difference_percent: f64,
    /// Goal on |difference_percent|.
    pub goal_percent: f64,
    /// Richardson extrapolation of the finest three levels (refinement ratio 2):
    /// the converged Fy, N, when the differences shrink monotonically.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub richardson_fy_n: Option<f64>,
    /// The observed order of convergence of that extrapolation.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub richardson_order: Option<f64>,
    /// (Fy committed - Richardson) / Richardson, %.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub committed_vs_richardson_percent: Option<f64>,
}

/// Goal of the check: |change| of Fy at full depth under a 2x refinement, %.
pub const MESH_GOAL_PERCENT: f64 = 2.0;

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

pub(super) fn mesh_convergence(c: &Campaign, work: &Path, threads: usize) -> Result<MeshReport> {
    let centre = c.pose.iter().find(|p| p.role == Role::Centre).context("no pose with role centre in the spec")?;
    let study = c.mesh_study();
    let committed = c.campaign.mesh.clone();
    let Some(k) = study.iter().position(|l| *l == committed) else {
        bail!("campaign.mesh_study {study:?} does not hold the committed level {committed:?}");
    };
    let Some(refined) = study.get(k + 1).cloned() else {
        bail!("campaign.mesh_study {study:?}: the committed level {committed:?} needs its 2x refinement after it");
    };
    let mut backend = backend_for(c.solver.engine, threads);
    backend.prepare()?;
    let mut levels = Vec::new();
    for level in &study {
        let mesh = c.mesh_level(level)?;
        let dir = work.join(format!("mesh-{}-{level}", c.solver.engine.name()));
        if dir.exists() {
            std::fs::remove_dir_all(&dir).with_context(|| format!("{}: cannot clear", dir.display()))?;
        }
        std::fs::create_dir_all(&dir).with_context(|| format!("{}: cannot create", dir.display()))?;
        println!("solving the centred needle on mesh {level:?} with {} ...", c.solver.engine.name());
        let job = Job {
            campaign: c,
            pose: centre,
            mesh_name: level,
            mesh,
            steps: c.loading.steps,
            work_dir: &dir,
            timeout: None,
            stall: Some(crate::campaign::DEFAULT_STALL),
            first_increment: 1.0,
            attempt: 0,
        };
        // the campaign's attempts (Backend::attempts): a level is solved as a pose is;
        // wall_s counts every attempt, the manifest-style `retry` says which failed
        let start = std::time::Instant::now();
        let solved = crate::campaign::solve_with_retry(backend.as_ref(), &job);
        let wall_s = start.elapsed().as_secs_f64();
        let run = match solved {
            Ok(s) => LevelRun {
                level: level.clone(),
                element_mm: mesh.fine_size_mm,
                tissue_elements: s.summary.tissue_elements,
                fy_n: s.wrenches.last().map(|w| w[1]).unwrap_or(f64::NAN),
                wall_s,
                threads,
                failure: None,
                retry: s.retry,
            },
            Err(f) => LevelRun {
                level: level.clone(),
                element_mm: mesh.fine_size_mm,
                tissue_elements: 0,
                fy_n: f64::NAN,
                wall_s,
                threads,
                failure: Some(f.message),
                retry: None,
            },
        };
        println!(
            "  {level}: Fy({} mm) = {:.5e} N, {} tissue elements, {:.0} s{}",
            c.loading.depth_mm,
            run.fy_n,
            run.tissue_elements,
            run.wall_s,
            run.failure.as_deref().map(|f| format!(" (FAILED: {f})")).unwrap_or_default()
        );
        levels.push(run);
    }
    let fy = |name: &str| levels.iter().find(|l| l.level == name).map(|l| l.fy_n).unwrap_or(f64::NAN);
    let (fc, fr) = (fy(&committed), fy(&refined));
    let rich = match levels.as_slice() {
        [.., a, b, d] => richardson(a.fy_n, b.fy_n, d.fy_n),
        _ => None,
    };
    Ok(MeshReport {
        engine: c.solver.engine.name().to_string(),
        committed,
        refined,
        depth_mm: c.loading.depth_mm,
        difference_percent: 100.0 * (fc - fr) / fr,
        goal_percent: MESH_GOAL_PERCENT,
        richardson_fy_n: rich.map(|r| r.0),
        richardson_order: rich.map(|r| r.1),
        committed_vs_richardson_percent: rich.map(|r| 100.0 * (fc - r.0) / r.0),
        levels,
    })
}

#[cfg(test)]
mod tests {
    use super::richardson;

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
}
