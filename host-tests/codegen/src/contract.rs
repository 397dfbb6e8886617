//! The fixed part of the contract in `coeffs/README.md`: component and sweep order,
//! units, domain, mirror parities, normalisation constants. A model file must agree
//! with every value here; the evaluator in `src/` hard-codes the same values.

/// Format version of `model.toml` this crate reads.
pub const FORMAT: i64 = 1;

/// Wrench components, in the contract's order (index c = 0..5).
pub const COMPONENTS: [&str; 6] = ["fx_n", "fy_n", "fz_n", "mx_nmm", "my_nmm", "mz_nmm"];

/// Unit of each component (ASCII: `N*mm` is newton millimetre).
pub const UNITS: [&str; 6] = ["N", "N", "N", "N*mm", "N*mm", "N*mm"];

/// Sweeps, in the contract's order (index k = 0..3).
pub const SWEEPS: [&str; 4] = ["x", "z", "theta_x", "theta_z"];

/// Name of each sweep's pose input (the `Pose` field).
pub const SWEEP_INPUTS: [&str; 4] = ["x_mm", "z_mm", "theta_x_deg", "theta_z_deg"];

/// Unit of each sweep's variable.
pub const SWEEP_UNITS: [&str; 4] = ["mm", "mm", "deg", "deg"];

/// Half-range `V_k` of each sweep (mm, mm, deg, deg): the domain is `|v| <= V_k`.
pub const HALF_RANGES: [f64; 4] = [12.0, 12.0, 15.0, 15.0];

/// Upper end of the depth range, mm (the domain is `0 <= depth <= 6`).
pub const DEPTH_MAX_MM: f64 = 6.0;

/// `odd[k][c]`: component c changes sign under sweep k's mirror (x and theta_z: fx, my,
/// mz; z and theta_x: fz, mx, my).
pub const ODD: [[bool; 6]; 4] = [
    [true, false, false, false, true, true],
    [false, false, true, true, true, false],
    [false, false, true, true, true, false],
    [true, false, false, false, true, true],
];

/// The nearest f32 to 1/3 (depth normalisation `u = d * (1/3) - 1`).
pub const ONE_THIRD_F32: f32 = 1.0 / 3.0;

/// The nearest f32 to `2 / V_k` for each sweep (`t = |v| * s_k - 1`).
pub const SWEEP_SCALES_F32: [f32; 4] = [2.0 / 12.0, 2.0 / 12.0, 2.0 / 15.0, 2.0 / 15.0];

/// The nearest f32 to `1 / V_k` for each input: the coupled form's cross-term inputs are
/// `n_k = v_k * CROSS_SCALES_F32[k]` (coeffs/README.md, "The coupled form").
pub const CROSS_SCALES_F32: [f32; 4] = [1.0 / 12.0, 1.0 / 12.0, 1.0 / 15.0, 1.0 / 15.0];

/// Status bits of the evaluation (name, value), as in the library's `Status`.
pub const STATUS_BITS: [(&str, u8); 8] = [
    ("OK", 0x00),
    ("SAT_X", 0x01),
    ("SAT_Z", 0x02),
    ("SAT_THETA_X", 0x04),
    ("SAT_THETA_Z", 0x08),
    ("SAT_DEPTH", 0x10),
    ("NO_MODEL", 0x40),
    ("ERROR", 0x80),
];
