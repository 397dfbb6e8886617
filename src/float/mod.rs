//! The f32 evaluator: the model in `f32`, bit for bit the contract's operation order
//! (`coeffs/README.md`), for cores with an FPU and for the host. Its modules mirror the
//! fixed-point evaluator's ([`crate::fixed`]) name for name: `pose`, `wrench`,
//! `stiffness`, `depth_extension`, `family`, `insertion` (`stack`, `track`), `viscoelastic`
//! (`identity`), and the evaluator's internals `tables` (the generated f32 tables),
//! `eval` (the wrench), `cross` (the coupled form's cross terms), `eval_stiffness` (the
//! wrench and its rates).
//!
//! Modules of this precision alone (`host-tests/tests/precision_mirrors.rs` reads these
//! lines):
//!
//! - precision-only: `horner` because f32 Horner in the contract's operation order (skipping
//!   the exact `+0.0` steps) is float arithmetic; the fixed evaluator's is `fixed::arith`.
//! - precision-only: `depth_rate` because the forces' rate by depth feeds the passivity
//!   guard of the control loop (`crate::control`), which runs the f32 insertion only.
//! - precision-only: `insertion::presliding` because the shaft's presliding (the
//!   `shaft-presliding` feature) is f32 only: the fixed-point insertion refuses a presliding
//!   layer (`InsertionError::FloatOnly`).
//!
//! The whole API is also at the crate's root (`needle_haptics::wrench`,
//! `needle_haptics::Pose`, `needle_haptics::insertion`...), re-exported from here.
//!
//! ```
//! use needle_haptics::float::{self, Pose};
//!
//! let pose = Pose { x_mm: 3.0, z_mm: -2.0, theta_x_deg: 5.0, theta_z_deg: 0.0, depth_mm: 4.5 };
//! let eval = float::wrench(&pose);
//! assert_eq!(eval, needle_haptics::wrench(&pose));
//! ```

pub(crate) mod cross;
pub mod depth_extension;
pub(crate) mod depth_rate;
pub(crate) mod eval;
pub(crate) mod eval_stiffness;
pub mod family;
pub(crate) mod horner;
// The module doc's link [`extended_wrench`](crate::extended_wrench) (insertion/mod.rs,
// line 12) names its target twice: left to the insertion work, whose folder is being
// changed; remove this allow with that fix ([`crate::extended_wrench`]).
#[allow(rustdoc::redundant_explicit_links)]
pub mod insertion;
mod pose;
mod stiffness;
pub(crate) mod tables;
pub mod viscoelastic;
mod wrench;

pub use depth_extension::extended_wrench;
pub use depth_rate::wrench_and_depth_rate;
pub use eval::wrench;
pub use eval_stiffness::wrench_and_stiffness;
pub use pose::Pose;
pub use stiffness::{Stiffness, StiffnessEvaluation, WrenchRate};
pub use wrench::Wrench;
