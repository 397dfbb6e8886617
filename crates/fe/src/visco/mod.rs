//! Viscoelastic ramp-and-hold runs (issue 39, item 3): the set's FE tissue (the uncoupled
//! Ogden of `[tissue]`) wrapped in FEBio's `uncoupled viscoelastic` material with the
//! Prony series of `[viscoelastic]`, fed at each of `speeds_mm_per_s` to
//! `loading.depth_mm` in `loading.steps` must points (at the elastic runs' depths), then
//! held for `hold_s`. `needle fe run --visco` solves them through the campaign's own
//! machinery (resume, retry ladder, atomic CSV and manifest) into
//! `<set>/fe/visco/<pose>_<speed>mm-s.csv` (with a `time_s` column) and
//! `<set>/fe/visco/manifest.toml`.
//!
//! A run's spec is the campaign's with the Prony series in `tissue.prony` and the time
//! course in `loading.ramp_hold` ([`apply`]), so its hash never equals an elastic run's.
//! FEBio's time is then seconds; the must points are [`RampHold::time_s`].
//! `needle fe verify --qlv` compares these runs with the library's filter (`qlv`, their
//! check). The run specs are the set's (`needle_set::spec::visco`, re-exported here).

pub mod qlv;

pub use needle_set::results::TIME_COLUMN;
pub use needle_set::set_folder::VISCO_DIR;
pub use needle_set::spec::visco::{
    apply, apply_frictionless_elastic, describe, frictionless_name, run_name, Friction, Prony, RampHold, ViscoSettings,
    FRICTIONLESS_SUFFIX, MAX_PRONY_TERMS,
};
