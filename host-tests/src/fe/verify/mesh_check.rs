//! The mesh-convergence check of `needle fe verify`: the centred vertical needle on the
//! committed mesh and on the `fine` level, Fy compared at full depth (goal 2%).

use crate::fe::backend::{Backend, CcxBackend, Job, JOB};
use crate::fe::dat;
use crate::fe::deck;
use crate::fe::spec::{self, Campaign, PoseSpec, Role};
use crate::fe::wrench;
use anyhow::{bail, Context, Result};
use serde::Serialize;
use std::path::Path;

/// Mesh-convergence result.
#[derive(Debug, Clone, Serialize)]
pub struct MeshReport {
    /// Mesh level of the committed data.
    pub committed: String,
    /// Depth at which the two are compared: full depth, or the deepest step the fine run
    /// finished when it stopped early (see `fine_failure`), mm.
    pub depth_mm: f64,
    /// Fy at `depth_mm` on it, N.
    pub fy_committed_n: f64,
    /// Fy at `depth_mm` on the fine level, N.
    pub fy_fine_n: f64,
    /// Why the fine run stopped before full depth (the check then fails).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub fine_failure: Option<String>,
    /// (committed - fine) / fine, %.
    pub difference_percent: f64,
    /// Wall time of the committed-mesh run, s.
    pub wall_committed_s: f64,
    /// Wall time of the fine-mesh run, s.
    pub wall_fine_s: f64,
}

pub(super) fn mesh_convergence(c: &Campaign, work: &Path) -> Result<MeshReport> {
    let centre = c.pose.iter().find(|p| p.role == Role::Centre).context("no pose with role centre in the spec")?;
    let committed = c.campaign.mesh.clone();
    let mut backend = CcxBackend::default();
    backend.prepare()?;
    // per level: Fy after each step it finished, wall time, why it stopped early
    let mut out: Vec<(Vec<f64>, f64, Option<String>)> = Vec::new();
    for level in [committed.as_str(), "fine"] {
        let mesh = c.mesh_level(level)?;
        let dir = work.join(format!("mesh-{level}"));
        std::fs::create_dir_all(&dir).with_context(|| format!("{}: cannot create", dir.display()))?;
        println!("solving the centred needle on mesh {level:?} ...");
        let job = Job {
            campaign: c,
            pose: centre,
            mesh_name: level,
            mesh,
            steps: c.loading.steps,
            work_dir: &dir,
            timeout: None,
            stall: Some(crate::fe::campaign::DEFAULT_STALL),
            first_increment: 1.0,
        };
        let start = std::time::Instant::now();
        let solved = backend.solve(&job);
        let wall = start.elapsed().as_secs_f64();
        match solved {
            Ok(s) => out.push((s.wrenches.iter().map(|w| w[1]).collect(), wall, None)),
            Err(f) => {
                let done = fy_of_finished_steps(c, centre, mesh, &dir).unwrap_or_default();
                if level == committed || done.is_empty() {
                    bail!("mesh {level:?}: {}; last lines of ccx's output:\n{}", f.message, f.log_tail);
                }
                out.push((done, wall, Some(f.message)));
            }
        }
    }
    let [(a, wall_a, _), (b, wall_b, fine_failure)] = <[_; 2]>::try_from(out).map_err(|_| anyhow::anyhow!("two mesh levels expected"))?;
    let k = a.len().min(b.len());
    let (Some(&fa), Some(&fb)) = (a.get(k.wrapping_sub(1)), b.get(k.wrapping_sub(1))) else {
        bail!("no load step finished on both meshes");
    };
    Ok(MeshReport {
        committed,
        depth_mm: c.loading.depth_at(k as u32),
        fy_committed_n: fa,
        fy_fine_n: fb,
        fine_failure,
        difference_percent: 100.0 * (fa - fb) / fb,
        wall_committed_s: wall_a,
        wall_fine_s: wall_b,
    })
}

/// Fy (N) after each step that a stopped run of the centred pose finished, read from its
/// `.dat` in `dir` (the deck is regenerated for the reduction; it is the one solved).
fn fy_of_finished_steps(c: &Campaign, pose: &PoseSpec, mesh: &spec::MeshLevel, dir: &Path) -> Result<Vec<f64>> {
    let deck = deck::write_deck(c, pose, mesh, c.loading.steps)?;
    let dat = dir.join(format!("{JOB}.dat"));
    let text = std::fs::read_to_string(&dat).with_context(|| format!("{}: cannot read", dat.display()))?;
    let blocks = dat::parse_rf(&text, &deck.print_set)?;
    let mut fy = Vec::new();
    for (k, b) in (1u32..).zip(&blocks) {
        if (b.total_time - f64::from(k)).abs() > 1e-5 * f64::from(k) {
            break;
        }
        fy.push(wrench::reduce(&deck, pose, c, &b.nodes)?[1]);
    }
    Ok(fy)
}
