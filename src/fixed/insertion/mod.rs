//! The whole insertion in integers: [`Insertion`] is [`crate::float::insertion::Insertion`]'s
//! state machine (the same phases, punctures, cutting, friction and track, documented
//! there) computed without floating point, for cores without an FPU.
//!
//! - Input: [`fixed::Pose`](super::Pose) (Q16.16 mm and degrees), one per tick.
//! - Output: [`fixed::Wrench`](super::Wrench) in µN and µN·mm, the status, the phase,
//!   the punctures and the filtered axial velocity (mm/s, Q16).
//! - The stacks: [`stacks::ALL`], the compiled-in f32 stacks converted at compile time
//!   ([`Stack::from_f32`]).
//! - The surrogate: [`fixed::extended_wrench`](super::extended_wrench) at `x/λ, z/λ, δ/λ`,
//!   scaled by `s λ²` (forces) and `s λ³` (moments), each gain `s λ^k` in Q16.
//! - Internally `i64`: path coordinates in mm Q16, the axis in Q30 ([`track`]), forces
//!   in µN Q16; the output rounds to whole µN and saturates to `i32`.
//!
//! **Glitches** (the f32 model's "Glitches", in integers): a pose outside the domain
//! (`|x|, |z| <= 64` mm, `|depth| <= 128` mm, tilts `|θ| <= 89` degrees:
//! `needle_contract::insertion_limits`) or one that moved further since the last accepted
//! pose than [`InsertionConfig::max_speed_mm_per_s`] (tilts:
//! [`InsertionConfig::max_turn_deg_per_s`]) allows over the ticks since it (the step per
//! tick in Q16 computed once in [`Insertion::new`]) is not integrated: the wrench and
//! phase are the last tick's, the flags ([`InsertionFlags`]) say why, and the deflected
//! boundary's filter relaxes over its held input (the next accepted tick's change taken
//! as a ramp over the ticks since the last: `viscoelastic::QlvState::hold`). The wrench's
//! `|fx| + |fy| + |fz|` stays within `FORCE_LIMIT_N` (in µN), scaled down to the bound
//! otherwise; `|mx| + |my| + |mz|` is within `MOMENT_LIMIT_NMM` (in µN·mm) by its type
//! (three `i32`, at most 6,442 N·mm). The
//! surrogate clamps further to its own domain and reports it.
//!
//! **Overflow.** Every product whose size depends on the stack's values or on the pose
//! saturates (`i64::saturating_mul`); within the stacks [`Stack::from_f32`] accepts
//! (`λ <= 8`, `s <= 16384`, total thickness <= 512 mm) and the clamped inputs, the
//! wrench of a realistic tissue stays far below saturation (the accuracy test compares
//! it with the f32 model over the golden paths of every shipped stack).
//!
//! **Velocity**: the backward difference of the depth times the tick rate
//! (`1e6 / period_us`, Q16, computed once in [`Insertion::new`]), low-passed with
//! `alpha = period / (period + tau)` (Q16, once): `v += floor(alpha (raw - v) / 2^16)`.
//! No division per tick but one: the path coordinate of a boundary is its depth below
//! the surface over the axis's vertical component (`2^60 / a_y`, once per tick).
mod softening;
mod stack;
mod track;

pub use stack::{
    stacks, FamilyMember, Karnopp, Layer, Softening, Stack, CUTTING_MAX_Q16, FRICTION_LEVEL_MAX_Q16, MAX_LAYERS, SIMILARITY_MAX,
    STICK_BAND_MAX_Q16, STIFFNESS_SCALE_MAX, TOTAL_THICKNESS_MAX_MM, VISCOUS_MAX_Q16,
};

#[cfg(feature = "tissue-shape")]
use super::arith::scale_q30;
use super::arith::{div_i64, div_u64, sat_mul};
use super::depth_extension::{round_shr_i32, saturate_i32};
#[cfg(not(feature = "viscoelastic"))]
use super::viscoelastic::identity::{QlvCoefficients, QlvState};
#[cfg(feature = "viscoelastic")]
use super::viscoelastic::{QlvCoefficients, QlvState};
use super::{extended_wrench, Pose, Wrench};
use crate::float::insertion::{InsertionError, Phase};
use crate::{InsertionFlags, Status};
use needle_contract::insertion_limits as limits;
use track::{axis, dot, mul_q30, mul_shr, HoldSums, Track, Vec3, TRACK_STIFFNESS_MAX_Q8};

