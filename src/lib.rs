//! `needle-haptics`: the reaction wrench of soft tissue on an inserted needle, fast
//! enough for a haptic control loop, from the parametric model of Bora, Mishra and
//! Siva Kumar ("Parametric modelling of needle-tissue interaction using finite element
//! analysis").
//!
//! `no_std`, no allocation, no `unsafe` (the FPU's square root instruction is called
//! from `needle-fpu`), no panics. The coefficients are fitted on the
//! host (`needle fit`) from finite-element runs and compiled in at build time from the
//! coefficient set named by `NEEDLE_COEFFS` (default `coeffs/default`).
//!
//! ```
//! use needle_haptics::{wrench, Pose};
//!
//! let pose = Pose { x_mm: 3.0, z_mm: -2.0, theta_x_deg: 5.0, theta_z_deg: 0.0, depth_mm: 4.5 };
//! let eval = wrench(&pose);
//! if !eval.status.is_error() {
//!     let _fy_n: f32 = eval.wrench.fy_n; // axial reaction force, N
//! }
//! ```
//!
//! # The model
//!
//! With `u = depth_mm / 3 - 1` and, for each sweep k (x, z, theta_x, theta_z) with value
//! `v_k`, `t_k = |v_k| / (V_k / 2) - 1` (`V` = 12 mm, 12 mm, 15°, 15°), each wrench
//! component c is
//!
//! ```text
//! w_c = B_c(u) + sum over k of  s_kc * D_kc(t_k, u)
//! ```
//!
//! where `B_c` is the quartic in depth of the centred vertical needle, `D_kc` the
//! deviation of sweep k's fitted model from its value at `v_k = 0` (a 5x5 polynomial,
//! exactly `+0.0` at `t = -1` in f32 and 0 in fixed point, by the fitter's construction),
//! and `s_kc = -1` when `v_k < 0` and component c is odd under that sweep's mirror, else
//! `+1`: every odd component changes sign under its mirror bit for bit. The exact f32 operation order is the contract in
//! `coeffs/README.md`; [`wrench`] follows it bit for bit.
//!
//! A set fitted in the coupled form (`form = "coupled"` in its `model.toml`,
//! [`model_info::COUPLED`]) adds cross terms to every component after the
//! superposition:
//!
//! ```text
//! w_c += sum over terms of  m(x/12, z/12, theta_x/15, theta_z/15) * P(u)
//! ```
//!
//! with `m` a product of powers of at least two inputs, chosen so that every term keeps
//! component c's mirror parities exactly, and `P` a polynomial in depth.
//!
//! Without a fitted model (a new set before `needle fit`), the library still builds
//! (with a cargo warning) and [`wrench`] returns a zero wrench with
//! `Status::NO_MODEL | Status::ERROR` for every pose ([`model_info::FITTED`] is `false`).
#![no_std]
#![forbid(unsafe_code)]
#![deny(missing_docs)]

mod bit_flags;
pub mod command;
pub mod control;
mod evaluation;
pub mod fixed;
pub mod float;
mod insertion_flags;
pub mod model_info;
pub mod orientation;
mod status;
pub mod telemetry;
mod unsolved;

pub use evaluation::Evaluation;
// The f32 evaluator's API at the root, where it has always been (`needle_haptics::wrench`,
// `needle_haptics::insertion::Insertion`...): `float` mirrors `fixed` module for module.
pub use float::{depth_extension, insertion, viscoelastic};
pub use float::{extended_wrench, wrench, wrench_and_depth_rate, wrench_and_stiffness};
pub use float::{Pose, Stiffness, StiffnessEvaluation, Wrench, WrenchRate};
pub use insertion_flags::InsertionFlags;
pub use status::Status;
