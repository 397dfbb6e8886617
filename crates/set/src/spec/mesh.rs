//! `[mesh.<level>]`: the named mesh levels.

use super::error::{SpecError, SpecResult};
use super::positive;
use serde::{Deserialize, Serialize};
use std::path::Path;

/// `[mesh.<level>]`: the O-grid tissue mesh and the needle facets.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MeshLevel {
    /// Half side of the fine core square around the needle path, mm.
    pub core_half_mm: f64,
    /// Elements along each side of the core square (even).
    pub core_elements: u32,
    /// Size of the first ring and of the fine layers, mm.
    pub fine_size_mm: f64,
    /// Depth of the fine layers under the surface, mm.
    pub fine_depth_mm: f64,
    /// Geometric growth ratio of rings and layers.
    pub growth: f64,
    /// Needle facets per quarter circumference.
    pub needle_facets_per_quarter: u32,
    /// Needle layer length near the tip, mm.
    pub needle_axial_mm: f64,
    /// FEBio's Newton energy tolerance (`etol`) for the runs on this level, instead of
    /// `[solver.febio] etol`; absent: the solver's. Part of the level, so of its runs'
    /// hash. For a study's reference level, whose must points are the reference the
    /// campaign's level is judged against (coeffs/README.md, "Mesh study").
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub etol: Option<f64>,
    /// FEBio's Newton residual tolerance (`rtol`: relative to the time step's first
    /// residual, on squared norms) for every attempt on this level, the first and the
    /// retries, instead of `[solver.febio] rtol` and `retry_rtol`; absent: the solver's.
    /// Part of the level, so of its runs' hash. For a study's reference level: with the
    /// campaign's 1e-3 (a residual norm cut by only 1/sqrt(1000)) the reference's must
    /// points depended on the time-step sequence (coeffs/README.md, "Mesh study").
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rtol: Option<f64>,
    /// FEBio's Newton residual tolerance for the retries on this level (the ladder's
    /// attempts after the first and their continuations), instead of `[solver.febio]
    /// retry_rtol` (and of this level's `rtol` there); absent: those. The retries judge
    /// convergence without the displacement norm (`retry_dtol` 0), so with the
    /// campaign's 1e-3 a retried must point could be accepted off the equilibrium path by
    /// up to 2.7 % of peak |Fy| (coeffs/default/README.md, "The retries' tolerance"); a
    /// tight one here, with `retry_min_residual_n`, keeps the first attempt's speed and
    /// the retries' points on the path. Part of the level's run hash, not of its
    /// first-attempt hash (the first attempt does not use it).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub retry_rtol: Option<f64>,
    /// The retry ladder's absolute residual floor on this level, N (FEBio's
    /// `min_residual`, squared), instead of `[solver.febio] retry_min_residual_n`;
    /// absent: the solver's. For a reference level solved to a tight `etol`, whose
    /// continuations restart with micrometre time steps: the relative residual criterion
    /// then asks for less than the contact's chatter (coeffs/README.md, "Mesh study").
    /// Part of the level's run hash, not of its first-attempt hash (the first attempt
    /// does not use it).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub retry_min_residual_n: Option<f64>,
    /// `true`: the first attempt on this level converges with the retries' tolerances
    /// too (`retry_dtol`, the level's `retry_rtol` and `retry_min_residual_n`), with whole
    /// load steps; absent or `false`: with `dtol` and `rtol`, as on every other level.
    /// For a level whose first contact chatters in the displacement norm: on core6
    /// train-03's first attempt failed at 0.25 mm with it and passed first contact
    /// without it (coeffs/default/README.md, "The first attempt on core6"). Part of the
    /// level, so of its runs' hash and, with the retry settings then used by the first
    /// attempt, of its first-attempt hash.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub first_attempt_retry_tolerances: Option<bool>,
}

impl MeshLevel {
    /// Whether the first attempt on this level uses the retries' tolerances
    /// (`first_attempt_retry_tolerances`).
    pub fn retry_tolerances_first(&self) -> bool {
        self.first_attempt_retry_tolerances == Some(true)
    }