/// The insertion's tick settings in integers.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct InsertionConfig {
    /// The period of the pose stream, µs (> 0; 1000 at 1 kHz).
    pub period_us: u32,
    /// Time constant of the velocity's low-pass filter, µs (0: unfiltered).
    pub velocity_time_constant_us: u32,
    /// The largest speed of `x`, `z` and `depth`, mm/s (> 0; 1,000 by default): faster
    /// is a glitch ([`InsertionFlags::FAST_MOTION`]).
    pub max_speed_mm_per_s: u32,
    /// The largest turning speed of the tilts, degrees/s (> 0; 1,000 by default).
    pub max_turn_deg_per_s: u32,
}

impl InsertionConfig {
    /// 1 kHz, velocity filtered with a 5 ms time constant (the f32 model's
    /// [`DEFAULT_1KHZ`](crate::float::insertion::InsertionConfig::DEFAULT_1KHZ)).
    pub const DEFAULT_1KHZ: Self = Self {
        period_us: 1000,
        velocity_time_constant_us: 5000,
        max_speed_mm_per_s: limits::SPEED_MAX_MM_PER_S,
        max_turn_deg_per_s: limits::TURN_MAX_DEG_PER_S,
    };
}

/// One tick's result.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct InsertionEvaluation {
    /// The wrench on the needle (block frame; µN, µN·mm about the hub).
    pub wrench: Wrench,
    /// The surrogate's status while deflecting (saturation).
    pub status: Status,
    /// What the step did with the pose and the wrench: a glitch (not integrated, the
    /// wrench held) or a wrench scaled down to its bound; [`InsertionFlags::OK`] otherwise.
    pub flags: InsertionFlags,
    /// The phase after this tick (a glitch tick's: the last tick's).
    pub phase: Phase,
    /// Boundaries punctured in this tick.
    pub punctures: u8,
    /// The filtered axial velocity, mm/s in Q16 (positive inserting), saturated to `i32`.
    pub velocity_mm_per_s_q16: i32,
}

/// The state of one needle path through a stack, in integers: fixed size, no allocation.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Insertion<'a> {
    stack: &'a Stack,
    /// Per layer the stiffness scale in use, Q16 (the stack's, or [`Insertion::set_scales`]').
    scales_q16: [i32; MAX_LAYERS],
    /// Per layer `[s λ², s λ³]`, Q16.
    gains_q16: [[i64; 2]; MAX_LAYERS],
    rate_q16: i64,
    alpha_q16: i64,
    punctured: usize,
    track_end_q16: i64,
    track: Option<Track>,
    preload_q16: [i64; 6],
    /// The last accepted pose's depth (Q16.16).
    last_depth_q16: Option<i32>,
    /// The last accepted pose's `x`, `z`, `theta_x`, `theta_z` (Q16.16).
    accepted_q16: [i32; 4],
    /// Ticks since the last accepted pose: 1, plus one per glitch tick since (at most
    /// [`MISSED_MAX`]).
    missed: u32,
    /// The largest step per tick of `x`, `z`, `depth` (mm Q16) and of the tilts (degrees
    /// Q16), from the configuration's speeds (saturated: 65,536 mm or degrees allow any
    /// move within the domain).
    max_step_q16: [u32; 2],
    /// The configuration's period and time constant, µs (the velocity's filter after a
    /// glitch).
    period_us: u32,
    tau_us: u32,
    /// The last tick's wrench and phase: what a glitch tick holds.
    held: (Wrench, Phase),
    velocity_q16: i64,
    /// Per layer the relaxation's per-tick coefficients (computed once, in `new`).
    qlv: [QlvCoefficients; MAX_LAYERS],
    /// The viscoelastic filter of the deflected boundary's wrench (µN Q16).
    qlv_state: QlvState,
}

/// What [`Insertion::deflect`] found.
struct Deflected {
    wrench_q16: [i64; 6],
    status: Status,
    punctures: u8,
}

