//! The fixed-point evaluator: the same model in integer arithmetic only, for cores
//! without an FPU (Cortex-M0/M0+/M3), with a proven error bound.
//!
//! - Input: [`Pose`], five `i32` in Q16.16 (mm or degrees × 65536).
//! - Output: [`Wrench`], six `i32` in µN and µN·mm, with the same [`Status`](crate::Status)
//!   saturation flags as the f32 evaluator (there is no NaN in integers).
//! - [`wrench`] evaluates it, [`wrench_and_stiffness`] with its derivatives by depth, x
//!   and z ([`Stiffness`], µN/mm); [`tables`] holds the generated integer tables, their Q
//!   formats and the error bound against the f64 model, per component.
//!
//! ```
//! use needle_haptics::fixed::{self, Pose};
//!
//! // x = 3 mm, z = -2 mm, theta_x = 5 deg, theta_z = 0, depth = 4.5 mm
//! let pose = Pose::new(3 * Pose::ONE, -2 * Pose::ONE, 5 * Pose::ONE, 0, 9 * Pose::ONE / 2);
//! let eval = fixed::wrench(&pose);
//! if !eval.status.is_error() {
//!     let _fy_un: i32 = eval.wrench.fy_un; // axial reaction force, micro-newtons
//! }
//! ```
//!
//! The code generator (`needle-codegen`, run by `build.rs`) picks the Q format of every
//! row polynomial and of every component's accumulator from the coefficients, bounds
//! every intermediate over the whole domain so that none can overflow (or refuses the
//! model, naming the matrix), and derives the error bound
//! [`tables::ERROR_BOUND_MICRO`]. The algorithm is the fixed-point contract in
//! `coeffs/README.md`; the fitter's independent implementation writes
//! `coeffs/<set>/golden-fixed.csv`, which this evaluator reproduces bit for bit.
//!
//! Its modules mirror the f32 evaluator's ([`crate::float`]) name for name: `pose`,
//! `wrench`, `stiffness`, `depth_extension`, `family`, `insertion` (`stack`, `track`),
//! `viscoelastic` (`identity`), `tables`, `eval`, `cross`, `eval_stiffness`. Modules of
//! this precision alone (`host-tests/tests/precision_mirrors.rs` reads these lines):
//!
//! - precision-only: `arith` because the Q15 product, the normalisation and the saturating
//!   `i64` product are integer arithmetic; the f32 evaluator's is `float::horner`.

mod arith;
mod cross;
mod depth_extension;
mod eval;
mod eval_stiffness;
pub mod family;
// The module doc links the private `track` (insertion/mod.rs, line 12): left to the
// insertion work, whose folder is being changed; remove this allow with that fix
// (`track` in backticks, without the link).
#[allow(rustdoc::private_intra_doc_links)]
pub mod insertion;
mod pose;
mod stiffness;
pub mod tables;
pub mod viscoelastic;
mod wrench;

pub use depth_extension::{extended_wrench, DEPTH_MAX_MM_Q16 as EXTENDED_DEPTH_MAX_MM_Q16};
pub use eval::wrench;
pub use eval_stiffness::wrench_and_stiffness;
pub use pose::Pose;
pub use stiffness::{Stiffness, StiffnessEvaluation, WrenchRate};
pub use wrench::{Evaluation, Wrench};
