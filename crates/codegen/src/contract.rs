//! The fixed part of the contract in `coeffs/README.md` (component and sweep order,
//! units, domain, mirror parities, normalisation constants, status bits), from the
//! `needle-contract` crate where each is defined once. A model file must agree with
//! every value here.
pub use needle_contract::{
    COMPONENTS, CROSS_SCALES_F32, DEPTH_MAX_MM, HALF_RANGES, MODEL_FORMAT as FORMAT, ODD, ONE_THIRD_F32, SWEEPS, SWEEP_INPUTS,
    SWEEP_SCALES_F32, SWEEP_UNITS, UNITS,
};

/// Status bits of the evaluation (name, value), as in the library's `Status`.
pub const STATUS_BITS: [(&str, u8); 9] = needle_contract::status::NAMES;

/// `"fx_n .. mz_nmm"`: the first and the last component's names, for messages and
/// generated comments.
pub fn component_range() -> String {
    format!("{} .. {}", COMPONENTS.first().copied().unwrap_or_default(), COMPONENTS.last().copied().unwrap_or_default())
}
