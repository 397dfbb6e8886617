//! The poses a campaign generates besides the listed ones: the Latin hypercube of
//! validation poses (`campaign.lhs_*`), the Sobol training design (`campaign.train_*`)
//! and the replacements of its failed poses (`campaign.train_replaced`); and the checks
//! of what `[campaign]` names among the poses.

use super::campaign::TrainReplacement;
use super::error::{SpecError, SpecResult};
use super::pose::{PoseSpec, Role, THETA_MAX_DEG, X_MAX_MM, Z_MAX_MM};
use super::Campaign;
use rand::{seq::SliceRandom, Rng, SeedableRng};
use std::path::Path;

impl Campaign {
    /// Every pose of the campaign: the listed ones, then `lhs_count` Latin hypercube
    /// poses named `lhs-01`, `lhs-02`, ... drawn with ChaCha8 from `lhs_seed`: each of the
    /// four inputs is split into `lhs_count` equal strata over the whole domain, one point
    /// uniform in each stratum, strata shuffled independently per input. Coordinates are
    /// rounded to 0.01 mm / 0.01 degree so that the deck is reproducible from the name.
    pub fn poses(&self) -> Vec<PoseSpec> {
        let mut out = self.pose.clone();
        let n = self.campaign.lhs_count as usize;
        if n == 0 {
            out.extend(self.train_poses());
            return out;
        }
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(self.campaign.lhs_seed);
        let ranges = [X_MAX_MM, Z_MAX_MM, THETA_MAX_DEG, THETA_MAX_DEG];
        let mut cols: Vec<Vec<f64>> = Vec::new();
        for half in ranges {
            let mut col: Vec<f64> = (0..n)
                .map(|i| {
                    let u = (i as f64 + rng.gen::<f64>()) / n as f64;
                    let v = -half + 2.0 * half * u;
                    (v * 100.0).round() / 100.0
                })
                .collect();
            col.shuffle(&mut rng);
            cols.push(col);
        }
        for i in 0..n {
            out.push(PoseSpec {
                name: format!("lhs-{:02}", i + 1),
                role: Role::Lhs,
                x_mm: cols[0][i],
                z_mm: cols[1][i],
                theta_x_deg: cols[2][i],
                theta_z_deg: cols[3][i],
            });
        }
        out.extend(self.train_poses());
        out
    }

    /// The `train_count` training poses `train-01`, `train-02`, ...: point i of the
    /// Owen-scrambled Sobol sequence in four dimensions (seed `train_seed`) mapped onto
    /// the whole domain, |x|, |z| <= 12 mm and |theta| <= 15 degrees, rounded like the
    /// hypercube. Every prefix of 2^k points is stratified in each input and in each pair
    /// of inputs, which is what the learning curve's nested subsets rely on.
    /// Then one more point per entry of `campaign.train_replaced`: the replacements
    /// ([`Campaign::replacement_of`]).
    pub fn train_poses(&self) -> Vec<PoseSpec> {
        let ranges = [X_MAX_MM, Z_MAX_MM, THETA_MAX_DEG, THETA_MAX_DEG];
        let drawn = self.campaign.train_count.saturating_add(u32::try_from(self.campaign.train_replaced.len()).unwrap_or(u32::MAX));
        (0..drawn)
            .map(|i| {
                let v: Vec<f64> = ranges
                    .iter()
                    .zip(0u32..)
                    .map(|(half, dim)| {
                        let u = f64::from(sobol_burley::sample(i, dim, self.campaign.train_seed));
                        (((-half + 2.0 * half * u) * 100.0).round() / 100.0).clamp(-half, *half)
                    })
                    .collect();
                PoseSpec {
                    name: self.train_name(i as usize),
                    role: Role::Train,
                    x_mm: v[0],
                    z_mm: v[1],
                    theta_x_deg: v[2],
                    theta_z_deg: v[3],
                }
            })
            .collect()
    }

    /// Name of point `i` (0-based) of the training sequence: `train-01`, ...
    pub fn train_name(&self, i: usize) -> String {
        format!("train-{:02}", i + 1)
    }

