//! The edge study of `needle fe verify --edge` (issue 42, item 1): when the shape of the
//! campaign's needle does not converge under mesh refinement, the needle's edge radius
//! as a parameter. For each radius of `campaign.edge_study_radii_mm` the centre (quarter
//! model) is solved on every level of `campaign.mesh_study` with
//! `needle.tip_edge_radius_mm` set to it ([`super::mesh_study`] with
//! [`MeshOptions::edge_radius_mm`], into `fe/edge/r<radius>mm/<level>/`), and compared
//! like the mesh study (shape after the best scale, absolute change, Richardson), with the
//! poses of `campaign.edge_study_poses` on the pair [`Campaign::edge_study_pair`] (the
//! committed level and its refinement, or, when the committed level is off the ladder,
//! the ladder's level before the mesh study's reference and that reference); beside it,
//! each pose's run on the pair's first level against the same level's run with the
//! campaign's edge (`fe/<pose>.csv`, or `fe/mesh/<level>/`): how much the edge changes
//! the shape, and the campaign's edge's run against this edge's on the refined level:
//! whether the data carry its converged shape. Not judged: the goals are the campaign
//! mesh's (`[mesh]`); these are the numbers to choose the mesh and the edge by.

use crate::campaign::runs::{read_current, same_depths, PoseRows};
use crate::campaign::RunOptions;
use crate::mesh::shape::{self, ShapeComparison};
use crate::mesh::study::{self, MeshOptions, MeshReport};
use crate::set_folder::SetFolder;
use crate::spec::{Campaign, Role};
use anyhow::{Context, Result};
use serde::Serialize;

/// One radius of the study.
#[derive(Debug, Clone, Serialize)]
pub struct EdgeStudy {
    /// The needle's edge radius of these runs, mm.
    pub radius_mm: f64,
    /// The campaign's own edge radius (`needle.tip_edge_radius_mm`), mm.
    pub campaign_radius_mm: f64,
    /// The centre on every level of the mesh study with this edge.
    pub mesh: MeshReport,
    /// Per pose (the centre, then `campaign.edge_study_poses`) with both results: the
    /// committed level's run with this edge against the campaign's (coarse: the
    /// campaign's edge, fine: this one): the shape the edge changes, after the best scale.
    pub against_campaign_edge: Vec<ShapeComparison>,
    /// Per pose with both results: the campaign's run (its edge, committed level) against
    /// this edge's run on the refined level: whether the committed data carry this
    /// edge's converged shape (judged like the mesh study: after the best scale).
    pub campaign_against_refined: Vec<ShapeComparison>,
}

impl std::fmt::Display for EdgeStudy {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let m = &self.mesh;
        write!(f, "edge r = {} mm:", self.radius_mm)?;
        let pairs: Vec<&ShapeComparison> = m.shape.iter().filter(|s| s.coarse == m.committed && s.fine == m.refined).collect();
        if pairs.is_empty() {
            write!(f, " {} vs {}: no comparison", m.committed, m.refined)?;
        }
        for s in pairs {
            write!(
                f,
                " {} {} vs {} after the best scale RMS {:.2}%, largest {:.2}% of peak |Fy| (the mesh study's goal {} / {}%: {});",
                s.pose,
                m.committed,
                m.refined,
                s.worst_rms_percent,
                s.worst_max_percent,
                m.shape_goal_percent[0],
                m.shape_goal_percent[1],
                if s.ok() { "within" } else { "outside" }
            )?;
        }
        if let Some(d) = m.difference_percent {
            write!(f, " centre Fy({} mm) {:+.2}%, {}", m.depth_mm, d, m.asymptotic)?;
        }
        for a in &self.against_campaign_edge {
            write!(
                f,
                "; {} against the campaign's edge ({} mm) on {}: scale {:.4}, then RMS {:.2}%, largest {:.2}%",
                a.pose, self.campaign_radius_mm, m.committed, a.scale, a.worst_rms_percent, a.worst_max_percent
            )?;
        }
        for a in &self.campaign_against_refined {
            write!(
                f,
                "; the campaign's {} ({} mm edge, {}) against this edge on {}: scale {:.4}, then RMS {:.2}%, largest {:.2}% ({})",
                a.pose,
                self.campaign_radius_mm,
                m.committed,
                m.refined,
                a.scale,
                a.worst_rms_percent,
                a.worst_max_percent,
                if a.ok() { "within the goal" } else { "outside the goal" }
            )?;
        }
        Ok(())
    }
}

