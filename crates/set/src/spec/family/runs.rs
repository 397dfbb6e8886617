//! The specs of the material family's runs (issue 64; `[family]`, checked in the parent
//! module): which runs there are ([`FamilyRun::all`]), each member's tissue
//! ([`member_tissue`]) and the campaign of a run ([`apply`]), so that the engine
//! (`needle_fe::family`) solves them and the fitter reads them against their hashes
//! without the engine. The runs, in the order `needle fe run --family` solves them:
//! - first the reference: the centre of the paper's own tissue (`[tissue]` as it is) to
//!   `family.depth_mm` on `family.mesh`, named `centre_paper`: the denominator of the ratio
//!   law on the members' own mesh and depth (the deep run is on another mesh, not as deep);
//! - the centre pose (quarter model) of each member to `family.depth_mm` in `family.steps`
//!   load steps on `family.mesh` (the deep runs' machinery: resume, retry ladder,
//!   continuation from the last must point), named `centre_w<weight>`;
//! - each of `family.check_poses` at each of `family.check_weight` to `loading.depth_mm` on
//!   the campaign's mesh level (half models, as the campaign solves them), named
//!   `<pose>_w<weight>`: the check of the ratio law that carries the coupled model's pose
//!   dependence over to the family;
//! - with `[family.fitted]`, the centre of a calibrated layer's material (its member, every
//!   modulus times its stiffness scale, both read from the stack file: [`FamilyRun::fitted`])
//!   to `family.fitted.depth_mm` on `family.mesh`, named `fitted_<stack>_l<layer>`;
//!
//! into `<set>/fe/family/<run>.csv` with one `<set>/fe/family/manifest.toml`.
//!
//! A member is a blend of the paper's material and a soft one: the Ogden terms of
//! `[tissue]` with their mu_i scaled by `weight`, plus one term of exponent
//! `family.soft_alpha` (2: neo-Hookean) with mu = (1 - weight) mu0, so that every member has
//! the initial shear modulus mu0 = sum mu_i of `[tissue]`, its bulk ratio and stretch
//! range: the members differ in their strain stiffening only, from the paper's (weight 1,
//! the reference) down to the soft term's (weight 0), so the family spans shapes at one
//! initial stiffness. (One-term Ogden members of alpha 0.5 to 4 were tried first: they
//! inverted elements under the wedge at about 2 mm on the family's mesh; the paper's
//! stiffening terms, even at a small weight, keep the elements under the tip sane.) Each member's tissue is in its run hash, so no two members'
//! results mix, and none mixes with the campaign's.

use super::{member_name, FamilySettings};
use crate::spec::{Campaign, PoseSpec, Tissue};
use std::path::Path;

/// One run variant of the family: a campaign run of its own (its tissue, loading, mesh
/// and poses).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum FamilyRun {
    /// The centre pose of the paper's own tissue, solved as deep as the members on their mesh.
    Reference,
    /// The centre pose of the member `weight`, solved deep.
    Centre {
        /// The member's weight of the paper's terms.
        weight: f64,
    },
    /// The check poses at the member `weight`, solved to `loading.depth_mm`.
    Check {
        /// The member's weight of the paper's terms.
        weight: f64,
    },
    /// The centre of `[family.fitted]`'s calibrated layer: the member `weight` with every
    /// modulus times `scale` (both from the stack file).
    Fitted {
        /// The layer's `family_weight`.
        weight: f64,
        /// The layer's `stiffness_scale` (> 0).
        scale: f64,
    },
}

impl FamilyRun {
    /// Every run of `f`, in the order they are solved: the reference, the centres (in
    /// `weight`'s order), then the checks (none when `check_poses` is empty).
    pub fn all(f: &FamilySettings) -> Vec<FamilyRun> {
        let centres = f.weight.iter().map(|&weight| FamilyRun::Centre { weight });
        let checks = f.check_weight.iter().filter(|_| !f.check_poses.is_empty()).map(|&weight| FamilyRun::Check { weight });
        std::iter::once(FamilyRun::Reference).chain(centres).chain(checks).collect()
    }

    /// The run of `[family.fitted]` of `f` (none without it), its member and scale read from
    /// the stack file in `set_dir` (checked as `needle calibrate` writes it, `file:line`).
    ///
    /// # Errors
    /// The stack cannot be read or is refused, it has no layer `family.fitted.layer`, or
    /// that layer's scale is not > 0 or its weight not in `0 ..= 1`.
    pub fn fitted(f: &FamilySettings, set_dir: &Path) -> anyhow::Result<Option<FamilyRun>> {
        let Some(m) = &f.fitted else { return Ok(None) };
        let path = set_dir.join(&m.stack);
        let stack = needle_codegen::tissue::parse_stack(&path).map_err(|e| anyhow::anyhow!("family.fitted.stack: {e}"))?;
        let Some(layer) = stack.layers.get(m.layer) else {
            anyhow::bail!("{}: family.fitted.layer = {}: the stack has {} layer(s)", path.display(), m.layer, stack.layers.len());
        };
        let (weight, scale) = (layer.family_weight, layer.stiffness_scale);
        if !(scale.is_finite() && scale > 0.0 && (0.0..=1.0).contains(&weight)) {
            anyhow::bail!(
                "{}: layer {}: stiffness_scale = {scale} and family_weight = {weight}: not a member to solve",
                path.display(),
                m.layer
            );
        }
        Ok(Some(FamilyRun::Fitted { weight, scale }))
    }

    /// The member's weight of the paper's terms; `None` for the reference (the paper's
    /// tissue itself, weight 1).
    pub fn weight(self) -> Option<f64> {
        match self {
            FamilyRun::Reference => None,
            FamilyRun::Centre { weight } | FamilyRun::Check { weight } | FamilyRun::Fitted { weight, .. } => Some(weight),
        }
    }