    /// The replacement of training pose `name` listed in `campaign.train_replaced`
    /// (`None`: not replaced).
    pub fn replacement_of(&self, name: &str) -> Option<String> {
        let k = self.campaign.train_replaced.iter().position(|r| r.pose == name)?;
        Some(self.train_name(self.campaign.train_count as usize + k))
    }

    /// The entry of `campaign.train_replaced` that pose `name` replaces (`None`: `name`
    /// is not a replacement).
    pub fn replaced_by(&self, name: &str) -> Option<&TrainReplacement> {
        let n = self.campaign.train_count as usize;
        self.campaign.train_replaced.iter().enumerate().find(|(k, _)| self.train_name(n + k) == name).map(|(_, r)| r)
    }

    /// Whether training pose `name` is replaced (not fitted: its replacement takes its slot).
    pub fn is_replaced(&self, name: &str) -> bool {
        self.campaign.train_replaced.iter().any(|r| r.pose == name)
    }

    /// The training design's `train_count` slots after the replacements: each pose of
    /// the first `train_count` as drawn, or the last replacement in its chain.
    pub fn train_design(&self) -> Vec<String> {
        (0..self.campaign.train_count as usize)
            .map(|i| {
                let mut name = self.train_name(i);
                while let Some(r) = self.replacement_of(&name) {
                    name = r;
                }
                name
            })
            .collect()
    }

    /// `campaign.edge_study_radii_mm`: each > 0 and below the needle's radius, not the
    /// campaign's own edge, listed once; messages start with the spec's `path`.
    fn validate_edge_study(&self, path: &Path) -> SpecResult<()> {
        let p = path.display();
        let field = "campaign.edge_study_radii_mm";
        for (k, r) in self.campaign.edge_study_radii_mm.iter().enumerate() {
            if !self.needle.fits_edge_radius(*r) {
                let max = self.needle.diameter_mm / 2.0;
                return Err(SpecError::range(&p, field, format!("{field}: {r} mm: must be > 0 and below the needle's radius ({max} mm)")));
            }
            if *r == self.needle.tip_edge_radius_mm {
                return Err(SpecError::inconsistent(
                    &p,
                    field,
                    format!("{field}: {r} mm is needle.tip_edge_radius_mm, the campaign's own edge (the mesh study has it)"),
                ));
            }
            if self.campaign.edge_study_radii_mm[..k].contains(r) {
                return Err(SpecError::duplicate(&p, field, format!("{r}"), format!("{field}: {r} mm is listed twice")));
            }
        }
        Ok(())
    }

