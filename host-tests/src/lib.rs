//! std side of `needle-haptics`: the FE campaign driver (CalculiX), the fitter and
//! the pieces of the `needle` command-line tool.
#![forbid(unsafe_code)]

pub mod cli;
pub mod fixed_error;
