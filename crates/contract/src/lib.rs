//! The fixed part of the model contract of `coeffs/README.md`, defined once: the
//! library (`src/`), the code generator, the fitter, the C API's checks and the tests
//! all read these constants, and a `model.toml` must agree with them.
//!
//! Changing one of them is changing the contract: the model format version
//! ([`MODEL_FORMAT`]), the golden vectors and every fitted set change with it.
#![no_std]

/// Format version of `model.toml`.
pub const MODEL_FORMAT: i64 = 1;

/// Polynomial degree in depth and in each swept variable.
pub const DEGREE: usize = 4;
/// Coefficients per polynomial (`DEGREE + 1`).
pub const TERMS: usize = DEGREE + 1;

/// Number of model outputs (wrench components).
pub const COMPONENT_COUNT: usize = 6;
/// Wrench components in the contract's order (index `c = 0..COMPONENT_COUNT`): forces in
/// N, moments in N·mm about the hub.
pub const COMPONENTS: [&str; COMPONENT_COUNT] = ["fx_n", "fy_n", "fz_n", "mx_nmm", "my_nmm", "mz_nmm"];
/// The first `FORCE_COUNT` components are forces (N), the others moments (N·mm about
/// the hub).
pub const FORCE_COUNT: usize = 3;
/// Index of the axial force `fy_n`: relative errors are quoted against its peak |Fy|
/// over a run ([`error_scales`]).
pub const FY: usize = 1;
/// Unit of each component (ASCII: `N*mm` is newton millimetre), from [`FORCE_COUNT`].
pub const UNITS: [&str; COMPONENT_COUNT] = {
    let mut units = ["N*mm"; COMPONENT_COUNT];
    let mut c = 0;
    while c < FORCE_COUNT {
        units[c] = "N";
        c += 1;
    }
    units
};

/// Whether component `c` is a force (N) rather than a moment (N·mm).
#[must_use]
pub const fn is_force(c: usize) -> bool {
    c < FORCE_COUNT
}

/// The scale each component's error is quoted against in every report (`needle
/// validate`, the FE checks, the figures): `peak_fy_n` (the largest |Fy| of the runs
/// judged, N) for the forces, `peak_fy_n * lever_arm_mm` (N·mm; the lever arm is the
/// hub's distance from the tip) for the moments.
#[must_use]
pub fn error_scales(peak_fy_n: f64, lever_arm_mm: f64) -> [f64; COMPONENT_COUNT] {
    let mut scales = [peak_fy_n * lever_arm_mm; COMPONENT_COUNT];
    for s in scales.iter_mut().take(FORCE_COUNT) {
        *s = peak_fy_n;
    }
    scales
}

/// The four single-axis sweeps in the contract's order (index `k = 0..3`), as named in
/// `model.toml`.
pub const SWEEPS: [&str; 4] = ["x", "z", "theta_x", "theta_z"];
/// The pose input each sweep varies (the `Pose` field).
pub const SWEEP_INPUTS: [&str; 4] = ["x_mm", "z_mm", "theta_x_deg", "theta_z_deg"];
/// Unit of each sweep's variable.
pub const SWEEP_UNITS: [&str; 4] = ["mm", "mm", "deg", "deg"];
/// The depth input's name (the `Pose` field and the files' column).
pub const DEPTH_INPUT: &str = "depth_mm";

/// Columns of the f32 golden file (`golden-f32.csv`): the four pose inputs, the depth,
/// the status bits, the wrench components.
pub const GOLDEN_COLUMNS: [&str; 6 + COMPONENT_COUNT] =
    golden_columns([SWEEP_INPUTS[0], SWEEP_INPUTS[1], SWEEP_INPUTS[2], SWEEP_INPUTS[3], DEPTH_INPUT], COMPONENTS);

/// A golden file's columns: the five pose inputs, `status`, the wrench components.
const fn golden_columns(inputs: [&'static str; 5], components: [&'static str; COMPONENT_COUNT]) -> [&'static str; 6 + COMPONENT_COUNT] {
    let mut out = [""; 6 + COMPONENT_COUNT];
    let mut i = 0;
    while i < 5 {
        out[i] = inputs[i];
        i += 1;
    }
    out[5] = "status";
    let mut c = 0;
    while c < COMPONENT_COUNT {
        out[6 + c] = components[c];
        c += 1;
    }
    out
}

/// Wrench components of the fixed-point evaluator, in the contract's order: forces in µN
/// (`un`), moments in µN·mm (`unmm`).
pub const FIXED_COMPONENTS: [&str; COMPONENT_COUNT] = ["fx_un", "fy_un", "fz_un", "mx_unmm", "my_unmm", "mz_unmm"];
/// The fixed-point evaluator's inputs in Q16.16: the four sweep inputs and the depth, as
/// named in the fixed-point golden files.
pub const FIXED_INPUTS: [&str; 5] = ["x_mm_q16", "z_mm_q16", "theta_x_deg_q16", "theta_z_deg_q16", "depth_mm_q16"];