    /// What the run solves, for messages: `weight = 0.05`, `the paper's tissue` or the
    /// fitted layer's `weight = 0.01, moduli x 30.3`.
    pub fn label(self) -> String {
        match self {
            FamilyRun::Fitted { weight, scale } => format!("the fitted layer: weight = {weight}, moduli x {scale}"),
            _ => self.weight().map_or_else(|| "the paper's tissue".to_string(), |w| format!("weight = {w}")),
        }
    }
}

/// The reference run's name (the paper's tissue at the family's depth and mesh).
pub const REFERENCE_RUN: &str = "centre_paper";

/// The member `weight` of `t`: `t`'s Ogden terms with mu_i x `weight`, then one term of
/// exponent `soft_alpha` with mu = (1 - `weight`) x mu0 of `t`; the initial shear modulus,
/// bulk ratio and stretch range of `t` kept.
pub fn member_tissue(t: &Tissue, weight: f64, soft_alpha: f64) -> Tissue {
    let mut mu: Vec<f64> = t.mu_n_per_mm2.iter().map(|m| m * weight).collect();
    let mut alpha = t.alpha.clone();
    mu.push((1.0 - weight) * t.mu0_n_per_mm2());
    alpha.push(soft_alpha);
    Tissue { mu_n_per_mm2: mu, alpha, ..t.clone() }
}

/// The campaign of `run` (`c` with the member's tissue, and for a centre run the family's
/// depth and steps), its renamed poses and its mesh level.
pub fn apply(c: &Campaign, f: &FamilySettings, run: FamilyRun) -> (Campaign, Vec<PoseSpec>, String) {
    let mut out = c.clone();
    if let Some(weight) = run.weight() {
        out.tissue = member_tissue(&c.tissue, weight, f.soft_alpha);
    }
    let every = c.poses();
    let named = |names: &[String]| -> Vec<PoseSpec> {
        names
            .iter()
            .filter_map(|n| every.iter().find(|p| &p.name == n))
            .map(|p| PoseSpec { name: run.weight().map_or_else(|| REFERENCE_RUN.to_string(), |w| member_name(&p.name, w)), ..p.clone() })
            .collect()
    };
    match run {
        FamilyRun::Fitted { scale, .. } => {
            out.tissue.scale_moduli(scale);
            out.loading.ramp_hold = None;
            let Some(m) = &f.fitted else { return (out, Vec::new(), f.mesh.clone()) };
            out.loading.depth_mm = m.depth_mm;
            out.loading.steps = m.steps;
            let poses = named(&["centre".to_string()]).into_iter().map(|p| PoseSpec { name: m.run_name(), ..p }).collect();
            (out, poses, f.mesh.clone())
        }
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
    fn every_member_is_a_stable_blend_at_the_initial_shear_modulus() {
        let c = shipped();
        let f = c.family.clone().expect("coeffs/default has a [family] section");
        let n = c.tissue.alpha.len();
        for &weight in &f.weight {
            let t = member_tissue(&c.tissue, weight, f.soft_alpha);
            assert_eq!(t.alpha.len(), n + 1);
            assert_eq!(t.alpha.last(), Some(&f.soft_alpha));
            assert_eq!(&t.alpha[..n], &c.tissue.alpha[..]);
            assert!((t.mu0_n_per_mm2() - c.tissue.mu0_n_per_mm2()).abs() <= 1e-15, "weight {weight}");
        }
        let paper = member_tissue(&c.tissue, 1.0, f.soft_alpha);
        assert_eq!(&paper.mu_n_per_mm2[..n], &c.tissue.mu_n_per_mm2[..], "weight 1 keeps the paper's terms");
        assert_eq!(paper.mu_n_per_mm2[n], 0.0, "weight 1 has no soft term");
    }

    #[test]
    fn runs_have_their_own_hashes_names_depths_and_meshes() {
        let c = shipped();
        let f = c.family.clone().expect("[family]");
        let runs = FamilyRun::all(&f);
        assert_eq!(runs.len(), 1 + f.weight.len() + f.check_weight.len());
        let set_dir = needle_stdx::workspace_root().join("coeffs/default");
        let fitted = FamilyRun::fitted(&f, &set_dir).expect("the shipped [family.fitted] stack");
        assert_eq!(fitted.is_some(), f.fitted.is_some());
        let mut hashes = std::collections::BTreeSet::new();
        for run in runs.into_iter().chain(fitted) {
            let (campaign, poses, mesh) = apply(&c, &f, run);
            assert!(!poses.is_empty(), "{run:?}");
            for p in &poses {
                match (run, run.weight(), &f.fitted) {
                    (FamilyRun::Fitted { .. }, _, Some(m)) => assert_eq!(p.name, m.run_name()),
                    (_, Some(w), _) => assert!(p.name.ends_with(&format!("_w{}", format!("{w}").replace('.', "p"))), "{}", p.name),
                    _ => assert_eq!(p.name, REFERENCE_RUN),
                }
                assert!(hashes.insert(campaign.run_hash(p, &mesh)), "{} repeats a hash", p.name);
            }
            match run {
                FamilyRun::Fitted { weight, scale } => {
                    let member = member_tissue(&c.tissue, weight, f.soft_alpha);
                    let ratio = campaign.tissue.mu0_n_per_mm2() / member.mu0_n_per_mm2();
                    assert!((ratio / scale - 1.0).abs() < 1e-12, "every modulus times the stack's scale: {ratio} vs {scale}");
                    let m = f.fitted.as_ref().expect("a fitted run comes from [family.fitted]");
                    assert_eq!((campaign.loading.depth_mm, campaign.loading.steps, mesh.as_str()), (m.depth_mm, m.steps, f.mesh.as_str()));
                }
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
