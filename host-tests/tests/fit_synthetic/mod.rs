//! A synthetic set for the fitter's tests: the shipped campaign spec, and for every pose an
//! analytic "FE" wrench with the block's mirror symmetries (odd components exactly zero
//! where a symmetry forces them to be), written as `fe/<pose>.csv`.

#![allow(dead_code)]

use needle_fit::{fit_set, FitOutput};
use needle_set::manifest::{manifest_text, Manifest, ManifestEntry, MANIFEST};
use needle_set::results::{content_sha256, to_csv, Row};
use needle_set::spec::{self, PoseSpec};
use std::path::{Path, PathBuf};

/// Lever arm used to scale moments in the tolerances, mm (the default set's hub).
pub const LEVER_MM: f64 = 60.0;

/// The analytic wrench at a pose and depth: forces in N, moments in N*mm. Mirror x -> -x
/// ((x, tz) -> (-x, -tz)) flips fx, my, mz; mirror z -> -z ((z, tx) -> (-z, -tx)) flips
/// fz, mx, my; the x-tz and z-tx couplings make combined poses differ from superposition.
pub fn wrench(p: &PoseSpec, d: f64) -> [f64; 6] {
    let (x, z, tx, tz) = (p.x_mm, p.z_mm, p.theta_x_deg, p.theta_z_deg);
    let depth_law = 0.01 * d.powf(1.5) + 0.002 * d * d;
    let fy = -depth_law * (1.0 + 0.003 * x * x + 0.002 * z * z + 0.001 * tx * tx + 0.0015 * tz * tz + 0.0001 * x * tz);
    let lateral = 0.004 * d.powf(1.2);
    let fx = lateral * (8.0 * (x / 8.0).sin() + 0.5 * tz + 0.002 * tz * tz * tz) * (1.0 + 0.01 * z * z);
    let fz = lateral * (9.0 * (z / 9.0).sin() + 0.6 * tx + 0.001 * tx * tx * tx) * (1.0 + 0.01 * x * x);
    let mx = 0.8 * LEVER_MM * fz + 0.01 * d * (tx / 5.0).sinh();
    let my = 0.0005 * d * (x + tz) * (z + tx);
    let mz = -0.8 * LEVER_MM * fx + 0.01 * d * tz;
    [fx, fy, fz, mx, my, mz]
}

/// Create a synthetic set in `dir` (campaign.toml copied from coeffs/default in the paper
/// form, whatever form the default set ships: the tests that need the coupled form switch
/// it on; one CSV per pose, and a manifest entry per CSV with the spec hash of the current
/// spec, so that the runs count as current). `skip` names poses whose CSV is not written.
pub fn make_set(dir: &Path, skip: &[&str]) {
    let src = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../coeffs/default/campaign.toml");
    std::fs::create_dir_all(dir.join("fe")).expect("create set folder");
    let text = std::fs::read_to_string(&src).expect("read campaign.toml");
    let paper: Vec<&str> = text.lines().filter(|l| l.trim() != "form = \"coupled\"").collect();
    std::fs::write(dir.join("campaign.toml"), paper.join("\n") + "\n").expect("write campaign.toml");
    let (campaign, _) = spec::load(dir).expect("load spec");
    let mut manifest = Manifest::default();
    for pose in campaign.poses() {
        if skip.contains(&pose.name.as_str()) {
            continue;
        }
        let rows: Vec<Row> = (0..=campaign.loading.steps)
            .map(|k| {
                let d = campaign.loading.depth_at(k);
                Row { depth_mm: d, wrench: wrench(&pose, d) }
            })
            .collect();
        let text = to_csv(&rows);
        std::fs::write(dir.join("fe").join(format!("{}.csv", pose.name)), &text).expect("write csv");
        let mut entry = synthetic_entry(&campaign, &pose);
        entry.csv_sha256 = Some(content_sha256(text.as_bytes()));
        manifest.pose.insert(pose.name.clone(), entry);
    }
    let text = manifest_text(&manifest).expect("manifest text");
    std::fs::write(dir.join("fe").join(MANIFEST), text).expect("write manifest");
}

/// A manifest entry for a synthetic run: the current spec hash, no solver.
fn synthetic_entry(campaign: &spec::Campaign, pose: &PoseSpec) -> ManifestEntry {
    ManifestEntry {
        spec_hash: campaign.run_hash(pose, &campaign.campaign.mesh),
        first_attempt_hash: None,
        engine: "none".into(),
        engine_version: "none (synthetic wrench)".into(),
        element: String::new(),
        solver_settings: String::new(),
        mesh: campaign.campaign.mesh.clone(),
        csv_sha256: None,
        model: "synthetic".into(),
        tissue_mesh: "none".into(),
        tissue_nodes: 0,
        tissue_elements: 0,
        needle_nodes: 0,
        needle_elements: 0,
        steps: campaign.loading.steps,
        depth_mm: campaign.loading.depth_mm,
        increments: 0,
        iterations: 0,
        wall_s: 0.0,
        peak_rss_mib: None,
        date: "1970-01-01T00:00:00Z".into(),
        role: pose.role,
        x_mm: pose.x_mm,
        z_mm: pose.z_mm,
        theta_x_deg: pose.theta_x_deg,
        theta_z_deg: pose.theta_z_deg,
        first_increment: None,
        retry: None,
        launcher: None,
        batch_job: None,
        replaces: None,
        replaced_because: None,
        viscoelastic: None,
    }
}

/// A fitted synthetic set: the temporary folder (kept alive) and the fit output.
pub fn fitted() -> (tempfile::TempDir, FitOutput) {
    let dir = tempfile::tempdir().expect("tempdir");
    make_set(dir.path(), &[]);
    let out = needle_set::set_folder::SetFolder::open(dir.path())
        .and_then(|s| fit_set(&s))
        .unwrap_or_else(|e| panic!("fit of the synthetic set: {e:#}"));
    (dir, out)
}

/// Replace `fe/<pose>.csv` with `rows` and record its new hash in the manifest, as a
/// rerun of the pose would (a changed FE result, not a hand edit).
pub fn rewrite_run(dir: &Path, pose: &str, rows: &[Row]) {
    let text = to_csv(rows);
    std::fs::write(dir.join("fe").join(format!("{pose}.csv")), &text).expect("write csv");
    let path = dir.join("fe").join(MANIFEST);
    let mut m = needle_set::manifest::read_manifest(&path).expect("manifest");
    m.pose.get_mut(pose).expect("entry").csv_sha256 = Some(content_sha256(text.as_bytes()));
    std::fs::write(&path, manifest_text(&m).expect("manifest text")).expect("write manifest");
}