const X_MAX_Q16: u32 = (limits::XZ_MAX_MM as u32) << 16;
const DEPTH_MAX_Q16: u32 = (limits::DEPTH_MAX_MM as u32) << 16;
const TILT_MAX_Q16: u32 = (limits::TILT_MAX_DEG as u32) << 16;
/// The force bound, µN, and the moment bound, µN·mm (`insertion_limits`).
const FORCE_LIMIT_UN: u64 = limits::FORCE_LIMIT_N as u64 * 1_000_000;
const MOMENT_LIMIT_UNMM: i64 = limits::MOMENT_LIMIT_NMM as i64 * 1_000_000;
/// The most ticks since the last accepted pose counted (about 17 minutes at 1 kHz).
const MISSED_MAX: u32 = 1 << 20;

/// Scales the force of `w` (µN) down to its bound when it is beyond it
/// (`|fx| + |fy| + |fz| <= FORCE_LIMIT_UN`: each force component times one factor, the
/// bound over the sum in Q32 rounded down, the product rounded toward zero, so the
/// scaled sum is at most the bound); [`InsertionFlags::WRENCH_LIMITED`] when it did. The
/// moments need no scaling: three `i32` are within `MOMENT_LIMIT_UNMM` (checked below).
fn bound(w: &mut [i32; 6]) -> InsertionFlags {
    let f: u64 = w.iter().take(3).map(|c| u64::from(c.unsigned_abs())).sum();
    if f <= FORCE_LIMIT_UN {
        return InsertionFlags::OK;
    }
    // f > FORCE_LIMIT_UN > 0: the factor is below 2^32 and `|c| factor` below 2^63
    let factor = i64::try_from(div_u64(FORCE_LIMIT_UN << 32, f).unwrap_or(0)).unwrap_or(0);
    for c in w.iter_mut().take(3) {
        // |c| factor / 2^32 <= |c|: within i32
        *c = ((i64::from(*c) * factor) / (1 << 32)) as i32;
    }
    InsertionFlags::WRENCH_LIMITED
}

/// A layer's gains `[s λ², s λ³]` (Q16) into `g` from its scale `s` (Q16) and `[λ², λ³]`
/// (Q16). Out of line on the Arm cores: the eight slots' loop is unrolled, and each copy
/// is then a call with pointers (the products written out eight times took 570-620 B;
/// once per configuration, not per tick).
#[cfg_attr(target_arch = "arm", inline(never))]
fn gains_of(g: &mut [i64; 2], s: i32, &[l2, l3]: &[i64; 2]) {
    *g = [mul_shr(i64::from(s), l2, 16), mul_shr(i64::from(s), l3, 16)];
}

/// The fixed-point moments are `i32` µN·mm: their sum is within the moment bound.
const _: () = assert!(3 * (i32::MAX as i64) <= MOMENT_LIMIT_UNMM);

/// The layer's family member and softening in range (`tissue-shape` feature; without it
/// the layer carries neither: `Stack::from_f32` refuses a stack that has them).
#[cfg(feature = "tissue-shape")]
fn shape_ok(l: &Layer) -> bool {
    l.softening.in_range() && (0..=1 << 24).contains(&l.family.weight_q24())
}

#[cfg(not(feature = "tissue-shape"))]
fn shape_ok(_l: &Layer) -> bool {
    true
}

fn layer_ok(l: &Layer) -> bool {
    let k = &l.friction;
    l.thickness_q16 > 0
        && l.stiffness_scale_q16 > 0
        && l.puncture_force_q16 > 0
        && k.stick_band_q16 > 0
        && k.in_range()
        && [l.cutting_force_q16, k.static_per_speed_q16, k.coulomb_q16, k.viscous_q16, l.track_stiffness_q8].iter().all(|&v| v >= 0)
        && l.track_stiffness_q8 <= TRACK_STIFFNESS_MAX_Q8
        && l.cutting_force_q16 <= CUTTING_MAX_Q16
        && (l.cutting_per_speed_q16.saturating_mul(k.stick_band_q16) >> 16) <= CUTTING_MAX_Q16
        && shape_ok(l)
}

