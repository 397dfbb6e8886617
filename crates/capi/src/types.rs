//! The C types of the API (`#[repr(C)]`; cbindgen writes them to `needle.h`).

/// Motor channels of the C loop.
pub const NEEDLE_CHANNELS: usize = 3;
/// 64-bit words of opaque storage in a [`needle_loop_t`].
pub const NEEDLE_LOOP_STORAGE_WORDS: usize = 315;
/// [`needle_loop_t::magic`] of an initialised loop.
pub const NEEDLE_LOOP_MAGIC: u32 = 0x4e4c_4f50;

/// 64-bit words of opaque storage in a [`needle_insertion_t`].
pub const NEEDLE_INSERTION_STORAGE_WORDS: usize = 278;
/// [`needle_insertion_t::magic`] of an initialised insertion.
pub const NEEDLE_INSERTION_MAGIC: u32 = 0x4e49_4e53;

/// 64-bit words of opaque storage in a [`needle_fixed_insertion_t`].
pub const NEEDLE_FIXED_INSERTION_STORAGE_WORDS: usize = 112;
/// [`needle_fixed_insertion_t::magic`] of an initialised fixed-point insertion.
pub const NEEDLE_FIXED_INSERTION_MAGIC: u32 = 0x4e46_494e;

/// Success.
pub const NEEDLE_OK: i32 = 0;
/// A pointer argument was NULL.
pub const NEEDLE_E_NULL: i32 = -1;
/// The configuration (or the new force limit) was refused; nothing changed.
pub const NEEDLE_E_CONFIG: i32 = -2;
/// The loop was not initialised with `needle_loop_init`.
pub const NEEDLE_E_UNINIT: i32 = -3;
/// An enumeration argument had an unknown value.
pub const NEEDLE_E_ARG: i32 = -4;

/// `pose_state` of `needle_loop_tick`: the pose is fresh.
pub const NEEDLE_POSE_FRESH: u8 = 0;
/// `pose_state`: the pose is stale (it is not evaluated; the output ramps to zero).
pub const NEEDLE_POSE_STALE: u8 = 1;
/// `pose_state`: there is no pose (`pose` may be NULL; the output ramps to zero).
pub const NEEDLE_POSE_MISSING: u8 = 2;

/// `over_limit`: scale the force down to the limit.
pub const NEEDLE_OVER_LIMIT_SATURATE: u8 = 0;
/// `over_limit`: treat a force above the limit as a fault and ramp to zero.
pub const NEEDLE_OVER_LIMIT_RAMP: u8 = 1;

/// The needle's pose (mm, degrees), as `needle_haptics::Pose`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct needle_pose_t {
    /// x of the insertion point, mm.
    pub x_mm: f32,
    /// z of the insertion point, mm.
    pub z_mm: f32,
    /// Tilt about x, degrees.
    pub theta_x_deg: f32,
    /// Tilt about z, degrees.
    pub theta_z_deg: f32,
    /// Depth along the needle, mm.
    pub depth_mm: f32,
}

/// The reaction wrench (N, N·mm about the needle's reference point), as
/// `needle_haptics::Wrench`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct needle_wrench_t {
    /// Force along x, N.
    pub fx_n: f32,
    /// Force along y, N.
    pub fy_n: f32,
    /// Force along z, N.
    pub fz_n: f32,
    /// Moment about x, N·mm.
    pub mx_nmm: f32,
    /// Moment about y, N·mm.
    pub my_nmm: f32,
    /// Moment about z, N·mm.
    pub mz_nmm: f32,
}

/// The wrench's partial derivatives (`needle_wrench_and_stiffness`): each array holds the
/// rates of fx, fy, fz (N/mm) and mx, my, mz (N·mm/mm), in that order.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct needle_stiffness_t {
    /// d wrench / d depth_mm.
    pub by_depth: [f32; 6],
    /// d wrench / d x_mm.
    pub by_x: [f32; 6],
    /// d wrench / d z_mm.
    pub by_z: [f32; 6],
}