/// Columns of the fixed-point golden file (`golden-fixed.csv`): the Q16.16 inputs, the
/// status bits, the wrench components in µN and µN·mm.
pub const GOLDEN_FIXED_COLUMNS: [&str; 6 + COMPONENT_COUNT] = golden_columns(FIXED_INPUTS, FIXED_COMPONENTS);

/// Fixed-point normalisation (coeffs/README.md, "Fixed-point evaluation"): `U = (D +
/// d / 2) / d - 32768` with `d = FIXED_DEPTH_DIVISOR` for the Q16.16 depth `D`: u =
/// depth / (DEPTH_MAX_MM / 2) - 1 in Q15, so `d = DEPTH_MAX_MM / 2 * 2^16 / 2^15`, 6.
pub const FIXED_DEPTH_DIVISOR: u32 = DEPTH_MAX_MM as u32;
/// `T_k = (|V_k| + d / 2) / d - 32768` with `d = FIXED_SWEEP_DIVISORS[k]`: t = |v| * 2 /
/// V - 1 in Q15 for the half-range V, so `d = V / 2 * 2^16 / 2^15 = V` (x, z 12; theta_x,
/// theta_z 15).
pub const FIXED_SWEEP_DIVISORS: [u32; 4] = {
    let [x, z, tx, tz] = HALF_RANGES;
    [x as u32, z as u32, tx as u32, tz as u32]
};
/// The coupled form's `N_k = sign(v_k) * ((|v_k| + d / 2) / d)` with `d =
/// FIXED_CROSS_DIVISORS[k]`: n = v / V in Q15, so `d = V * 2^16 / 2^15 = 2 V` (x, z 24;
/// theta_x, theta_z 30).
pub const FIXED_CROSS_DIVISORS: [u32; 4] = {
    let [x, z, tx, tz] = FIXED_SWEEP_DIVISORS;
    [2 * x, 2 * z, 2 * tx, 2 * tz]
};

/// Columns of an FE run's file (`fe/<pose>.csv`): the depth, the wrench components.
pub const FE_COLUMNS: [&str; 1 + COMPONENT_COUNT] = {
    let mut out = [DEPTH_INPUT; 1 + COMPONENT_COUNT];
    let mut c = 0;
    while c < COMPONENT_COUNT {
        out[1 + c] = COMPONENTS[c];
        c += 1;
    }
    out
};

/// Largest `|x|` and `|z|` of the domain, mm.
pub const XZ_MAX_MM: f64 = 12.0;
/// Largest `|theta_x|` and `|theta_z|` of the domain, degrees.
pub const THETA_MAX_DEG: f64 = 15.0;
/// Largest depth of the domain, mm (the domain is `0 <= depth <= 6`).
pub const DEPTH_MAX_MM: f64 = 6.0;
/// Most layers a tissue stack (`coeffs/<set>/tissue/*.toml`) may have: the library's
/// insertion state holds this many.
pub const MAX_TISSUE_LAYERS: usize = 8;
/// Format version of a tissue stack file that `needle calibrate` writes: 2 adds a layer's
/// material family member and its pre-puncture softening (issue 64).
pub const TISSUE_FORMAT: i64 = 2;
/// The tissue formats a build reads (1: without the family and softening fields).
pub const TISSUE_FORMATS_READ: [i64; 2] = [1, 2];
/// The largest pre-puncture softening fraction of a layer (exclusive): the force at the
/// puncture keeps at least half the elastic one.
pub const SOFTENING_FRACTION_MAX: f64 = 0.5;
/// The range of a layer's presliding distance (tissue format 2's `presliding_mm`, the
/// `shaft-presliding` feature), mm: the shaft's stuck state turns over within twice it.
pub const PRESLIDING_MM_RANGE: (f64, f64) = (0.01, 50.0);
/// The range of a layer's relaxation slip distance (tissue format 2's
/// `relaxation_slip_mm`: the travel within which the shortest shaft term's arm is
/// loaded, the stick band's edge times that term's time constant), mm. Below the
/// presliding distance's: a term of a few milliseconds (three sampling periods of a 1 kHz
/// rig) slipping at a stick band's edge of 0.05 mm/s is loaded within 1.5e-4 mm.
pub const RELAXATION_SLIP_MM_RANGE: (f64, f64) = (1.0e-4, 50.0);
/// The range of a layer's tissue tent stiffness (tissue format 2's `tent_n_per_mm`, the
/// `shaft-presliding` feature), N/mm: the layer's tissue around the shaft, a spring to the
/// ground in series with the shaft's friction (it turns over over millimetres and is
/// lifted with a withdrawing needle).
pub const TENT_N_PER_MM_RANGE: (f64, f64) = (0.001, 100.0);