impl<'a> Insertion<'a> {
    /// A path through `stack`, the needle above the surface.
    ///
    /// # Errors
    /// `InsertionError::FloatOnly` (a stack with a presliding layer: `shaft-presliding`),
    /// [`InsertionError::LayerCount`] (also for a stack [`Stack::from_f32`] refused),
    /// [`InsertionError::Value`] (a value out of the tissue file's ranges after
    /// rounding, e.g. a thickness below 2^-17 mm, or beyond the integer ranges: a
    /// stiffness scale above [`STIFFNESS_SCALE_MAX`], a track stiffness above 8.4 N/mm
    /// per mm), [`InsertionError::Config`] (a zero period).
    pub fn new(stack: &'a Stack, config: InsertionConfig) -> Result<Self, InsertionError> {
        #[cfg(feature = "shaft-presliding")]
        if stack.float_only {
            return Err(InsertionError::FloatOnly);
        }
        if stack.count == 0 || stack.count > MAX_LAYERS {
            return Err(InsertionError::LayerCount);
        }
        let max_scale = (STIFFNESS_SCALE_MAX as i64) << 16;
        if !stack.layers().iter().all(|l| layer_ok(l) && l.stiffness_scale_q16 <= max_scale) || stack.inv_similarity_q30 <= 0 {
            return Err(InsertionError::Value);
        }
        #[cfg_attr(not(feature = "viscoelastic"), allow(unused_mut))]
        let mut qlv = [QlvCoefficients::NONE; MAX_LAYERS];
        #[cfg(feature = "viscoelastic")]
        for (k, l) in qlv.iter_mut().zip(stack.layers()) {
            // terms out of the integer ranges (or a zero period: `Config` below)
            *k = QlvCoefficients::new(&l.prony, config.period_us).ok_or(if config.period_us == 0 {
                InsertionError::Config
            } else {
                InsertionError::Value
            })?;
        }
        let mut scales_q16 = [0; MAX_LAYERS];
        for (s, l) in scales_q16.iter_mut().zip(stack.layers()) {
            // <= 2^30 (checked above)
            *s = l.stiffness_scale_q16 as i32;
        }
        let period = u64::from(config.period_us);
        let rate_q16 = div_u64(1_000_000_u64 << 16, period).ok_or(InsertionError::Config)?;
        let whole = period + u64::from(config.velocity_time_constant_us);
        let alpha_q16 = div_u64((period << 16) + (whole >> 1), whole).ok_or(InsertionError::Config)?;
        if config.max_speed_mm_per_s == 0 || config.max_turn_deg_per_s == 0 {
            return Err(InsertionError::Config);
        }
        // speed (mm/s) times period (µs) times 2^16 / 10^6 = 1,024 / 15,625, saturated
        let per_tick = |speed: u32| {
            u32::try_from(div_u64(u64::from(speed).saturating_mul(period).saturating_mul(1024), 15_625).unwrap_or(0)).unwrap_or(u32::MAX)
        };
        let max_step_q16 = [per_tick(config.max_speed_mm_per_s), per_tick(config.max_turn_deg_per_s)];
        let mut insertion = Self {
            stack,
            scales_q16,
            gains_q16: [[0; 2]; MAX_LAYERS],
            rate_q16: i64::try_from(rate_q16).map_err(|_| InsertionError::Config)?,
            alpha_q16: i64::try_from(alpha_q16).map_err(|_| InsertionError::Config)?,
            punctured: 0,
            track_end_q16: 0,
            track: None,
            preload_q16: [0; 6],
            last_depth_q16: None,
            accepted_q16: [0; 4],
            missed: 1,
            max_step_q16,
            period_us: config.period_us,
            tau_us: config.velocity_time_constant_us,
            held: (Wrench::ZERO, Phase::Approach),
            velocity_q16: 0,
            qlv,
            qlv_state: QlvState::REST,
        };
        insertion.update_gains();
        Ok(insertion)
    }

    /// `gains_q16` from `scales_q16` and the stack's `λ` powers (a slot past the layers
    /// keeps its zero scale and gains: the same products).
    fn update_gains(&mut self) {
        let pow = &self.stack.similarity_pow_q16;
        for (g, &s) in self.gains_q16.iter_mut().zip(&self.scales_q16) {
            gains_of(g, s, pow);
        }
    }