    /// Check the level `name`; messages start with the spec's `path`.
    ///
    /// # Errors
    /// An odd or too small element count, fewer than 2 facets per quarter, a size, `etol`,
    /// `rtol`, `retry_rtol` or residual floor not finite and > 0, a growth below 1.
    pub fn validate(&self, path: &Path, name: &str) -> SpecResult<()> {
        let p = path.display();
        if self.core_elements < 2 || !self.core_elements.is_multiple_of(2) {
            let field = format!("mesh.{name}.core_elements");
            return Err(SpecError::range(&p, &field, format!("{field} = {}: must be even and >= 2", self.core_elements)));
        }
        if self.needle_facets_per_quarter < 2 {
            let field = format!("mesh.{name}.needle_facets_per_quarter");
            return Err(SpecError::range(&p, &field, format!("{field} = {}: must be >= 2", self.needle_facets_per_quarter)));
        }
        for (f, v) in [
            ("core_half_mm", self.core_half_mm),
            ("fine_size_mm", self.fine_size_mm),
            ("fine_depth_mm", self.fine_depth_mm),
            ("needle_axial_mm", self.needle_axial_mm),
        ] {
            positive(path, &format!("mesh.{name}.{f}"), v)?;
        }
        if let Some(etol) = self.etol {
            positive(path, &format!("mesh.{name}.etol"), etol)?;
        }
        if let Some(rtol) = self.rtol {
            positive(path, &format!("mesh.{name}.rtol"), rtol)?;
        }
        if let Some(rtol) = self.retry_rtol {
            positive(path, &format!("mesh.{name}.retry_rtol"), rtol)?;
        }
        if let Some(floor) = self.retry_min_residual_n {
            positive(path, &format!("mesh.{name}.retry_min_residual_n"), floor)?;
        }
        if !(self.growth.is_finite() && self.growth >= 1.0) {
            let field = format!("mesh.{name}.growth");
            return Err(SpecError::range(&p, &field, format!("{field} = {}: must be >= 1", self.growth)));
        }
        Ok(())
    }
}

#[cfg(test)]
mod mesh_level_tests {
    use crate::spec::shipped_key;
    use crate::spec::{parse, SpecError};
    use std::path::Path;

    /// `key` of the shipped `[mesh.fine]` set to each bad value is refused, naming the
    /// field and its line.
    fn refused_on_the_fine_level(key: &str) {
        refused_on_level("fine", key);
    }

    /// `key` of the shipped `[mesh.<level>]` set to each bad value is refused, naming the
    /// field and its line.
    fn refused_on_level(level: &str, key: &str) {
        let (text, line, shipped) = shipped_key(&format!("mesh.{level}"), key);
        for bad in ["0.0", "-0.001", "nan", "inf"] {
            // only this level's line: another level may ship the same value
            let spec: String = text
                .lines()
                .enumerate()
                .map(|(i, l)| if i + 1 == line && l == shipped { format!("{key} = {bad}\n") } else { format!("{l}\n") })
                .collect();
            assert_ne!(spec.trim_end(), text.trim_end());
            match parse(&spec, Path::new("campaign.toml")) {
                Ok(_) => panic!("{key} = {bad} accepted"),
                Err(e) => {
                    let want = format!("mesh.{level}.{key}");
                    assert!(matches!(&e, SpecError::OutOfRange { field, .. } if *field == want), "{e:?}");
                    assert_eq!(e.at(), format!("campaign.toml:{line}"), "{e}");
                }
            }
        }
    }

    #[test]
    fn a_levels_energy_tolerance_not_above_zero_is_refused_with_file_line_and_field() {
        refused_on_the_fine_level("etol");
    }

    #[test]
    fn a_levels_residual_tolerance_not_above_zero_is_refused_with_file_line_and_field() {
        refused_on_the_fine_level("rtol");
    }

    #[test]
    fn a_levels_retry_residual_tolerance_not_above_zero_is_refused_with_file_line_and_field() {
        refused_on_level("core6", "retry_rtol");
    }

    #[test]
    fn a_levels_residual_floor_not_above_zero_is_refused_with_file_line_and_field() {
        refused_on_the_fine_level("retry_min_residual_n");
    }
}
