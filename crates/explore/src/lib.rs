//! `needle explore`: the model in a browser, evaluated by the firmware's own code.
//!
//! [`wasm::build`] compiles `crates/wasm` (the `no_std` library and the set's tables,
//! `NEEDLE_COEFFS` = the set) for `wasm32-unknown-unknown`; [`server`] serves one page
//! (`page/`: HTML, CSS and plain JavaScript, embedded in this binary: nothing is fetched
//! from the network), the module, [`set_json`] (the set's FE runs, needle and block) and
//! [`stacks_json`] (tissue files given with `--stack`, and tissues drawn within their spread).
#![forbid(unsafe_code)]

pub mod server;
pub mod set_json;
pub mod stacks_json;
pub mod wasm;