    /// Replaces the layers' stiffness scales (Q16.16, one per layer, each > 0 and at most
    /// [`STIFFNESS_SCALE_MAX`]); the path's state is kept.
    ///
    /// # Errors
    /// [`InsertionError::Scales`]: not one scale per layer, or one out of range; nothing
    /// is changed then.
    pub fn set_scales(&mut self, scales_q16: &[i32]) -> Result<(), InsertionError> {
        let max = (STIFFNESS_SCALE_MAX as i64) << 16;
        if scales_q16.len() != self.stack.count || !scales_q16.iter().all(|&s| s > 0 && i64::from(s) <= max) {
            return Err(InsertionError::Scales);
        }
        for (slot, &s) in self.scales_q16.iter_mut().zip(scales_q16) {
            *slot = s;
        }
        self.update_gains();
        Ok(())
    }

    /// The stack (its own scales; those in use are [`Insertion::scales_q16`]).
    #[must_use]
    pub fn stack(&self) -> &'a Stack {
        self.stack
    }

    /// The stiffness scales in use, one per layer, Q16.
    #[must_use]
    pub fn scales_q16(&self) -> &[i32] {
        self.scales_q16.get(..self.stack.count).unwrap_or(&[])
    }

    /// Forgets the path: the needle is above the surface again (no track, no velocity).
    pub fn reset(&mut self) {
        self.end_path();
        self.last_depth_q16 = None;
        self.missed = 1;
        self.held = (Wrench::ZERO, Phase::Approach);
        self.velocity_q16 = 0;
    }

    fn end_path(&mut self) {
        self.punctured = 0;
        self.track_end_q16 = 0;
        self.track = None;
        self.preload_q16 = [0; 6];
        self.qlv_state.reset();
    }

    /// One tick: the pose in, the wrench out (the f32 model's
    /// [`step`](crate::float::insertion::Insertion::step), in integers). Call it once per
    /// period of the configuration. Never panics.
    ///
    /// Never inlined: one function per image, which the no-float check of
    /// `tests/firmware_no_panic.rs` disassembles (a call costs a few instructions of
    /// the 5,000-17,000 a step takes).
    #[inline(never)]
    pub fn step(&mut self, pose: &Pose) -> InsertionEvaluation {
        let glitch = self.screen(pose);
        if !glitch.is_ok() {
            self.missed = self.missed.saturating_add(1).min(MISSED_MAX);
            // the deflected boundary's filter follows time over the held input
            if let Some(c) = self.qlv.get(self.punctured) {
                self.qlv_state.hold(c);
            }
            let (wrench, phase) = self.held;
            let velocity_mm_per_s_q16 = saturate_i32(self.velocity_q16);
            return InsertionEvaluation { wrench, status: Status::OK, flags: glitch, phase, punctures: 0, velocity_mm_per_s_q16 };
        }
        let depth = i64::from(pose.depth_mm_q16);
        let step_q16 = self.last_depth_q16.map_or(0, |last| depth - i64::from(last));
        self.filter_velocity(step_q16);
        self.last_depth_q16 = Some(pose.depth_mm_q16);
        self.accepted_q16 = [pose.x_mm_q16, pose.z_mm_q16, pose.theta_x_deg_q16, pose.theta_z_deg_q16];
        self.missed = 1;
        // friction and cutting see the velocity only when it has the last motion's sign
        let v = if (self.velocity_q16 > 0 && step_q16 > 0) || (self.velocity_q16 < 0 && step_q16 < 0) { self.velocity_q16 } else { 0 };
        if depth <= 0 {
            self.end_path();
            return self.evaluation([0; 6], Status::OK, Phase::Approach, 0);
        }
        let a = axis(pose.theta_x_deg_q16, pose.theta_z_deg_q16);
        let (x, z) = (i64::from(pose.x_mm_q16), i64::from(pose.z_mm_q16));
        let entry: Vec3 = [x, 0, z];
        let bounds = self.boundaries(a[1]);
        let Deflected { wrench_q16: mut w, status, punctures } = self.deflect(pose, depth, a, entry, &bounds);
        let phase = self.shaft(depth, a, entry, v, &bounds, &mut w);
        self.evaluation(w, status, phase, punctures)
    }

    /// The tick's evaluation: the wrench rounded to µN and µN·mm, saturated to `i32` and
    /// bounded (`bound`); it is what the next glitch tick holds.
    fn evaluation(&mut self, w_q16: [i64; 6], status: Status, phase: Phase, punctures: u8) -> InsertionEvaluation {
        let mut w = w_q16.map(|c| round_shr_i32(c, 16));
        let flags = bound(&mut w);
        let wrench = Wrench::from_array(w);
        self.held = (wrench, phase);
        InsertionEvaluation { wrench, status, flags, phase, punctures, velocity_mm_per_s_q16: saturate_i32(self.velocity_q16) }
    }

    /// The glitch flags of `pose` (the module's "Glitches"): [`InsertionFlags::OK`] to
    /// integrate it. In `u32`: magnitudes and distances of `i32` never overflow there;
    /// the largest distance of `x`, `z`, `depth` (of the tilts) against one allowance.
    fn screen(&self, pose: &Pose) -> InsertionFlags {
        let Pose { x_mm_q16: x, z_mm_q16: z, theta_x_deg_q16: tx, theta_z_deg_q16: tz, depth_mm_q16: d } = *pose;
        let (xz, tilt) = (x.unsigned_abs().max(z.unsigned_abs()), tx.unsigned_abs().max(tz.unsigned_abs()));
        if xz > X_MAX_Q16 || d.unsigned_abs() > DEPTH_MAX_Q16 || tilt > TILT_MAX_Q16 {
            return InsertionFlags::OUT_OF_DOMAIN;
        }
        let Some(last_d) = self.last_depth_q16 else { return InsertionFlags::OK };
        let [lx, lz, ltx, ltz] = self.accepted_q16;
        let [mm, deg] = self.max_step_q16.map(|s| s.saturating_mul(self.missed));
        if x.abs_diff(lx).max(z.abs_diff(lz)).max(d.abs_diff(last_d)) <= mm && tx.abs_diff(ltx).max(tz.abs_diff(ltz)) <= deg {
            InsertionFlags::OK
        } else {
            InsertionFlags::FAST_MOTION
        }
    }

    fn filter_velocity(&mut self, step_q16: i64) {
        let (raw, alpha) =
            if self.missed <= 1 { (mul_shr(step_q16, self.rate_q16, 16), self.alpha_q16) } else { self.after_glitch(step_q16) };
        self.velocity_q16 = self.velocity_q16.saturating_add(mul_shr(alpha, raw.saturating_sub(self.velocity_q16), 16));
    }

    /// The velocity's raw value and filter gain for a step over `missed` ticks (after a
    /// glitch): the step over `missed` periods, `alpha = n T / (n T + tau)` in Q16, as
    /// `2^16 - tau 2^16 / (n T + tau)` rounded (`n <= 2^20`, `T, tau < 2^32`: every value
    /// below 2^53 in `u64`, the divisor at least `T >= 1`).
    fn after_glitch(&self, step_q16: i64) -> (i64, i64) {
        let raw = div_i64(mul_shr(step_q16, self.rate_q16, 16), i64::from(self.missed)).unwrap_or(0);
        let tau = u64::from(self.tau_us);
        let whole = u64::from(self.period_us) * u64::from(self.missed) + tau;
        let held = div_u64((tau << 16) + (whole >> 1), whole).unwrap_or(0);
        (raw, (1 << 16) - i64::try_from(held).unwrap_or(0))
    }

    /// Path coordinates of the layers' upper boundaries (mm Q16) for a needle of
    /// vertical axis component `a_y` (Q30, `> 0` for tilts within ±89 degrees), and
    /// `i64::MAX` past the last layer: `(sum of the thicknesses above) 2^30 / a_y`.
    fn boundaries(&self, a_y_q30: i64) -> [i64; MAX_LAYERS + 1] {
        // cos(89°)^2 2^30 > 327,000: the division is by a positive number; `checked_div`
        // keeps the no-panic proof without relying on it
        let inv_ay_q30 = div_i64(1_i64 << 60, a_y_q30).unwrap_or(i64::MAX);
        let mut q = [i64::MAX; MAX_LAYERS + 1];
        let mut above = 0_i64;
        for (slot, l) in q.iter_mut().zip(self.stack.layers()) {
            *slot = mul_shr(above, inv_ay_q30, 30);
            above = above.saturating_add(l.thickness_q16);
        }
        q
    }

    /// The deflection of the first intact boundary, with the punctures it causes; the
    /// boundary's wrench through the layer's viscoelastic filter, reset at a puncture and
    /// when no boundary is deflected (the f32 model's rules).
    fn deflect(&mut self, pose: &Pose, depth: i64, a: Vec3, entry: Vec3, bounds: &[i64; MAX_LAYERS + 1]) -> Deflected {
        let mut punctures = 0u8;
        while self.punctured < self.stack.count {
            let (Some(&q), Some(layer), Some(&[gf, gm]), Some(qlv)) = (
                bounds.get(self.punctured),
                self.stack.layers.get(self.punctured),
                self.gains_q16.get(self.punctured),
                self.qlv.get(self.punctured),
            ) else {
                break;
            };
            if depth <= q {
                break;
            }
            let e = self.surrogate(pose, entry, depth - q);
            let [fx, fy, fz, mx, my, mz] = e.wrench.to_array().map(i64::from);
            // the forces times `s λ²`, the moments times `s λ³`
            #[cfg_attr(not(feature = "tissue-shape"), allow(unused_mut))]
            let mut fm = [sat_mul(fx, gf), sat_mul(fy, gf), sat_mul(fz, gf), sat_mul(mx, gm), sat_mul(my, gm), sat_mul(mz, gm)];
            #[cfg(feature = "tissue-shape")]
            if layer.family.weight_q24() < 1 << 24 {
                // the member's ratio at the FE depth δ/λ (the f32 model's `member_deflection`)
                let fe_depth = saturate_i32(mul_shr(depth - q, self.stack.inv_similarity_q30, 30));
                let g = crate::fixed::family::ratio(fe_depth, &layer.family).0.clamp(0, 1 << 31);
                scale_q30(&mut fm, g);
            }
            #[cfg_attr(not(feature = "tissue-shape"), allow(unused_mut))]
            let mut v = self.qlv_state.step(qlv, fm);
            let boundary = dot([v[0], v[1], v[2]], a).saturating_add(self.carried_cutting_q16());
            #[cfg(feature = "tissue-shape")]
            let soft = layer.softening;
            #[cfg(feature = "tissue-shape")]
            let critical_q16 = soft.critical_q16;
            #[cfg(not(feature = "tissue-shape"))]
            let critical_q16 = layer.puncture_force_q16;
            // the softening's factor at this force (1 without softening), for either branch
            #[cfg(feature = "tissue-shape")]
            let factor = soft.active().then(|| soft.factor_q30(boundary));
            if boundary < critical_q16 {
                #[cfg(feature = "tissue-shape")]
                if let Some(factor) = factor {
                    Softening::apply(factor, &mut v);
                }
                let [vfx, vfy, vfz, vmx, vmy, vmz] = v;
                let [px, py, pz, pmx, pmy, pmz] = self.preload_q16;
                let sum = |p: i64, x: i64| p.saturating_add(x);
                let total = [sum(px, vfx), sum(py, vfy), sum(pz, vfz), sum(pmx, vmx), sum(pmy, vmy), sum(pmz, vmz)];
                return Deflected { wrench_q16: total, status: e.status, punctures };
            }
            // the stored viscous force is released; the elastic lateral part stays,
            // softened to its share at the puncture
            self.qlv_state.reset();
            #[cfg(feature = "tissue-shape")]
            if let Some(factor) = factor {
                Softening::apply(factor, &mut fm);
            }
            let [fx, fy, fz, mx, my, mz] = fm;
            let (f, moments) = ([fx, fy, fz], [mx, my, mz]);
            let axial = dot(f, a);
            let [ax, ay, az] = a;
            // puncture: the axial force goes, the lateral force and the moments stay
            if self.track.is_none() {
                self.track = Some(Track { entry_q16: entry, axis_q30: a });
            }
            let lateral = [f[0] - mul_q30(axial, ax), f[1] - mul_q30(axial, ay), f[2] - mul_q30(axial, az)];
            for (p, x) in self.preload_q16.iter_mut().zip([lateral[0], lateral[1], lateral[2], moments[0], moments[1], moments[2]]) {
                *p = p.saturating_add(x);
            }
            self.punctured += 1;
            self.track_end_q16 = depth;
            punctures = punctures.saturating_add(1);
        }
        self.qlv_state.reset();
        Deflected { wrench_q16: self.preload_q16, status: Status::OK, punctures }
    }

    /// The FE surrogate for this stack's needle at indentation `delta_q16` (mm Q16):
    /// evaluated at `x/λ, z/λ, δ/λ` (the clamped entry point's x and z).
    fn surrogate(&self, pose: &Pose, entry: Vec3, delta_q16: i64) -> super::Evaluation {
        let inv = self.stack.inv_similarity_q30;
        let fe = Pose {
            x_mm_q16: saturate_i32(mul_shr(entry[0], inv, 30)),
            z_mm_q16: saturate_i32(mul_shr(entry[2], inv, 30)),
            depth_mm_q16: saturate_i32(mul_shr(delta_q16, inv, 30)),
            ..*pose
        };
        extended_wrench(&fe)
    }

    /// The cutting force of the last punctured layer (µN Q16; 0 before the first
    /// puncture): what the tip carries onto the next boundary.
    fn carried_cutting_q16(&self) -> i64 {
        self.punctured.checked_sub(1).and_then(|j| self.stack.layers.get(j)).map_or(0, |l| l.cutting_force_q16)
    }

    /// Friction, cutting and the track's hold on the shaft, added to `w`; the phase.
    fn shaft(&mut self, depth: i64, a: Vec3, entry: Vec3, v: i64, bounds: &[i64; MAX_LAYERS + 1], w: &mut [i64; 6]) -> Phase {
        let m = self.punctured;
        let index = |j: usize| u8::try_from(j).unwrap_or(u8::MAX);
        let bound = |j: usize| bounds.get(j).copied().unwrap_or(i64::MAX);
        if m == 0 {
            return if depth > bound(0) { Phase::Deflecting(0) } else { Phase::Approach };
        }
        let next = bound(m);
        let top = depth.min(next);
        let hub_q = depth - self.stack.hub_from_tip_q16;
        let deviation = self.track.map(|t| t.deviation(entry, a, hub_q));
        let mut axial_q16 = 0_i64;
        let mut hold = HoldSums::default();
        for (j, layer) in self.stack.layers().iter().enumerate().take(m) {
            let (q1, q2) = (bound(j), bound(j + 1).min(top));
            if q2 <= q1 {
                continue;
            }
            axial_q16 += ((q2 - q1) * layer.friction.per_mm_q16(v)) >> 16;
            hold.add(layer.track_stiffness_q8, q1, q2);
        }
        if let Some(d) = &deviation {
            d.add_hold(&hold, w);
        }
        // cutting layer m - 1, or carrying its cutting force onto boundary m
        let cutting = |v: i64| {
            self.stack.layers.get(m - 1).map_or(0, |l| {
                if v < l.friction.stick_band_q16 {
                    // 0 < v < band: below `cutting_per_speed * band <= 2^44 2^16` (`layer_ok`)
                    (l.cutting_per_speed_q16 * v) >> 16
                } else {
                    l.cutting_force_q16
                }
            })
        };
        let phase = if depth >= next {
            if v > 0 {
                axial_q16 = axial_q16.saturating_add(cutting(v));
            }
            Phase::Deflecting(index(m))
        } else if depth >= self.track_end_q16 && v > 0 {
            axial_q16 = axial_q16.saturating_add(cutting(v));
            Phase::Cutting(index(m - 1))
        } else {
            // the boundaries rise with j: the count of those above the tip by bisection
            let inside = bounds.get(1..m).map_or(0, |b| b.partition_point(|&q| q < depth));
            Phase::InTrack(index(inside))
        };
        if depth > self.track_end_q16 && depth < next {
            self.track_end_q16 = depth;
        }
        // the force on the needle opposes the motion: along +a (towards the hub) inserting
        for (wc, &ac) in w.iter_mut().zip(&a) {
            *wc = wc.saturating_add(mul_q30(axial_q16, ac));
        }
        phase
    }
}