/// Run (or resume, or with `o.solve` false only read) the study of every radius of
/// `campaign.edge_study_radii_mm`.
///
/// # Errors
/// The spec has no radii, or as [`super::mesh_study`].
pub fn edge_study(set: &SetFolder, c: &Campaign, o: &MeshOptions) -> Result<Vec<EdgeStudy>> {
    if c.campaign.edge_study_radii_mm.is_empty() {
        anyhow::bail!("--edge: campaign.edge_study_radii_mm is empty: name the edge radii to study, mm");
    }
    let centre = c.pose.iter().find(|p| p.role == Role::Centre).context("no pose with role centre in the spec")?.name.clone();
    let poses: Vec<String> = std::iter::once(centre).chain(c.campaign.edge_study_poses.iter().cloned()).collect();
    let mut out = Vec::new();
    for &r in &c.campaign.edge_study_radii_mm {
        let mesh = super::mesh_study(set, c, &MeshOptions { edge_radius_mm: Some(r), ..o.clone() })?;
        let read = |edge: Option<f64>, level: &str| -> Result<PoseRows> {
            let opts = RunOptions {
                only: Some(poses.join(",")),
                mesh: Some(level.to_string()),
                out_dir: Some(study::run_dir(c, &o.set_dir, level, edge)),
                edge_radius_mm: edge,
                ..RunOptions::new(&o.set_dir)
            };
            read_current(set, &opts)
        };
        let campaign = read(None, &mesh.committed)?;
        let compare = |level: &str| -> Result<Vec<ShapeComparison>> {
            let edge = read(Some(r), level)?;
            let labels = (format!("r {} mm {}", c.needle.tip_edge_radius_mm, mesh.committed), format!("r {r} mm {level}"));
            Ok(poses
                .iter()
                .filter_map(|p| match (campaign.get(p), edge.get(p)) {
                    (Some(Ok(a)), Some(Ok(b))) if same_depths(&a.rows, &b.rows) => {
                        Some(shape::compare(p, (&labels.0, &labels.1), &a.rows, &b.rows, c.needle.reference_from_tip_mm))
                    }
                    _ => None,
                })
                .collect())
        };
        let (against_campaign_edge, campaign_against_refined) = (compare(&mesh.committed)?, compare(&mesh.refined)?);
        let study = EdgeStudy {
            radius_mm: r,
            campaign_radius_mm: c.needle.tip_edge_radius_mm,
            mesh,
            against_campaign_edge,
            campaign_against_refined,
        };
        needle_stdx::outln!("{study}");
        out.push(study);
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use crate::spec::shipped_key;
    use std::path::Path;

    #[test]
    fn bad_radii_are_refused_with_file_line_and_field() {
        let (text, line, shipped) = shipped_key("campaign", "edge_study_radii_mm");
        for (bad, want) in [
            ("[0.0]", "must be > 0 and below the needle's radius"),
            ("[0.7]", "must be > 0 and below the needle's radius"),
            ("[0.1]", "is needle.tip_edge_radius_mm, the campaign's own edge"),
            ("[0.4, 0.4]", "0.4 mm is listed twice"),
        ] {
            let t = text.replacen(&shipped, &format!("edge_study_radii_mm = {bad}"), 1);
            let e = crate::spec::parse(&t, Path::new("campaign.toml")).err().map(|e| e.to_string()).unwrap_or_default();
            assert!(e.starts_with(&format!("campaign.toml:{line}: campaign.edge_study_radii_mm: ")) && e.contains(want), "{bad}: {e}");
        }
        assert_eq!(crate::mesh::study::edge_dir(0.4), "r0p4mm");
    }
}