/// The needle's pose in fixed point, as `needle_haptics::fixed::Pose`: each input in
/// Q16.16 (mm or degrees times 65536).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct needle_fixed_pose_t {
    /// x of the insertion point, mm × 65536.
    pub x_mm_q16: i32,
    /// z of the insertion point, mm × 65536.
    pub z_mm_q16: i32,
    /// Tilt about x, degrees × 65536.
    pub theta_x_deg_q16: i32,
    /// Tilt about z, degrees × 65536.
    pub theta_z_deg_q16: i32,
    /// Depth along the needle, mm × 65536.
    pub depth_mm_q16: i32,
}

/// The reaction wrench in integers (µN, µN·mm), as `needle_haptics::fixed::Wrench`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct needle_fixed_wrench_t {
    /// Force along x, µN.
    pub fx_un: i32,
    /// Force along y, µN.
    pub fy_un: i32,
    /// Force along z, µN.
    pub fz_un: i32,
    /// Moment about x, µN·mm.
    pub mx_unmm: i32,
    /// Moment about y, µN·mm.
    pub my_unmm: i32,
    /// Moment about z, µN·mm.
    pub mz_unmm: i32,
}

/// The fixed-point wrench's partial derivatives (`needle_fixed_wrench_and_stiffness`):
/// each array holds the rates of fx, fy, fz (µN/mm) and mx, my, mz (µN·mm/mm).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct needle_fixed_stiffness_t {
    /// d wrench / d depth.
    pub by_depth: [i32; 6],
    /// d wrench / d x.
    pub by_x: [i32; 6],
    /// d wrench / d z.
    pub by_z: [i32; 6],
}

/// Identity and domain of the compiled-in model.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct needle_model_info_t {
    /// The coefficient set's name, NUL-terminated (truncated to 32 characters).
    pub set: [u8; 33],
    /// SHA-256 of the FE data the model was fitted on, 64 hex digits, NUL-terminated.
    pub fe_sha256: [u8; 65],
    /// `false` for a build without a fitted model (every evaluation is an error).
    pub fitted: bool,
    /// Domain: `|x_mm| <= x_max_mm`.
    pub x_max_mm: f32,
    /// Domain: `|z_mm| <= z_max_mm`.
    pub z_max_mm: f32,
    /// Domain: `|theta| <= theta_max_deg`.
    pub theta_max_deg: f32,
    /// Domain: `0 <= depth_mm <= depth_max_mm`.
    pub depth_max_mm: f32,
}

/// One motor channel's linear map: `c = (g[0]*fx + g[1]*fy) + g[2]*fz`, duty `|c|` of
/// full scale (clipped to 1), direction pin high when `(c >= 0) != direction_inverted`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default)]
pub struct needle_channel_map_t {
    /// Full-scale fraction per newton of fx, fy, fz.
    pub gains_per_n: [f32; 3],
    /// Swap the direction pin's polarity.
    pub direction_inverted: bool,
}

/// Configuration of the C loop (see `needle_haptics::control::LoopConfig`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default)]
pub struct needle_loop_config_t {
    /// The map of each channel.
    pub channels: [needle_channel_map_t; NEEDLE_CHANNELS],
    /// Device force limit on |F|, N.
    pub force_limit_n: f32,
    /// Largest limit the host link may set, N.
    pub force_limit_max_n: f32,
    /// `NEEDLE_OVER_LIMIT_SATURATE` or `NEEDLE_OVER_LIMIT_RAMP`.
    pub over_limit: u8,
    /// Ramp step per tick and component during a fault, N.
    pub ramp_step_n: f32,
}

/// The passivity guard of the C loop (see `needle_haptics::control::Passivity`): the
/// device's physical damping along the insertion and the loop's period; the guard keeps
/// the rendered stiffness at half of Colgate's bound `2 b / T`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default)]
pub struct needle_passivity_t {
    /// Physical damping of the device along the insertion, N·s/mm (finite, > 0).
    pub damping_n_s_per_mm: f32,
    /// The loop's period, s (finite, > 0; 0.001 at 1 kHz).
    pub period_s: f32,
}

