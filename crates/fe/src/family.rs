//! The material family's runs (issue 64; `[family]` of campaign.toml, checked in
//! `spec::family`): `needle fe run --family` solves
//! - first the reference: the centre of the paper's own tissue (`[tissue]` as it is) to
//!   `family.depth_mm` on `family.mesh`, named `centre_paper`: the denominator of the ratio
//!   law on the members' own mesh and depth (the deep run is on another mesh, not as deep);
//! - the centre pose (quarter model) of each member to `family.depth_mm` in `family.steps`
//!   load steps on `family.mesh` (the deep runs' machinery: resume, retry ladder,
//!   continuation from the last must point), named `centre_a<alpha>`;
//! - each of `family.check_poses` at each of `family.check_alpha` to `loading.depth_mm` on
//!   the campaign's mesh level (half models, as the campaign solves them), named
//!   `<pose>_a<alpha>`: the check of the ratio law that carries the coupled model's pose
//!   dependence over to the family;
//!
//! into `<set>/fe/family/<run>.csv` with one `<set>/fe/family/manifest.toml`.
//!
//! A member is the one-term Ogden tissue with the exponent `alpha` and the initial shear
//! modulus of `[tissue]` (mu = sum mu_i), the same bulk ratio and stretch range: it differs
//! from the paper's material in its strain stiffening only, so the family spans shapes
//! at one initial stiffness. Each member's tissue is in its run hash, so no two members'
//! results mix, and none mixes with the campaign's.

use crate::spec::{family::member_name, Campaign, FamilySettings, PoseSpec, Tissue};

pub use needle_set::set_folder::FAMILY_DIR;

/// One run variant of the family: a campaign run of its own (its tissue, loading, mesh
/// and poses).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum FamilyRun {
    /// The centre pose of the paper's own tissue, solved as deep as the members on their mesh.
    Reference,
    /// The centre pose of the member `alpha`, solved deep.
    Centre {
        /// The member's Ogden exponent.
        alpha: f64,
    },
    /// The check poses at the member `alpha`, solved to `loading.depth_mm`.
    Check {
        /// The member's Ogden exponent.
        alpha: f64,
    },
}

impl FamilyRun {
    /// Every run of `f`, in the order they are solved: the reference, the centres (in
    /// `alpha`'s order), then the checks (none when `check_poses` is empty).
    pub fn all(f: &FamilySettings) -> Vec<FamilyRun> {
        let centres = f.alpha.iter().map(|&alpha| FamilyRun::Centre { alpha });
        let checks = f.check_alpha.iter().filter(|_| !f.check_poses.is_empty()).map(|&alpha| FamilyRun::Check { alpha });
        std::iter::once(FamilyRun::Reference).chain(centres).chain(checks).collect()
    }

    /// The member's exponent; `None` for the reference (the paper's tissue).
    pub fn alpha(self) -> Option<f64> {
        match self {
            FamilyRun::Reference => None,
            FamilyRun::Centre { alpha } | FamilyRun::Check { alpha } => Some(alpha),
        }
    }

    /// What the run solves, for messages: `alpha = 2` or `the paper's tissue`.
    pub fn label(self) -> String {
        self.alpha().map_or_else(|| "the paper's tissue".to_string(), |a| format!("alpha = {a}"))
    }
}

/// The reference run's name (the paper's tissue at the family's depth and mesh).
pub const REFERENCE_RUN: &str = "centre_paper";

/// The member `alpha` of `t`: one Ogden term with mu = sum mu_i of `t`, the rest of `t` kept.
pub fn member_tissue(t: &Tissue, alpha: f64) -> Tissue {
    Tissue { mu_n_per_mm2: vec![t.mu0_n_per_mm2()], alpha: vec![alpha], ..t.clone() }
}

/// The campaign of `run` (`c` with the member's tissue, and for a centre run the family's
/// depth and steps), its renamed poses and its mesh level.
pub fn apply(c: &Campaign, f: &FamilySettings, run: FamilyRun) -> (Campaign, Vec<PoseSpec>, String) {
    let mut out = c.clone();
    if let Some(alpha) = run.alpha() {
        out.tissue = member_tissue(&c.tissue, alpha);
    }
    let every = c.poses();
    let named = |names: &[String]| -> Vec<PoseSpec> {
        names
            .iter()
            .filter_map(|n| every.iter().find(|p| &p.name == n))
            .map(|p| PoseSpec { name: run.alpha().map_or_else(|| REFERENCE_RUN.to_string(), |a| member_name(&p.name, a)), ..p.clone() })
            .collect()
    };
    match run {
        FamilyRun::Reference | FamilyRun::Centre { .. } => {
            out.loading.depth_mm = f.depth_mm;
            out.loading.steps = f.steps;
            out.loading.ramp_hold = None;
            (out, named(&["centre".to_string()]), f.mesh.clone())
        }
        FamilyRun::Check { .. } => {
            let mesh = c.campaign.mesh.clone();
            (out, named(&f.check_poses), mesh)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::Path;

    fn shipped() -> Campaign {
        let text = std::fs::read_to_string(needle_stdx::workspace_root().join("coeffs/default/campaign.toml")).expect("campaign.toml");
        crate::spec::parse(&text, Path::new("campaign.toml")).expect("the shipped spec")
    }

    #[test]
    fn every_member_is_a_stable_one_term_ogden_tissue_at_the_initial_shear_modulus() {
        let c = shipped();
        let f = c.family.clone().expect("coeffs/default has a [family] section");
        for &alpha in &f.alpha {
            let t = member_tissue(&c.tissue, alpha);
            assert_eq!(t.alpha, vec![alpha]);
            assert!((t.mu0_n_per_mm2() - c.tissue.mu0_n_per_mm2()).abs() <= 1e-15, "alpha {alpha}");
            crate::material::check(&t).unwrap_or_else(|e| panic!("member alpha = {alpha}: {e:#}"));
        }
    }

    #[test]
    fn runs_have_their_own_hashes_names_depths_and_meshes() {
        let c = shipped();
        let f = c.family.clone().expect("[family]");
        let runs = FamilyRun::all(&f);
        assert_eq!(runs.len(), 1 + f.alpha.len() + f.check_alpha.len());
        let mut hashes = std::collections::BTreeSet::new();
        for run in runs {
            let (campaign, poses, mesh) = apply(&c, &f, run);
            assert!(!poses.is_empty(), "{run:?}");
            for p in &poses {
                match run.alpha() {
                    Some(a) => assert!(p.name.ends_with(&format!("_a{}", format!("{a}").replace('.', "p"))), "{}", p.name),
                    None => assert_eq!(p.name, REFERENCE_RUN),
                }
                assert!(hashes.insert(campaign.run_hash(p, &mesh)), "{} repeats a hash", p.name);
            }
            match run {
                FamilyRun::Reference | FamilyRun::Centre { .. } => {
                    assert_eq!((campaign.loading.depth_mm, mesh.as_str()), (f.depth_mm, f.mesh.as_str()))
                }
                FamilyRun::Check { .. } => {
                    assert_eq!((campaign.loading.depth_mm, mesh.as_str()), (c.loading.depth_mm, c.campaign.mesh.as_str()));
                    assert_eq!(poses.len(), f.check_poses.len());
                }
            }
        }
        let centre = c.poses().into_iter().find(|p| p.name == "centre").expect("centre");
        assert!(!hashes.contains(&c.run_hash(&centre, &c.campaign.mesh)), "a member never passes for the campaign's run");
        if let Some(d) = &c.deep {
            assert!(!hashes.contains(&c.run_hash(&centre, &d.mesh)), "the reference never passes for the deep run");
        }
    }
}
