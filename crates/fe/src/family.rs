//! The material family's runs (issue 64; `[family]` of campaign.toml): their specs (the
//! runs, each member's tissue, a run's campaign) are the set's
//! (`needle_set::spec::family::runs`, re-exported here); `needle fe run --family` solves
//! them through the campaign runner (`crate::campaign::plan` applies a run), each member
//! material-checked first, into `<set>/fe/family/<run>.csv` with one
//! `<set>/fe/family/manifest.toml`.

pub use needle_set::set_folder::FAMILY_DIR;
pub use needle_set::spec::family::runs::{apply, member_tissue, FamilyRun, REFERENCE_RUN};

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::Path;

    /// Every member of the shipped family passes the Drucker stability check (the engine's
    /// `material::check`), as `needle fe run --family` requires before it solves.
    #[test]
    fn every_shipped_member_is_drucker_stable() {
        let text = std::fs::read_to_string(needle_stdx::workspace_root().join("coeffs/default/campaign.toml")).expect("campaign.toml");
        let c = crate::spec::parse(&text, Path::new("campaign.toml")).expect("the shipped spec");
        let f = c.family.clone().expect("coeffs/default has a [family] section");
        for &weight in &f.weight {
            let t = member_tissue(&c.tissue, weight, f.soft_alpha);
            crate::material::check(&t).unwrap_or_else(|e| panic!("member weight = {weight}: {e:#}"));
        }
    }
}
