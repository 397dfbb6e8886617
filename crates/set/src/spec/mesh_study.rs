//! The levels of the mesh study (`needle fe verify --mesh`, `--edge`): the ladder of
//! `campaign.mesh_study` (coarse to fine, each a 2x refinement of the one before: the
//! absolute change and Richardson's estimate), and the pair the shape goal is judged on,
//! the committed level and its reference. On the ladder, the committed level's reference
//! is the level after it; a committed level off the ladder (a level refined where the
//! campaign needed it, not everywhere: issue 42's `core6`) names its reference in
//! `campaign.mesh_reference`, a level of the ladder that refines it everywhere.

use super::error::{SpecError, SpecResult};
use super::mesh::MeshLevel;
use super::Campaign;
use std::path::Path;

impl MeshLevel {
    /// Whether `self` refines `coarser` everywhere: the core's elements, the first ring and
    /// the needle's layers no larger, the growth no faster, as many needle facets or
    /// more, over the same core and fine depth; and one of them strictly finer.
    pub fn refines(&self, coarser: &MeshLevel) -> bool {
        let core = |m: &MeshLevel| m.core_half_mm / f64::from(m.core_elements);
        let no_coarser = core(self) <= core(coarser)
            && self.fine_size_mm <= coarser.fine_size_mm
            && self.growth <= coarser.growth
            && self.needle_axial_mm <= coarser.needle_axial_mm
            && self.needle_facets_per_quarter >= coarser.needle_facets_per_quarter;
        let same_extent = self.core_half_mm == coarser.core_half_mm && self.fine_depth_mm == coarser.fine_depth_mm;
        let finer = core(self) < core(coarser)
            || self.fine_size_mm < coarser.fine_size_mm
            || self.growth < coarser.growth
            || self.needle_axial_mm < coarser.needle_axial_mm
            || self.needle_facets_per_quarter > coarser.needle_facets_per_quarter;
        no_coarser && same_extent && finer
    }
}

impl Campaign {
    /// The ladder of the mesh study (`campaign.mesh_study`, or the committed level and
    /// `fine` when it is empty).
    pub fn mesh_study(&self) -> Vec<String> {
        if self.campaign.mesh_study.is_empty() {
            vec![self.campaign.mesh.clone(), "fine".to_string()]
        } else {
            self.campaign.mesh_study.clone()
        }
    }

    /// The pair the mesh study judges: the committed level and its reference (the level
    /// after it on the ladder, or `campaign.mesh_reference` when it is off the ladder).
    ///
    /// # Errors
    /// The committed level is the ladder's last, or off the ladder without a reference.
    pub fn mesh_study_pair(&self) -> Result<(String, String), String> {
        let ladder = self.mesh_study();
        let committed = self.campaign.mesh.clone();
        if let Some(reference) = &self.campaign.mesh_reference {
            return Ok((committed, reference.clone()));
        }
        let Some(k) = ladder.iter().position(|l| *l == committed) else {
            return Err(format!(
                "campaign.mesh_study {ladder:?} does not hold the committed level {committed:?}: name the level it is judged against in campaign.mesh_reference"
            ));
        };
        match ladder.get(k + 1) {
            Some(refined) => Ok((committed, refined.clone())),
            None => Err(format!("campaign.mesh_study {ladder:?}: the committed level {committed:?} needs its 2x refinement after it")),
        }
    }

    /// The pair of the edge study, which runs on the ladder only: the ladder's level
    /// before the mesh study's reference, and that reference (the mesh study's pair when
    /// the committed level is on the ladder).
    ///
    /// # Errors
    /// As [`Campaign::mesh_study_pair`], or the reference is the ladder's first level.
    pub fn edge_study_pair(&self) -> Result<(String, String), String> {
        let (_, reference) = self.mesh_study_pair()?;
        let ladder = self.mesh_study();
        match ladder.iter().position(|l| *l == reference).and_then(|k| k.checked_sub(1)).and_then(|k| ladder.get(k)) {
            Some(level) => Ok((level.clone(), reference)),
            None => Err(format!("campaign.mesh_study {ladder:?}: no level before the reference {reference:?} for the edge study")),
        }
    }

