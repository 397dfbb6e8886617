//! This crate's own evaluations of the contract, independent of the library: in f64
//! ([`float64`], the reference and the fit's), in f32 and in fixed point bit for bit as
//! the library must give them ([`float32`], [`fixed`]: the golden vectors come from
//! them), and the rates by depth, x and z ([`rate_float32`], [`rate_float64`]).

pub mod fixed;
pub mod float32;
pub mod float64;
pub mod rate_float32;
pub mod rate_float64;