    /// Check what `[campaign]` names among the poses (`mesh_study_poses`,
    /// `train_replaced`, `fit_without`); messages start with the spec's `path`.
    ///
    /// # Errors
    /// An unknown pose, a replaced pose not drawn before its replacement or listed twice
    /// or without its reason, a pose both replaced and left out, a left-out pose whose
    /// role is always or never fitted.
    pub(super) fn validate_design(&self, path: &Path) -> SpecResult<()> {
        let p = path.display();
        let every_pose = self.poses();
        for (field, names) in
            [("campaign.mesh_study_poses", &self.campaign.mesh_study_poses), ("campaign.edge_study_poses", &self.campaign.edge_study_poses)]
        {
            if let Some(name) = names.iter().find(|name| !every_pose.iter().any(|q| &q.name == *name)) {
                return Err(SpecError::unknown(&p, field, name, format!("{field}: {name:?} is not a pose of this campaign")));
            }
        }
        self.validate_edge_study(path)?;
        let mut replaced = std::collections::BTreeSet::new();
        for (k, r) in self.campaign.train_replaced.iter().enumerate() {
            let replacement = self.train_name(self.campaign.train_count as usize + k);
            // the pose must be a training pose drawn before its replacement
            let drawn_before = (0..self.campaign.train_count as usize + k).any(|i| self.train_name(i) == r.pose);
            if !drawn_before {
                return Err(SpecError::inconsistent(
                    &p,
                    "campaign.train_replaced",
                    format!(
                        "campaign.train_replaced[{k}]: {:?} is not a training pose drawn before its replacement {replacement:?}",
                        r.pose
                    ),
                ));
            }
            if !replaced.insert(r.pose.clone()) {
                return Err(SpecError::duplicate(
                    &p,
                    "campaign.train_replaced",
                    &r.pose,
                    format!("campaign.train_replaced: {:?} is listed twice", r.pose),
                ));
            }
            if r.why.trim().is_empty() {
                return Err(SpecError::range(
                    &p,
                    "campaign.train_replaced.why",
                    format!("campaign.train_replaced[{k}] ({}): `why` is empty (the failure from its logs)", r.pose),
                ));
            }
            if self.campaign.fit_without.contains(&r.pose) {
                return Err(SpecError::duplicate(
                    &p,
                    "campaign.fit_without",
                    &r.pose,
                    format!("campaign.fit_without: {:?} is in campaign.train_replaced, so it is not fitted already; list it once", r.pose),
                ));
            }
        }
        for name in &self.campaign.fit_without {
            match every_pose.iter().find(|q| &q.name == name) {
                None => {
                    return Err(SpecError::unknown(
                        &p,
                        "campaign.fit_without",
                        name,
                        format!("campaign.fit_without: {name:?} is not a pose of this campaign"),
                    ))
                }
                Some(q) if !q.role.may_be_left_out() => {
                    return Err(SpecError::inconsistent(
                        &p,
                        "campaign.fit_without",
                        format!(
                            "campaign.fit_without: pose {name:?} has role {:?}; only sweep and training runs can be left out of the fit",
                            q.role
                        ),
                    ));
                }
                Some(_) => {}
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use crate::spec::{load, parse, Role, SpecError, THETA_MAX_DEG, X_MAX_MM, Z_MAX_MM};
    use std::path::Path;

    /// The training design: a prefix of the scrambled Sobol sequence, inside the
    /// domain, one point per stratum of each input for 8 and 16 points, another seed
    /// another design.
    #[test]
    fn training_poses_are_nested_stratified_sobol_prefixes() {
        let set = needle_stdx::workspace_root().join("coeffs/default");
        let Ok((mut c, _)) = load(&set) else { panic!("cannot load {}", set.display()) };
        c.campaign.train_replaced.clear();
        c.campaign.train_seed = 7;
        c.campaign.train_count = 16;
        let sixteen = c.train_poses();
        c.campaign.train_count = 8;
        let eight = c.train_poses();
        assert_eq!(sixteen.len(), 16);
        assert_eq!(eight[..], sixteen[..8], "raising train_count keeps the earlier poses");
        assert_eq!(sixteen[15].name, "train-16");
        assert!(sixteen.iter().all(|p| p.role == Role::Train));
        for (n, poses) in [(8usize, &eight), (16, &sixteen)] {
            let ranges = [X_MAX_MM, Z_MAX_MM, THETA_MAX_DEG, THETA_MAX_DEG];
            for (dim, half) in ranges.iter().enumerate() {
                let mut hit = vec![0u32; n];
                for p in poses.iter() {
                    let v = [p.x_mm, p.z_mm, p.theta_x_deg, p.theta_z_deg][dim];
                    assert!(v.abs() <= *half, "{}: input {dim} = {v} outside +-{half}", p.name);
                    // stratum of the unrounded point; rounding to 0.01 may move a point
                    // across a boundary by at most 0.005
                    let k = (((v + half) / (2.0 * half)) * n as f64).floor().clamp(0.0, n as f64 - 1.0) as usize;
                    hit[k] += 1;
                }
                let empty = hit.iter().filter(|&&h| h == 0).count();
                assert!(empty <= 1, "{n} points, input {dim}: strata hit {hit:?}");
            }
        }
        c.campaign.train_seed = 8;
        assert_ne!(c.train_poses(), eight, "the seed scrambles the design");
        assert!(c.poses().iter().filter(|p| p.role == Role::Train).count() == 8, "poses() lists the training poses");
    }

    /// Issue 42, item 3: a training pose that fails every attempt is replaced by the next
    /// point of the sequence; a replacement that fails is replaced in turn.
    #[test]
    fn replaced_training_poses_take_the_next_points_of_the_sequence() {
        let set = needle_stdx::workspace_root().join("coeffs/default");
        let text = std::fs::read_to_string(set.join("campaign.toml")).expect("campaign.toml");
        let Ok((mut c, _)) = load(&set) else { panic!("cannot load {}", set.display()) };
        c.campaign.train_replaced.clear();
        c.campaign.train_count = 10;
        let ten = c.train_poses();
        c.campaign.train_count = 8;
        let why = |p: &str| crate::spec::TrainReplacement { pose: p.into(), why: "all attempts failed".into() };
        c.campaign.train_replaced = vec![why("train-03"), why("train-09")];
        let got = c.train_poses();
        assert_eq!(got, ten, "8 drawn + 2 replacements = the first 10 points of the sequence");
        assert_eq!(c.replacement_of("train-03").as_deref(), Some("train-09"));
        assert_eq!(c.replacement_of("train-09").as_deref(), Some("train-10"));
        assert_eq!(c.replacement_of("train-04"), None);
        assert_eq!(c.replaced_by("train-10").map(|r| r.pose.as_str()), Some("train-09"));
        assert_eq!(c.replaced_by("train-03").map(|r| r.pose.as_str()), None);
        assert!(c.is_replaced("train-09") && !c.is_replaced("train-10"));
        let design = c.train_design();
        assert_eq!(design.len(), 8);
        assert_eq!(design[2], "train-10", "slot 3: train-03 -> train-09 -> train-10");
        assert_eq!(design[3], "train-04");
        // the spec's checks, on the text: entries appended after the shipped ones (a TOML
        // array of tables of [campaign] goes after its plain keys, before [deep])
        let shipped = parse(&text, Path::new("campaign.toml")).map(|c| c.campaign.train_replaced.len()).unwrap_or(usize::MAX);
        let at_end = |entries: &[(&str, &str)]| {
            let add: String =
                entries.iter().map(|(p, w)| format!("[[campaign.train_replaced]]\npose = \"{p}\"\nwhy = \"{w}\"\n")).collect();
            let t = text.replacen("\n[deep]\n", &format!("\n{add}\n[deep]\n"), 1);
            assert_ne!(t, text, "the test's edit did not apply");
            parse(&t, Path::new("campaign.toml")).map(|c| c.campaign.train_replaced.len())
        };
        assert_eq!(at_end(&[("train-09", "x")]).ok(), Some(shipped + 1));
        let r = at_end(&[("train-60", "x")]);
        assert!(matches!(&r, Err(SpecError::Inconsistent { field, .. }) if field == "campaign.train_replaced"), "{r:?}");
        let r = at_end(&[("train-09", "x"), ("train-09", "y")]);
        assert!(
            matches!(&r, Err(SpecError::Duplicate { field, name, .. }) if field == "campaign.train_replaced" && name == "train-09"),
            "{r:?}"
        );
        let r = at_end(&[("train-09", " ")]);
        assert!(matches!(&r, Err(SpecError::OutOfRange { field, .. }) if field == "campaign.train_replaced.why"), "{r:?}");
        let both = text.replacen("fit_without = [", "fit_without = [\"train-09\", ", 1).replacen(
            "\n[deep]\n",
            "\n[[campaign.train_replaced]]\npose = \"train-09\"\nwhy = \"x\"\n\n[deep]\n",
            1,
        );
        let r = parse(&both, Path::new("campaign.toml")).map(|c| c.campaign.train_replaced.len());
        assert!(
            matches!(&r, Err(SpecError::Duplicate { field, name, .. }) if field == "campaign.fit_without" && name == "train-09"),
            "{r:?}"
        );
        // a replacement replaced in turn
        let first = format!("train-{}", 33 + shipped);
        assert_eq!(at_end(&[("train-09", "x"), (first.as_str(), "y")]).ok(), Some(shipped + 2));
    }
}
