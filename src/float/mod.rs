//! The f32 evaluator, laid out as the fixed-point one (`crate::fixed`): `tables` (the
//! generated f32 tables), `horner` (its arithmetic: Horner in the contract's operation
//! order), `eval` (the wrench), `cross` (the coupled form's cross terms), `eval_stiffness`
//! (the wrench and its rates), `depth_rate` (the wrench and its forces' rate by depth).
//! Its entry points are re-exported at the crate's root (`wrench`, `wrench_and_stiffness`,
//! `wrench_and_depth_rate`); the value types (`Pose`, `Wrench`, `Stiffness`...) live
//! there too.

pub(crate) mod cross;
pub(crate) mod depth_rate;
pub(crate) mod eval;
pub(crate) mod eval_stiffness;
pub(crate) mod horner;
pub(crate) mod tables;
