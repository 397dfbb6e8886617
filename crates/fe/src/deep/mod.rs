//! Deep runs: `[deep]` of campaign.toml, the pre-puncture response beyond the campaign's
//! `loading.depth_mm` (issue 41, item 5). `needle fe run --deep` solves the listed poses
//! to `deep.depth_mm` in `deep.steps` load steps on `deep.mesh` through the campaign's
//! own machinery (resume, retry ladder, continuation from the last must point, manifest)
//! into `<set>/fe/deep/<pose>.csv` and `<set>/fe/deep/manifest.toml`.
//!
//! A deep run is the campaign's spec with `[loading]` replaced by the deep depth and
//! steps (`DeepSettings::apply`, in `needle_set::spec::deep`, as its check `validate_deep`), so its run hash differs from the shallow run's and the
//! two never mix. The mesh level's fine layers must reach past the deep depth: the tip
//! would otherwise cut through layers that grow geometrically below `fine_depth_mm`.

pub use needle_set::set_folder::DEEP_DIR;
pub use needle_set::spec::{key_line, DeepSettings};