    /// `campaign.mesh_reference`: a level of the ladder, not its first, for a committed
    /// level off the ladder, which it refines everywhere.
    pub(super) fn validate_mesh_reference(&self, path: &Path) -> SpecResult<()> {
        let Some(reference) = &self.campaign.mesh_reference else { return Ok(()) };
        let (p, field) = (path.display(), "campaign.mesh_reference");
        let ladder = self.mesh_study();
        let committed = &self.campaign.mesh;
        let Some(level) = self.mesh.get(reference) else {
            return Err(SpecError::unknown(&p, field, reference, format!("{field} = {reference:?}: no [mesh.{reference}] level")));
        };
        let refuse = |why: String| Err(SpecError::inconsistent(&p, field, format!("{field} = {reference:?}: {why}")));
        if ladder.contains(committed) {
            return refuse(format!(
                "the committed level {committed:?} is on campaign.mesh_study {ladder:?}, which judges it against the level after it; \
                 a reference is for a committed level off the ladder"
            ));
        }
        match ladder.iter().position(|l| l == reference) {
            None => return refuse(format!("not on campaign.mesh_study {ladder:?}")),
            Some(0) => {
                return refuse(format!("the first level of campaign.mesh_study {ladder:?}: the edge study needs the level before it"))
            }
            Some(_) => {}
        }
        match self.mesh.get(committed) {
            Some(m) if level.refines(m) => Ok(()),
            _ => refuse(format!(
                "does not refine the committed level {committed:?} everywhere (core elements, first ring, growth, needle facets and layers)"
            )),
        }
    }
}

#[cfg(test)]
mod tests {
    use crate::spec::{parse, SpecError};
    use std::path::Path;

    fn shipped() -> String {
        let set = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../coeffs/default/campaign.toml");
        std::fs::read_to_string(set).expect("the shipped spec")
    }

    /// The shipped spec with `campaign.mesh` and `campaign.mesh_reference` set.
    fn with(mesh: &str, reference: Option<&str>) -> String {
        let text = shipped();
        let mut new = format!("\nmesh = \"{mesh}\"\n");
        if let Some(r) = reference {
            new.push_str(&format!("mesh_reference = \"{r}\"\n"));
        }
        // campaign.mesh: the first `mesh = ` line after `[campaign]`
        let (head, tail) = text.split_once("\n[campaign]\n").expect("[campaign]");
        let (before, after) = tail.split_once("\nmesh = ").expect("campaign.mesh");
        let after = after.split_once('\n').expect("its line").1;
        format!("{head}\n[campaign]\n{before}{new}{after}")
    }

    #[test]
    fn a_committed_level_off_the_ladder_is_judged_against_its_reference_and_the_edge_study_stays_on_the_ladder() {
        let c = parse(&with("core6", Some("fine")), Path::new("campaign.toml")).expect("core6 judged against fine");
        assert_eq!(c.mesh_study_pair(), Ok(("core6".to_string(), "fine".to_string())));
        assert_eq!(c.edge_study_pair(), Ok(("needle8".to_string(), "fine".to_string())));
        let c = parse(&with("core6", None), Path::new("campaign.toml")).expect("loads; the study refuses");
        assert!(c.mesh_study_pair().unwrap_err().contains("campaign.mesh_reference"));
        let c = parse(&with("needle8", None), Path::new("campaign.toml")).expect("on the ladder");
        assert_eq!(c.mesh_study_pair(), Ok(("needle8".to_string(), "fine".to_string())));
        assert_eq!(c.edge_study_pair(), c.mesh_study_pair());
    }

    #[test]
    fn a_reference_that_is_not_a_refinement_off_the_ladder_is_refused_with_file_line_and_field() {
        for (mesh, reference, why) in [
            ("needle8", "fine", "is on campaign.mesh_study"),
            ("core6", "needle8", "does not refine"),
            ("core6", "coarse8", "the first level"),
            ("core6", "core8", "not on campaign.mesh_study"),
            ("core6", "nope", "no [mesh.nope] level"),
        ] {
            let text = with(mesh, Some(reference));
            match parse(&text, Path::new("campaign.toml")) {
                Ok(_) => panic!("{mesh} against {reference} accepted"),
                Err(e) => {
                    assert!(
                        matches!(&e, SpecError::Inconsistent { field, .. } | SpecError::Unknown { field, .. } if field == "campaign.mesh_reference"),
                        "{e:?}"
                    );
                    assert!(e.to_string().contains(why), "{mesh} against {reference}: {e}");
                    let line = text.lines().position(|l| l.starts_with("mesh_reference")).expect("the line") + 1;
                    assert_eq!(e.at(), format!("campaign.toml:{line}"), "{e}");
                }
            }
        }
    }

    #[test]
    fn a_level_refines_another_only_when_no_size_is_coarser() {
        let c = parse(&shipped(), Path::new("campaign.toml")).expect("the shipped spec");
        let level = |n: &str| c.mesh_level(n).expect(n).clone();
        assert!(level("fine").refines(&level("needle8")));
        assert!(level("fine").refines(&level("core6")), "core 0.075 <= 0.1 mm, first ring 0.15 <= 0.3 mm, growth 1.2 <= 1.4");
        assert!(level("core6").refines(&level("needle8")));
        assert!(!level("needle8").refines(&level("core6")));
        assert!(!level("needle8").refines(&level("needle8")), "not strictly finer");
        let mut wider = level("fine");
        wider.core_half_mm *= 2.0;
        wider.core_elements *= 2;
        assert!(!wider.refines(&level("needle8")), "another core: not the same mesh refined");
    }
}