/// What one tick of the C loop read, computed and commands.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default)]
pub struct needle_tick_t {
    /// Tick count (1 for the first tick).
    pub tick: u32,
    /// The pose evaluated (the last fresh one on a stale or missing tick).
    pub pose: needle_pose_t,
    /// The model's wrench (zero when not evaluated or on error).
    pub wrench: needle_wrench_t,
    /// The force commanded after the limit and the ramp, N.
    pub force_cmd_n: [f32; 3],
    /// Duty cycle of each channel, for the `max_duty` given to the tick.
    pub duty: [u16; NEEDLE_CHANNELS],
    /// Loop flags (`needle_haptics::control::LoopFlags` bits).
    pub flags: u16,
    /// The model's status bits (`NEEDLE_STATUS_*` of needle_coeffs.h).
    pub model_status: u8,
    /// Direction pin level of each channel.
    pub direction_high: [bool; NEEDLE_CHANNELS],
    /// Enable pin level.
    pub enable: bool,
}

/// A control loop's state, opaque to C: allocate it anywhere (static, stack), then
/// `needle_loop_init`. Plain data: it may be copied with `memcpy`.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct needle_loop_t {
    /// Opaque.
    pub storage: [u64; NEEDLE_LOOP_STORAGE_WORDS],
    /// `NEEDLE_LOOP_MAGIC` once initialised.
    pub magic: u32,
}

/// `needle_wrench` status bit (`needle_haptics::Status::SAT_X`): x was outside the domain
/// and clamped. Each `NEEDLE_STATUS_*` value is checked against the library's by
/// `tests/c_program.rs` (`status_and_flag_constants_are_the_librarys`).
pub const NEEDLE_STATUS_SAT_X: u8 = 0x01;
/// Status bit: z clamped to the domain.
pub const NEEDLE_STATUS_SAT_Z: u8 = 0x02;
/// Status bit: theta_x clamped to the domain.
pub const NEEDLE_STATUS_SAT_THETA_X: u8 = 0x04;
/// Status bit: theta_z clamped to the domain.
pub const NEEDLE_STATUS_SAT_THETA_Z: u8 = 0x08;
/// Status bit: depth clamped to the domain.
pub const NEEDLE_STATUS_SAT_DEPTH: u8 = 0x10;
/// Status bit: the (clamped) pose lies in the region where the set's FE campaign could
/// not solve; the wrench is still the model's (an extrapolation), not zeroed.
pub const NEEDLE_STATUS_FE_UNSOLVED: u8 = 0x20;
/// Status bit: the build has no fitted model (the wrench is zero).
pub const NEEDLE_STATUS_NO_MODEL: u8 = 0x40;
/// Status bit: no wrench could be computed (NaN input, NULL pose, no model).
pub const NEEDLE_STATUS_ERROR: u8 = 0x80;

/// `needle_insertion_result_t::flags` bit (`needle_haptics::InsertionFlags::FAST_MOTION`):
/// the pose moved further since the last accepted one than the largest speeds allow; not
/// integrated, the wrench held. Each `NEEDLE_INSERTION_*` value is checked against the
/// library's by `tests/c_program.rs`.
pub const NEEDLE_INSERTION_FAST_MOTION: u8 = 0x01;
/// Insertion flag: the pose is outside the insertion's domain (|x|, |z| <= 64 mm,
/// |depth| <= 128 mm, tilts <= 89 degrees); not integrated, the wrench held.
pub const NEEDLE_INSERTION_OUT_OF_DOMAIN: u8 = 0x02;
/// Insertion flag: an input was NaN or infinite; not integrated, the wrench zero.
pub const NEEDLE_INSERTION_NOT_FINITE: u8 = 0x04;
/// Insertion flag: the force (|fx| + |fy| + |fz| <= 100 N) or moment (|mx| + |my| + |mz|)
/// bound was exceeded and the wrench scaled down to it.
pub const NEEDLE_INSERTION_WRENCH_LIMITED: u8 = 0x08;