/// Format version of a set's unsolved region (`unsolved.toml`).
pub const UNSOLVED_FORMAT: i64 = 1;
/// Most balls (mirror images included) an unsolved region may have: the library's
/// prefilter holds one bit per ball in a `u64`.
pub const UNSOLVED_MAX_BALLS: usize = 64;

/// Most Prony terms of a tissue layer's relaxation function (the quasi-linear
/// viscoelastic filter holds this many per wrench component).
pub const MAX_PRONY_TERMS: usize = 3;
/// Largest sum of a layer's Prony weights `g_i` in the long-term normalisation
/// (`G(t) = 1 + sum g_i exp(-t / tau_i)` relative to the elastic, long-term response):
/// the instantaneous response is at most 10 times the long-term one (an Abaqus-style
/// normalised sum of at most 0.9, [`prony_long_term_from_instantaneous`]).
pub const PRONY_G_SUM_MAX: f64 = 9.0;

/// The Prony weights in the long-term normalisation (FEBio's, the tissue files' and the
/// library's: `G(t) / G_inf = 1 + sum g_i exp(-t / tau_i)`) from the weights normalised by
/// the instantaneous response (Abaqus-style: `G(t) / G_0 = 1 - sum g'_i (1 - exp(-t /
/// tau_i))`, `sum g'_i < 1`): `g_i = g'_i / (1 - sum g'_j)`, the time constants unchanged.
/// `None` when a weight is not finite and >= 0 or their sum is not below 1 (no long-term
/// response).
#[must_use]
pub fn prony_long_term_from_instantaneous<const N: usize>(g_instantaneous: [f64; N]) -> Option<[f64; N]> {
    if !g_instantaneous.iter().all(|g| g.is_finite() && *g >= 0.0) {
        return None;
    }
    let long_term = 1.0 - g_instantaneous.iter().sum::<f64>();
    // the weights are finite (checked): so is their sum
    if long_term <= 0.0 {
        return None;
    }
    Some(g_instantaneous.map(|g| g / long_term))
}

/// Half-range `V_k` of each sweep (mm, mm, deg, deg): the domain is `|v| <= V_k`.
pub const HALF_RANGES: [f64; 4] = [XZ_MAX_MM, XZ_MAX_MM, THETA_MAX_DEG, THETA_MAX_DEG];

/// `ODD[k][c]`: component `c` changes sign under sweep `k`'s mirror. The mirror x -> -x
/// maps (x, theta_z) to (-x, -theta_z) and flips fx, my, mz; z -> -z maps (z, theta_x)
/// to (-z, -theta_x) and flips fz, mx, my.
pub const ODD: [[bool; COMPONENT_COUNT]; 4] = [
    [true, false, false, false, true, true],
    [false, false, true, true, true, false],
    [false, false, true, true, true, false],
    [true, false, false, false, true, true],
];

/// The nearest f32 to 1/3: the normalised depth is `u = depth * (1/3) - 1`.
pub const ONE_THIRD_F32: f32 = 1.0 / 3.0;
/// The nearest f32 to `2 / V_k` per sweep: `t = |v| * SWEEP_SCALES_F32[k] - 1`.
pub const SWEEP_SCALES_F32: [f32; 4] = [2.0 / 12.0, 2.0 / 12.0, 2.0 / 15.0, 2.0 / 15.0];
/// The nearest f32 to `1 / V_k` per input: the coupled form's cross-term inputs are
/// `n_k = v_k * CROSS_SCALES_F32[k]`.
pub const CROSS_SCALES_F32: [f32; 4] = [1.0 / 12.0, 1.0 / 12.0, 1.0 / 15.0, 1.0 / 15.0];