/// `needle_tick_t::flags` bit (`needle_haptics::control::LoopFlags::POSE_STALE`).
pub const NEEDLE_LOOP_POSE_STALE: u16 = 0x0001;
/// Loop flag: no pose this tick.
pub const NEEDLE_LOOP_POSE_MISSING: u16 = 0x0002;
/// Loop flag: the evaluator returned an error.
pub const NEEDLE_LOOP_EVAL_ERROR: u16 = 0x0004;
/// Loop flag: the force exceeded the limit.
pub const NEEDLE_LOOP_OVER_LIMIT: u16 = 0x0008;
/// Loop flag: the force was scaled down to the limit.
pub const NEEDLE_LOOP_FORCE_SATURATED: u16 = 0x0010;
/// Loop flag: the output is ramping (to zero or back).
pub const NEEDLE_LOOP_RAMPING: u16 = 0x0020;
/// Loop flag: a duty cycle was clipped to the channel's range.
pub const NEEDLE_LOOP_DUTY_CLIPPED: u16 = 0x0040;
/// Loop flag: a PWM or pin write failed.
pub const NEEDLE_LOOP_OUTPUT_ERROR: u16 = 0x0080;
/// Loop flag: the enable pin is low.
pub const NEEDLE_LOOP_DISABLED: u16 = 0x0100;
/// Loop flag: the passivity guard limited the rendered stiffness.
pub const NEEDLE_LOOP_STIFFNESS_LIMITED: u16 = 0x0200;
/// Loop flag: the insertion rejected the pose as a glitch (`NEEDLE_INSERTION_*`); a fault
/// that keeps the passivity guard's state.
pub const NEEDLE_LOOP_POSE_GLITCH: u16 = 0x0400;

/// A needle path through a tissue stack: initialise with `needle_insertion_init`. Plain
/// data: it may be copied with `memcpy`.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct needle_insertion_t {
    /// Opaque.
    pub storage: [u64; NEEDLE_INSERTION_STORAGE_WORDS],
    /// `NEEDLE_INSERTION_MAGIC` once initialised.
    pub magic: u32,
}

/// One tick of `needle_insertion_step`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default)]
pub struct needle_insertion_result_t {
    /// The wrench on the needle (N, N·mm about the hub).
    pub wrench: needle_wrench_t,
    /// `NEEDLE_STATUS_*` bits of the surrogate (saturation; `ERROR` for a pose that is not finite).
    pub status: u8,
    /// Boundaries punctured in this tick.
    pub punctures: u8,
    /// Phase code: `0` approach, `0x100 | layer` deflecting, `0x200 | layer` cutting, `0x300 | layer` in the track.
    pub phase: u16,
    /// Filtered axial velocity, mm/s (positive inserting).
    pub velocity_mm_per_s: f32,
    /// `NEEDLE_INSERTION_*` flags of the step: a glitch (not integrated, the wrench held)
    /// or a wrench scaled down to its bound; 0 otherwise.
    pub flags: u8,
}

/// A needle path through a tissue stack in integers: initialise with
/// `needle_fixed_insertion_init`. Plain data: it may be copied with `memcpy`.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct needle_fixed_insertion_t {
    /// Opaque.
    pub storage: [u64; NEEDLE_FIXED_INSERTION_STORAGE_WORDS],
    /// `NEEDLE_FIXED_INSERTION_MAGIC` once initialised.
    pub magic: u32,
}

/// One tick of `needle_fixed_insertion_step`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default)]
pub struct needle_fixed_insertion_result_t {
    /// The wrench on the needle (µN, µN·mm about the hub).
    pub wrench: needle_fixed_wrench_t,
    /// `NEEDLE_STATUS_*` bits of the surrogate (saturation).
    pub status: u8,
    /// Boundaries punctured in this tick.
    pub punctures: u8,
    /// Phase code, as `needle_insertion_result_t`'s.
    pub phase: u16,
    /// Filtered axial velocity, mm/s × 65536 (positive inserting).
    pub velocity_mm_per_s_q16: i32,
    /// `NEEDLE_INSERTION_*` flags, as `needle_insertion_result_t`'s.
    pub flags: u8,
}