/// The status bits of an evaluation (`needle_haptics::Status`, the C API's
/// `NEEDLE_STATUS_*`, the golden files' `status` column).
pub mod status {
    /// Nothing to report.
    pub const OK: u8 = 0x00;
    /// x was outside the domain and clamped.
    pub const SAT_X: u8 = 0x01;
    /// z was clamped.
    pub const SAT_Z: u8 = 0x02;
    /// theta_x was clamped.
    pub const SAT_THETA_X: u8 = 0x04;
    /// theta_z was clamped.
    pub const SAT_THETA_Z: u8 = 0x08;
    /// depth was clamped.
    pub const SAT_DEPTH: u8 = 0x10;
    /// The (clamped) pose lies in the region where the set's FE campaign could not solve
    /// (`unsolved.toml`, coeffs/README.md "The unsolved region"): the wrench is still the
    /// model's, an extrapolation from the runs that solved. Like the saturation bits it
    /// does not zero the wrench.
    pub const FE_UNSOLVED: u8 = 0x20;
    /// The build has no fitted model (always with [`ERROR`]).
    pub const NO_MODEL: u8 = 0x40;
    /// No wrench: an input was NaN or infinite, or there is no model.
    pub const ERROR: u8 = 0x80;
    /// The five saturation bits.
    pub const SATURATION: u8 = SAT_X | SAT_Z | SAT_THETA_X | SAT_THETA_Z | SAT_DEPTH;
    /// Every bit with its name, `OK` first, then in bit order.
    pub const NAMES: [(&str, u8); 9] = [
        ("OK", OK),
        ("SAT_X", SAT_X),
        ("SAT_Z", SAT_Z),
        ("SAT_THETA_X", SAT_THETA_X),
        ("SAT_THETA_Z", SAT_THETA_Z),
        ("SAT_DEPTH", SAT_DEPTH),
        ("FE_UNSOLVED", FE_UNSOLVED),
        ("NO_MODEL", NO_MODEL),
        ("ERROR", ERROR),
    ];
}

/// The insertion model's physical limits (`needle_haptics::insertion` and
/// `fixed::insertion`, coeffs/README.md "Insertion flags"): its domain, the default
/// largest speeds of a tick and the bound on its wrench. A pose outside the domain, or
/// one that moved further than the configuration's largest speeds allow since the last
/// accepted pose, is a glitch: not integrated as motion ([`insertion_flags`]).
pub mod insertion_limits {
    /// Largest `|x|` and `|z|` of an insertion pose (the entry point), mm.
    pub const XZ_MAX_MM: i32 = 64;
    /// Largest `|depth|` of an insertion pose (the tip along the axis past the surface), mm.
    pub const DEPTH_MAX_MM: i32 = 128;
    /// Largest `|theta_x|` and `|theta_z|` of an insertion pose, degrees.
    pub const TILT_MAX_DEG: i32 = 89;
    /// The default largest speed of `x`, `z` and `depth`, mm/s (1 mm per tick at 1 kHz:
    /// a hand's fast reach, 24 times the fastest golden insertion path's 41.7 mm/s).
    pub const SPEED_MAX_MM_PER_S: u32 = 1000;
    /// The default largest turning speed of the tilts, degrees/s (1 degree per tick at 1 kHz).
    pub const TURN_MAX_DEG_PER_S: u32 = 1000;
    /// The bound on the insertion's force: `|fx| + |fy| + |fz|` never exceeds it, N (so no
    /// force component does); a larger force is scaled down to it, its direction kept.
    pub const FORCE_LIMIT_N: i32 = 100;
    /// The bound on the insertion's moment about the hub: `|mx| + |my| + |mz|` never
    /// exceeds it, N·mm (so no moment component does); scaled down as the force.
    pub const MOMENT_LIMIT_NMM: i32 = 10_000;
}

/// The insertion step's own flags (`needle_haptics::insertion::InsertionFlags`, the C
/// API's `NEEDLE_INSERTION_*`, the CLI's `flags` column), beside the surrogate's
/// [`status`] bits (whose eight bits are all taken).
pub mod insertion_flags {
    /// Nothing to report: the pose was accepted and the wrench was within its bound.
    pub const OK: u8 = 0x00;
    /// The pose moved further since the last accepted pose than the configuration's
    /// largest speeds allow: a glitch, not integrated (the wrench held).
    pub const FAST_MOTION: u8 = 0x01;
    /// The pose lies outside the insertion's domain ([`super::insertion_limits`]): a
    /// glitch, not integrated (the wrench held).
    pub const OUT_OF_DOMAIN: u8 = 0x02;
    /// An input was NaN or infinite: a glitch, not integrated (the wrench zero, the
    /// status `ERROR`).
    pub const NOT_FINITE: u8 = 0x04;
    /// The wrench's force or moment was beyond its bound
    /// ([`super::insertion_limits::FORCE_LIMIT_N`], [`super::insertion_limits::MOMENT_LIMIT_NMM`])
    /// and was scaled down to it.
    pub const WRENCH_LIMITED: u8 = 0x08;
    /// The three glitch flags: the tick was not integrated.
    pub const GLITCH: u8 = FAST_MOTION | OUT_OF_DOMAIN | NOT_FINITE;
    /// Every flag with its name, `OK` first, then in bit order.
    pub const NAMES: [(&str, u8); 5] = [
        ("OK", OK),
        ("FAST_MOTION", FAST_MOTION),
        ("OUT_OF_DOMAIN", OUT_OF_DOMAIN),
        ("NOT_FINITE", NOT_FINITE),
        ("WRENCH_LIMITED", WRENCH_LIMITED),
    ];
}
