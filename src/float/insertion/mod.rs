//! The whole insertion: an [`Insertion`] follows one needle path through a tissue
//! [`Stack`], tick by tick, and gives the wrench of every phase.
//!
//! **The phases** (the tip at path coordinate `depth_mm`, mm along the needle's axis
//! below the top surface; layer `j`'s upper boundary at path coordinate
//! `q_j = (sum of the thicknesses above it) / a_y`, `a_y` the vertical component of the
//! needle's axis):
//!
//! - *approach* (`depth_mm <= 0`): no contact, the zero wrench. The tip leaving the
//!   tissue ends the path: the next contact is a new insertion (new puncture).
//! - *deflecting* boundary `m` (the first not yet punctured, `depth_mm > q_m`): the FE
//!   surrogate [`extended_wrench`](crate::extended_wrench) (past 6 mm the FE depth
//!   extension) at the indentation `depth_mm - q_m`, times the
//!   layer's stiffness scale `s_m` (the scaling law), carried from the set's FE needle to
//!   the stack's by geometric similarity: with `λ = needle_diameter_mm /
//!   FE_NEEDLE_DIAMETER_MM`, the surrogate is evaluated at `x/λ, z/λ, δ/λ` (tilts
//!   unchanged) and its forces are scaled by `s λ²`, its moments by `s λ³` (the hub at
//!   `λ` times the FE needle's). Elastic for a layer without Prony terms: withdrawing
//!   gives the same force back. With terms ([`Layer::prony`]) each of the six components
//!   passes the layer's quasi-linear viscoelastic filter
//!   ([`viscoelastic`](crate::float::viscoelastic), the state in the insertion): faster
//!   indentation gives more force, a held needle feels it relax to the elastic one;
//!   withdrawing, the filter keeps running (the force falls below the elastic one). The
//!   puncture threshold compares the filtered axial force.
//! - *viscous force released*: a puncture resets the filter (the boundary's stored
//!   viscous force goes with its axial force; the lateral preload kept is the elastic
//!   one), and so does the tip leaving the boundary (moving above it, or the path
//!   ending): no stored force is pushed into the hand, and the next boundary starts
//!   from rest.
//! - *puncture*: when the deflection's axial force (along the needle, pushing it back)
//!   plus the cutting force carried from the layer above (see below) reaches the layer's
//!   `puncture_force_n`, the boundary is punctured in that tick: its axial force is gone
//!   (the cue), its lateral force and moments stay as the track's preload, so the five
//!   lateral components are continuous. A puncture can be followed by the next
//!   boundary's in the same tick (a thin layer, or a boundary weaker than the cutting
//!   force carried onto it: punctured at contact).
//! - *cutting* layer `m - 1`: while the tip advances past the deepest point it reached
//!   (the track's end), the layer's `cutting_force_n` opposes it, ramped in over the
//!   layer's stick band of speed (zero for a needle at rest).
//! - *carried cutting*: while the tip, advancing, deflects boundary `m >= 1`, the
//!   cutting force of layer `m - 1` stays on it (ramped the same way): the tissue at the
//!   boundary carries the load the tip was cutting with, so the force does not drop
//!   where the tip meets a boundary (only a puncture drops it: no false loss of
//!   resistance). Boundary `m` punctures when its deflection's axial force reaches
//!   `puncture_force_n - cutting_force_n` of the layer above (the full cutting force,
//!   whatever the speed: where it punctures does not depend on the speed).
//! - *in the track*: behind the track's end (withdrawal, or re-advance after one) only
//!   friction acts; past the end cutting resumes, with no new puncture.
//! - everywhere after the first puncture: shaft friction ([`Karnopp`]) per mm of shaft in
//!   each punctured layer, and the track's lateral hold (`track` module: springs per mm
//!   of shaft that keep it on the line it had at the first puncture).
//!
//! **Velocity** (mm/s along the axis) comes from the pose stream: the backward difference
//! of `depth_mm` over the tick's period, low-passed by a first-order filter of time
//! constant [`InsertionConfig::velocity_time_constant_s`]. Friction and cutting use it
//! only when it has the sign of the last tick's motion (else zero): they never push the
//! needle the way it last moved, so they only take energy out.
//!
//! **Glitches** (issue 66: an encoder glitch must never become a kilonewton): before a
//! tick is integrated its pose is screened ([`InsertionFlags`]). A pose outside the
//! insertion's domain (`|x|, |z| <= 64` mm, `|depth| <= 128` mm, tilts `|θ| <= 89`°:
//! `needle_contract::insertion_limits`), not finite, or one whose `x`, `z` or `depth` moved
//! further since the last accepted pose than [`InsertionConfig::max_speed_mm_per_s`]
//! times the time since it (tilts: [`InsertionConfig::max_turn_deg_per_s`]) is not
//! integrated as motion: no puncture, no velocity, no track or cutting change; the
//! deflected boundary's viscoelastic filter relaxes over its input held at the last
//! tick's (`QlvState::hold`: its state follows time); the tick's wrench and phase are
//! the last tick's (zero and `ERROR` for a pose that is not finite) and its flags say
//! why. The next pose is compared with the last accepted one over the time since it (the
//! allowance grows by one period per glitch tick, so a real move the stream lost is
//! accepted once it is within the speed), the velocity filter takes that time as its
//! step, and the viscoelastic filter takes the input's change as a ramp over it (exact
//! for a force that changed at a constant rate; docs/insertion.md, "Glitches", gives the
//! recovery). Whatever the input, `|fx| + |fy| + |fz|` stays
//! within `insertion_limits::FORCE_LIMIT_N` (100 N) and `|mx| + |my| + |mz|` within
//! `MOMENT_LIMIT_NMM` (10,000 N·mm): a larger wrench is scaled down to the bound
//! (direction kept, [`InsertionFlags::WRENCH_LIMITED`]). The model has no clock: a time
//! stamp going backwards reaches it as a pose out of order, a jump like any other.
//!
//! f32 throughout, `libm` for the trigonometry: the same bits on every target.
#[cfg(feature = "shaft-presliding")]
mod presliding;
mod softening;
mod stack;
mod track;

#[cfg(feature = "shaft-presliding")]
pub use presliding::HeldTerms;
#[cfg(feature = "tissue-shape")]
use softening::SofteningTerms;
#[cfg(feature = "shaft-presliding")]
pub use stack::Presliding;
pub use stack::{stacks, FamilyMember, Karnopp, Layer, Softening, Stack, FE_NEEDLE_DIAMETER_MM, HUB_FROM_TIP_MM, MAX_LAYERS};

use crate::float::depth_extension::extended_wrench_and_depth_rate;
#[cfg(not(feature = "viscoelastic"))]
use crate::float::viscoelastic::identity::{QlvCoefficients, QlvState};
#[cfg(feature = "viscoelastic")]
use crate::float::viscoelastic::{QlvCoefficients, QlvState};
use crate::{extended_wrench, InsertionFlags, Pose, Status, Wrench};
use needle_contract::insertion_limits as limits;
use track::{axis, dot, Track, Vec3};

/// The insertion's tick settings.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct InsertionConfig {
    /// The period of the pose stream, s (finite, > 0; 0.001 at 1 kHz).
    pub period_s: f32,
    /// Time constant of the velocity's low-pass filter, s (finite, >= 0; 0: unfiltered).
    pub velocity_time_constant_s: f32,
    /// The largest speed of `x_mm`, `z_mm` and `depth_mm`, mm/s (finite, > 0): a pose
    /// that moved further since the last accepted one is a glitch
    /// ([`InsertionFlags::FAST_MOTION`]); the device's fastest motion, 1,000 by default.
    pub max_speed_mm_per_s: f32,
    /// The largest turning speed of the tilts, degrees/s (finite, > 0; 1,000 by default).
    pub max_turn_deg_per_s: f32,
}

impl InsertionConfig {
    /// 1 kHz, velocity filtered with a 5 ms time constant (cut-off about 32 Hz: the
    /// hand's motion passes, one tick's quantisation noise of the position is averaged
    /// over five ticks).
    /// The largest speeds are `needle_contract::insertion_limits`' defaults (1 m/s and
    /// 1,000 degrees/s: 1 mm and 1 degree per tick).
    pub const DEFAULT_1KHZ: Self = Self {
        period_s: 0.001,
        velocity_time_constant_s: 0.005,
        max_speed_mm_per_s: limits::SPEED_MAX_MM_PER_S as f32,
        max_turn_deg_per_s: limits::TURN_MAX_DEG_PER_S as f32,
    };
}

/// Why an [`Insertion`] could not be made or changed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[non_exhaustive]
pub enum InsertionError {
    /// The stack has no layer or more than [`MAX_LAYERS`].
    LayerCount,
    /// A layer value is out of its range (the tissue file's checks), or the needle
    /// diameters are not finite and > 0.
    Value,
    /// The configuration's period, time constant or largest speeds are out of range.
    Config,
    /// [`Insertion::set_scales`] got a count other than the stack's layers, or a scale
    /// that is not finite and > 0.
    Scales,
    /// A layer has Prony terms and the library was built without its `viscoelastic`
    /// feature.
    NeedsViscoelastic,
    /// A layer has a presliding ([`Presliding`]), which the fixed-point insertion does
    /// not have (the f32 insertion's alone); only with the `shaft-presliding` feature.
    #[cfg(feature = "shaft-presliding")]
    FloatOnly,
}

impl core::fmt::Display for InsertionError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str(match self {
            Self::LayerCount => "tissue stack: 1 to 8 layers",
            Self::Value => "tissue stack: a value out of range (thickness, scale, puncture force, stick band > 0; the rest >= 0)",
            Self::Config => "insertion config: period_s, max_speed_mm_per_s and max_turn_deg_per_s must be finite and > 0, velocity_time_constant_s finite and >= 0",
            Self::Scales => "stiffness scales: one per layer, each finite and > 0",
            Self::NeedsViscoelastic => "tissue stack: a layer has Prony terms; build needle-haptics with its `viscoelastic` feature",
            #[cfg(feature = "shaft-presliding")]
            Self::FloatOnly => "tissue stack: a layer has a presliding (presliding_mm); the fixed-point insertion has none: use the f32 insertion",
        })
    }
}

impl core::error::Error for InsertionError {}

/// Where the tip is, as the last tick found it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Phase {
    /// Above the surface: no contact.
    #[default]
    Approach,
    /// Pressing on the upper boundary of this layer (not yet punctured).
    Deflecting(u8),
    /// Cutting through this layer (at the track's end, advancing).
    Cutting(u8),
    /// Inside the cut track, behind its end, in this layer (withdrawing, holding or
    /// re-advancing).
    InTrack(u8),
}

impl Phase {
    /// The phase as one number: `0` approach, `0x100 | layer` deflecting,
    /// `0x200 | layer` cutting, `0x300 | layer` in the track (the C API's and the golden
    /// sequences' form).
    #[must_use]
    pub const fn code(self) -> u16 {
        match self {
            Self::Approach => 0,
            Self::Deflecting(l) => 0x100 | l as u16,
            Self::Cutting(l) => 0x200 | l as u16,
            Self::InTrack(l) => 0x300 | l as u16,
        }
    }
}

/// One tick's result.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct InsertionEvaluation {
    /// The wrench on the needle (block frame; N, N·mm about the hub).
    pub wrench: Wrench,
    /// The surrogate's status while deflecting (saturation), `ERROR` for a pose that is
    /// not finite (then the wrench is zero and the state is unchanged).
    pub status: Status,
    /// What the step did with the pose and the wrench: a glitch (not integrated, the
    /// wrench held) or a wrench scaled down to its bound; [`InsertionFlags::OK`] otherwise.
    pub flags: InsertionFlags,
    /// The phase after this tick (a glitch tick's: the last tick's).
    pub phase: Phase,
    /// Boundaries punctured in this tick (0 in most ticks).
    pub punctures: u8,
    /// The filtered axial velocity, mm/s (positive inserting).
    pub velocity_mm_per_s: f32,
}

/// The wrench of a boundary indented by `indentation_mm` (along the needle) under the
/// needle `pose` (its `depth_mm` is not used): the FE surrogate scaled by `scale` and
/// carried to a needle `similarity` times the FE needle's diameter (the module's rule:
/// evaluated at `x/λ, z/λ, δ/λ`, forces times `scale λ²`, moments times `scale λ³`).
/// The status is the surrogate's (saturation beyond its domain); `ERROR` and the zero
/// wrench for a `similarity` that is not finite and > 0.
#[must_use]
pub fn deflection(pose: &Pose, indentation_mm: f32, scale: f32, similarity: f32) -> crate::Evaluation {
    deflection_at(pose, indentation_mm, scale, similarity, false).0
}

/// [`deflection`] and, with `rate`, its stiffness along the path: `|dF/dδ|` of the three
/// forces, N/mm (`s λ` times the surrogate's depth rate at `δ/λ`: [`extended_wrench_and_depth_rate`]);
/// without `rate` the stiffness is 0 and the surrogate is [`extended_wrench`]. The same
/// wrench bits either way.
fn deflection_at(pose: &Pose, indentation_mm: f32, scale: f32, similarity: f32, rate: bool) -> (crate::Evaluation, f32) {
    let lambda = similarity;
    if !positive(lambda) {
        return (crate::Evaluation { wrench: Wrench::ZERO, status: Status::ERROR }, 0.0);
    }
    let fe = Pose { x_mm: pose.x_mm / lambda, z_mm: pose.z_mm / lambda, depth_mm: indentation_mm / lambda, ..*pose };
    let (e, k) = if rate {
        let (e, [rx, ry, rz]) = extended_wrench_and_depth_rate(&fe);
        (e, needle_fpu::sqrtf(rx * rx + ry * ry + rz * rz) * scale * lambda)
    } else {
        (extended_wrench(&fe), 0.0)
    };
    let (force, moment) = (scale * lambda * lambda, scale * lambda * lambda * lambda);
    let [fx, fy, fz, mx, my, mz] = e.wrench.to_array();
    let scaled = [fx * force, fy * force, fz * force, mx * moment, my * moment, mz * moment];
    (crate::Evaluation { wrench: Wrench::from_array(scaled), status: e.status }, k)
}

/// The family member's ratio `g(δ/λ, w)` ([`crate::float::family::ratio`]) at
/// `indentation_mm` and the boundary's stiffness with it, `k g + |F|₁ |dg/dδ|` (`f1_n`:
/// `|F|₁`, the sum of the forces' magnitudes before `g`, at least the force's length, so
/// the guard's view is not below it). Out of line, scalars in and out: a stack of the
/// paper's tissue pays one compare; without the `tissue-shape` feature nothing.
#[cfg(feature = "tissue-shape")]
#[inline(never)]
fn member_gain(f1_n: f32, k: f32, indentation_mm: f32, similarity: f32, member: &FamilyMember) -> (f32, f32) {
    // similarity > 0 (checked by `Insertion::new`)
    let (g, g_rate_per_fe_mm) = crate::float::family::ratio(indentation_mm / similarity, member);
    (g, k * g + f1_n * libm::fabsf(g_rate_per_fe_mm / similarity))
}

/// The needle's unit axis from tip to hub for the pose's tilts (each clamped to ±89
/// degrees), as the insertion model computes it: `(-sin θz cos θx, cos θz cos θx, sin θx)`
/// (the [`orientation`](crate::orientation) convention) with f32 polynomials for sine and
/// cosine (error below 1e-7 against f64: the `track` module).
#[must_use]
pub fn needle_axis(pose: &Pose) -> [f32; 3] {
    axis(pose.theta_x_deg, pose.theta_z_deg)
}

/// The state of one needle path through a stack: fixed size, no allocation.
///
/// `repr(C)`, the per-tick scalars first and the per-layer tables last: a Cortex-M
/// floating-point load reaches 1,020 bytes from its base, so the fields a tick reads stay
/// within one instruction's reach of `self` (the M4F loop tick's budget).
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[repr(C)]
pub struct Insertion {
    count: usize,
    similarity: f32,
    config: InsertionConfig,
    punctured: usize,
    track_end_mm: f32,
    track: Option<Track>,
    preload: [f32; 6],
    last_depth_mm: Option<f32>,
    /// The last accepted pose's `x_mm`, `z_mm`, `theta_x_deg`, `theta_z_deg` (its depth is
    /// `last_depth_mm`): what the next pose's motion is measured from.
    accepted: [f32; 4],
    /// Time since the last accepted pose, s: the period, plus one per glitch tick since.
    elapsed_s: f32,
    /// The last tick's wrench and phase: what a glitch tick holds.
    held: (Wrench, Phase),
    velocity_mm_per_s: f32,
    /// The viscoelastic filter of the deflected boundary's wrench.
    qlv_state: QlvState,
    /// The filter's share for a guard of the last [`Insertion::step_with_stiffness`]
    /// (zero-sized without the `viscoelastic` feature; written only by that call, so
    /// `step` carries none of it).
    guard_share: FilterTerms,
    /// The shaft's presliding: per layer its coefficients and state (only with the
    /// `shaft-presliding` feature).
    #[cfg(feature = "shaft-presliding")]
    shaft: presliding::Shaft,
    /// Per layer the relaxation's per-tick coefficients (computed once, in `new`).
    qlv: [QlvCoefficients; MAX_LAYERS],
    layers: [Layer; MAX_LAYERS],
    /// Per layer the pre-puncture softening's terms and the force that punctures
    /// (computed once, in `new`; only with the `tissue-shape` feature). Last: read once
    /// per tick, through the layer's index.
    #[cfg(feature = "tissue-shape")]
    soft: [SofteningTerms; MAX_LAYERS],
}

/// What a passivity guard needs of an insertion tick beside its wrench
/// ([`Insertion::step_with_stiffness`]).
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct GuardTerms {
    /// The stiffness along the path of the boundary being deflected, N/mm: `|dF/dδ|` of
    /// its three forces (the rate of [`deflection`]) times the layer's viscoelastic
    /// filter's effective stiffness ratio `rho` (1 without Prony terms:
    /// `viscoelastic::QlvCoefficients::effective_stiffness_ratio`); 0 when no boundary
    /// is deflected (approach, or in the track short of the next boundary) and for an
    /// error.
    pub stiffness_n_per_mm: f32,
    /// The force of shaft friction and cutting in the wrench, N (block frame): it only
    /// takes energy out, so a guard leaves it as it is and limits the rest (the
    /// boundary's deflection, the preload and the track's hold: the elastic part). A
    /// presliding's held force is in neither: a spring that slips, its force and
    /// stiffness are the guard's to read apart (`held`).
    pub dissipative_n: [f32; 3],
    /// The shaft's presliding's held force, its stiffness, axis and the tick's step
    /// (only with the `shaft-presliding` feature; [`HeldTerms::NONE`] when nothing is
    /// held): elastic and slipping, rendered by the guard's own bristle.
    #[cfg(feature = "shaft-presliding")]
    pub held: HeldTerms,
}

impl GuardTerms {
    /// No stiffness, no dissipative force (nothing held).
    #[cfg(not(feature = "shaft-presliding"))]
    pub const NONE: Self = Self { stiffness_n_per_mm: 0.0, dissipative_n: [0.0; 3] };
    /// No stiffness, no dissipative force, nothing held.
    #[cfg(feature = "shaft-presliding")]
    pub const NONE: Self = Self { stiffness_n_per_mm: 0.0, dissipative_n: [0.0; 3], held: HeldTerms::NONE };
}

/// What a guard needs of the deflected boundary's viscoelastic filter: the deflected
/// layer whose coefficients it uses (read with them by [`Insertion::guard_filter`]; none when no
/// boundary with Prony terms is deflected: the insertion's filter is then at rest), the
/// unfiltered elastic deflection force `E` and the filter's part `V` of the wrench's
/// forces (filtered minus `E`). The guard renders `F - D - V` (the elastic part, a
/// function of the path) through its rule and adds its own filter run on the guarded `E`
/// (`control::passivity`). The insertion keeps it and the guard reads it
/// ([`Insertion::guard_filter`]): nothing of the filter is copied through the loop's
/// calls in a tick without one.
#[cfg(feature = "viscoelastic")]
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub(crate) struct FilterTerms {
    /// The deflected layer with Prony terms, [`FilterTerms::NO_LAYER`] for none.
    layer: u8,
    /// The boundary's deflection force before the filter, N (block frame).
    pub(crate) deflection_n: [f32; 3],
    /// The filter's part of the wrench's forces, N: the filtered deflection force
    /// minus `deflection_n`.
    pub(crate) viscous_n: [f32; 3],
}

#[cfg(feature = "viscoelastic")]
impl FilterTerms {
    /// No deflected layer with terms.
    const NO_LAYER: u8 = u8::MAX;
    /// No filter in this tick.
    pub(crate) const NONE: Self = Self { layer: Self::NO_LAYER, deflection_n: [0.0; 3], viscous_n: [0.0; 3] };

    /// No filter in this tick (the forces are not read without a layer).
    fn clear(&mut self) {
        self.layer = Self::NO_LAYER;
    }
}

/// The deflected boundary's filter as a guard reads it ([`Insertion::guard_filter`]):
/// the layer's coefficients and [`FilterTerms`]; `None` without one.
pub(crate) type FilterShare<'a> = Option<(&'a QlvCoefficients, &'a FilterTerms)>;

/// Without the `viscoelastic` feature there is no filter: nothing.
#[cfg(not(feature = "viscoelastic"))]
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub(crate) struct FilterTerms;

#[cfg(not(feature = "viscoelastic"))]
impl FilterTerms {
    /// Nothing.
    pub(crate) const NONE: Self = Self;

    /// Nothing to clear.
    fn clear(&mut self) {}
}

/// What [`Insertion::deflect`] found: the wrench so far (preload included), the
/// surrogate's status, the punctures of this tick, the deflected boundary's stiffness.
struct Deflected {
    wrench: [f32; 6],
    status: Status,
    punctures: u8,
    stiffness_n_per_mm: f32,
}

/// The guard's share of the deflected boundary's filter ([`FilterTerms`]): layer `j`
/// (whose coefficients have terms), the elastic deflection force and the filtered minus
/// the elastic one.
#[cfg(feature = "viscoelastic")]
fn filter_terms(j: usize, elastic: &[f32; 6], filtered: &[f32; 6]) -> FilterTerms {
    let layer = match u8::try_from(j) {
        Ok(layer) if layer != FilterTerms::NO_LAYER => layer,
        _ => return FilterTerms::NONE,
    };
    let [ex, ey, ez, ..] = *elastic;
    let [fx, fy, fz, ..] = *filtered;
    FilterTerms { layer, deflection_n: [ex, ey, ez], viscous_n: [fx - ex, fy - ey, fz - ez] }
}

/// Without the filter: nothing.
#[cfg(not(feature = "viscoelastic"))]
fn filter_terms(_j: usize, _elastic: &[f32; 6], _filtered: &[f32; 6]) -> FilterTerms {
    FilterTerms
}

/// Scales the wrench `w` down to its bound when it is beyond it (the module's
/// "Glitches": `|fx| + |fy| + |fz| <= FORCE_LIMIT_N`, `|mx| + |my| + |mz| <=
/// MOMENT_LIMIT_NMM`, the direction kept; a sum that is not finite gives zero), the
/// dissipative force with the force; [`InsertionFlags::WRENCH_LIMITED`] when it did.
fn bound(w: &mut [f32; 6], dissipative_n: &mut [f32; 3]) -> InsertionFlags {
    const FORCE: f32 = limits::FORCE_LIMIT_N as f32;
    const MOMENT: f32 = limits::MOMENT_LIMIT_NMM as f32;
    let abs = libm::fabsf;
    let [fx, fy, fz, mx, my, mz] = *w;
    let (f, m) = (abs(fx) + abs(fy) + abs(fz), abs(mx) + abs(my) + abs(mz));
    if f <= FORCE && m <= MOMENT {
        return InsertionFlags::OK;
    }
    // the rounding of `limit / sum` may round up: the factor keeps the scaled sum below
    let scale = |sum: f32, limit: f32| {
        if sum <= limit {
            1.0
        } else if sum.is_finite() {
            limit * 0.999_99 / sum
        } else {
            0.0
        }
    };
    let (sf, sm) = (scale(f, FORCE), scale(m, MOMENT));
    *w = [fx * sf, fy * sf, fz * sf, mx * sm, my * sm, mz * sm];
    for d in dissipative_n.iter_mut() {
        *d = if sf > 0.0 { *d * sf } else { 0.0 };
    }
    InsertionFlags::WRENCH_LIMITED
}

fn positive(v: f32) -> bool {
    v.is_finite() && v > 0.0
}

fn non_negative(v: f32) -> bool {
    v.is_finite() && v >= 0.0
}

/// The layer's family member and softening: covered by the set's FE and in range with
/// the `tissue-shape` feature; without it only the paper's tissue without softening.
fn shape_ok(l: &Layer) -> bool {
    if cfg!(feature = "tissue-shape") {
        l.family.is_covered() && l.softening.is_valid()
    } else {
        l.family.weight() >= 1.0 && l.softening.fraction == 0.0
    }
}

fn layer_ok(l: &Layer) -> bool {
    let k = &l.friction;
    #[cfg(feature = "shaft-presliding")]
    if !l.presliding.is_valid() {
        return false;
    }
    positive(l.thickness_mm)
        && positive(l.stiffness_scale)
        && positive(l.puncture_force_n)
        && positive(k.stick_band_mm_per_s)
        && shape_ok(l)
        && [l.cutting_force_n, k.static_n_per_mm, k.coulomb_n_per_mm, k.viscous_n_s_per_mm2, l.track_stiffness_n_per_mm2]
            .into_iter()
            .all(non_negative)
}

impl Insertion {
    /// A path through `stack`, the needle above the surface.
    ///
    /// # Errors
    /// [`InsertionError::LayerCount`], [`InsertionError::Value`] (the same checks as the
    /// tissue file's, for a stack built at run time), [`InsertionError::Config`].
    pub fn new(stack: &Stack<'_>, config: InsertionConfig) -> Result<Self, InsertionError> {
        if stack.layers.is_empty() || stack.layers.len() > MAX_LAYERS {
            return Err(InsertionError::LayerCount);
        }
        if !stack.layers.iter().all(layer_ok) || !positive(stack.needle_diameter_mm) || !positive(FE_NEEDLE_DIAMETER_MM) {
            return Err(InsertionError::Value);
        }
        if !positive(config.period_s)
            || !non_negative(config.velocity_time_constant_s)
            || !positive(config.max_speed_mm_per_s)
            || !positive(config.max_turn_deg_per_s)
        {
            return Err(InsertionError::Config);
        }
        if cfg!(not(feature = "viscoelastic")) && stack.layers.iter().any(|l| !l.prony.as_slice().is_empty()) {
            return Err(InsertionError::NeedsViscoelastic);
        }
        let mut qlv = [QlvCoefficients::NONE; MAX_LAYERS];
        for (k, l) in qlv.iter_mut().zip(stack.layers) {
            // a run-time stack's terms are checked like the file's (`PronyTerms::new`)
            let terms = crate::float::viscoelastic::PronyTerms::new(l.prony.as_slice()).map_err(|_| InsertionError::Value)?;
            *k = QlvCoefficients::new(&terms, config.period_s).map_err(|_| InsertionError::Config)?;
        }
        #[cfg(feature = "tissue-shape")]
        let soft = {
            let mut soft = [SofteningTerms::NONE; MAX_LAYERS];
            for (t, l) in soft.iter_mut().zip(stack.layers) {
                *t = SofteningTerms::new(l.puncture_force_n, &l.softening).ok_or(InsertionError::Value)?;
            }
            soft
        };
        #[cfg(feature = "shaft-presliding")]
        let shaft = presliding::Shaft::new(stack.layers.iter().map(|l| &l.presliding), config.period_s).ok_or(InsertionError::Value)?;
        let mut layers = [stack.layers.first().copied().ok_or(InsertionError::LayerCount)?; MAX_LAYERS];
        for (slot, l) in layers.iter_mut().zip(stack.layers) {
            *slot = *l;
        }
        Ok(Self {
            layers,
            count: stack.layers.len(),
            similarity: stack.needle_diameter_mm / FE_NEEDLE_DIAMETER_MM,
            config,
            punctured: 0,
            track_end_mm: 0.0,
            track: None,
            preload: [0.0; 6],
            last_depth_mm: None,
            accepted: [0.0; 4],
            elapsed_s: config.period_s,
            held: (Wrench::ZERO, Phase::Approach),
            velocity_mm_per_s: 0.0,
            qlv,
            #[cfg(feature = "shaft-presliding")]
            shaft,
            #[cfg(feature = "tissue-shape")]
            soft,
            qlv_state: QlvState::REST,
            guard_share: FilterTerms::NONE,
        })
    }

    /// Replaces the layers' stiffness scales (a per-trainee or per-patient setup, no
    /// rebuild); the path's state is kept.
    ///
    /// # Errors
    /// [`InsertionError::Scales`]: not one scale per layer, or one not finite and > 0;
    /// nothing is changed then.
    pub fn set_scales(&mut self, scales: &[f32]) -> Result<(), InsertionError> {
        if scales.len() != self.count || !scales.iter().copied().all(positive) {
            return Err(InsertionError::Scales);
        }
        for (l, s) in self.layers.iter_mut().zip(scales) {
            l.stiffness_scale = *s;
        }
        Ok(())
    }

    /// The layers in use (the stack's, with any scales set).
    #[must_use]
    pub fn layers(&self) -> &[Layer] {
        self.layers.get(..self.count).unwrap_or(&[])
    }

    /// Forgets the path: the needle is above the surface again (no track, no velocity).
    pub fn reset(&mut self) {
        self.end_path();
        self.last_depth_mm = None;
        self.elapsed_s = self.config.period_s;
        self.held = (Wrench::ZERO, Phase::Approach);
        self.velocity_mm_per_s = 0.0;
    }

    fn end_path(&mut self) {
        self.punctured = 0;
        self.track_end_mm = 0.0;
        self.track = None;
        self.preload = [0.0; 6];
        self.qlv_state.reset();
        #[cfg(feature = "shaft-presliding")]
        self.shaft.reset();
    }

    /// One tick: the pose (entry point on the top surface, tilts, `depth_mm` of the tip
    /// along the axis past the surface plane, negative above it) in, the wrench out.
    /// Call it once per period of the configuration.
    ///
    /// A glitch (a pose outside the domain, not finite, or moving faster than the
    /// configuration's largest speeds: the module's "Glitches") changes nothing but the
    /// time since the last accepted pose; its evaluation holds the last tick's wrench
    /// and phase (zero and `ERROR` when not finite) with the flags saying why. Whatever
    /// the pose, `|fx| + |fy| + |fz| <= 100` N and `|mx| + |my| + |mz| <= 10,000` N·mm.
    pub fn step(&mut self, pose: &Pose) -> InsertionEvaluation {
        #[cfg(feature = "shaft-presliding")]
        return self.tick(pose, false, &mut { HeldTerms::NONE }).0;
        #[cfg(not(feature = "shaft-presliding"))]
        self.tick(pose, false).0
    }

    /// [`step`](Self::step) (the same state change and the same bits) with what a
    /// passivity guard needs beside the wrench ([`GuardTerms`]): the deflected boundary's
    /// stiffness and the dissipative part of the force. The control loop's guard takes
    /// them ([`LoopCore::set_insertion`](crate::control::LoopCore::set_insertion)).
    pub fn step_with_stiffness(&mut self, pose: &Pose) -> (InsertionEvaluation, GuardTerms) {
        #[cfg(feature = "shaft-presliding")]
        {
            let mut held = HeldTerms::NONE;
            let (e, stiffness_n_per_mm, dissipative_n) = self.tick(pose, true, &mut held);
            (e, GuardTerms { stiffness_n_per_mm, dissipative_n, held })
        }
        #[cfg(not(feature = "shaft-presliding"))]
        {
            let (e, stiffness_n_per_mm, dissipative_n) = self.tick(pose, true);
            (e, GuardTerms { stiffness_n_per_mm, dissipative_n })
        }
    }

    /// The deflected boundary's filter of the last
    /// [`step_with_stiffness`](Self::step_with_stiffness) for a guard: its coefficients
    /// and the forces of [`FilterTerms`]; `None` when no boundary with Prony terms was
    /// deflected (always without the `viscoelastic` feature).
    pub(crate) fn guard_filter(&self) -> FilterShare<'_> {
        #[cfg(feature = "viscoelastic")]
        if let Some(c) = self.qlv.get(usize::from(self.guard_share.layer)) {
            return Some((c, &self.guard_share));
        }
        None
    }

    // Never inlined: LLVM 22 (rustc 1.95) crashed in register allocation on x86-64 with
    // the grown state inlined into a large caller (host-tests/tests/insertion_fixed.rs).
    #[inline(never)]
    /// The tick's evaluation, and (with `rate`; else 0) the deflected boundary's
    /// stiffness and the dissipative force of [`GuardTerms`], whose filter share it
    /// leaves in `guard_share` and (with `shaft-presliding`) its held force in
    /// `held_out` (with `rate` only; left as it is in a tick that holds nothing).
    fn tick(
        &mut self,
        pose: &Pose,
        rate: bool,
        #[cfg(feature = "shaft-presliding")] held_out: &mut HeldTerms,
    ) -> (InsertionEvaluation, f32, [f32; 3]) {
        if rate {
            self.guard_share.clear();
        }
        let glitch = self.screen(pose);
        if !glitch.is_ok() {
            self.elapsed_s += self.config.period_s;
            // the deflected boundary's filter follows time over the held input
            if let Some(c) = self.qlv.get(self.punctured) {
                self.qlv_state.hold(c);
            }
            // and so does the shaft's held force
            #[cfg(feature = "shaft-presliding")]
            self.shaft.advance(0.0);
            let (wrench, phase) = self.held;
            let e = if glitch.contains(InsertionFlags::NOT_FINITE) {
                InsertionEvaluation {
                    wrench: Wrench::ZERO,
                    status: Status::ERROR,
                    flags: glitch,
                    phase,
                    punctures: 0,
                    velocity_mm_per_s: self.velocity_mm_per_s,
                }
            } else {
                InsertionEvaluation {
                    wrench,
                    status: Status::OK,
                    flags: glitch,
                    phase,
                    punctures: 0,
                    velocity_mm_per_s: self.velocity_mm_per_s,
                }
            };
            return (e, 0.0, [0.0; 3]);
        }
        let depth = pose.depth_mm;
        let step_mm = self.last_depth_mm.map_or(0.0, |last| depth - last);
        self.filter_velocity(step_mm);
        #[cfg(feature = "shaft-presliding")]
        self.shaft.advance(step_mm);
        self.last_depth_mm = Some(depth);
        self.accepted = [pose.x_mm, pose.z_mm, pose.theta_x_deg, pose.theta_z_deg];
        self.elapsed_s = self.config.period_s;
        // friction and cutting see the velocity only when it has the last motion's sign
        let v = if self.velocity_mm_per_s * step_mm > 0.0 { self.velocity_mm_per_s } else { 0.0 };
        if depth <= 0.0 {
            self.end_path();
            self.held = (Wrench::ZERO, Phase::Approach);
            return (self.evaluation(Wrench::ZERO, Status::OK, Phase::Approach, 0), 0.0, [0.0; 3]);
        }
        let a = axis(pose.theta_x_deg, pose.theta_z_deg);
        let entry: Vec3 = [pose.x_mm, 0.0, pose.z_mm];
        let bounds = self.boundaries(a[1]);
        let Deflected { wrench: mut w, status, punctures, stiffness_n_per_mm } = self.deflect(pose, a, entry, &bounds, rate);
        let (phase, axial_n, held) = self.shaft(pose, a, entry, v, &bounds, &mut w);
        #[cfg(not(feature = "shaft-presliding"))]
        let () = held;
        let mut dissipative_n = [axial_n * a[0], axial_n * a[1], axial_n * a[2]];
        #[cfg(feature = "shaft-presliding")]
        let sum_before_n = libm::fabsf(w[0]) + libm::fabsf(w[1]) + libm::fabsf(w[2]);
        let flags = bound(&mut w, &mut dissipative_n);
        // the presliding's held force, read apart by a guard (`HeldTerms`)
        #[cfg(feature = "shaft-presliding")]
        if rate {
            let sum_after_n = libm::fabsf(w[0]) + libm::fabsf(w[1]) + libm::fabsf(w[2]);
            *held_out = HeldTerms::new(held, a, step_mm, sum_before_n, sum_after_n);
        }
        let wrench = Wrench::from_array(w);
        self.held = (wrench, phase);
        let e = InsertionEvaluation { wrench, status, flags, phase, punctures, velocity_mm_per_s: self.velocity_mm_per_s };
        (e, stiffness_n_per_mm, dissipative_n)
    }

    fn evaluation(&self, wrench: Wrench, status: Status, phase: Phase, punctures: u8) -> InsertionEvaluation {
        InsertionEvaluation { wrench, status, flags: InsertionFlags::OK, phase, punctures, velocity_mm_per_s: self.velocity_mm_per_s }
    }

    /// The glitch flags of `pose` (the module's "Glitches"): [`InsertionFlags::OK`] to
    /// integrate it. The domain's tests are written `|v| <= max`, false for NaN too.
    fn screen(&self, pose: &Pose) -> InsertionFlags {
        const XZ: f32 = limits::XZ_MAX_MM as f32;
        const DEPTH: f32 = limits::DEPTH_MAX_MM as f32;
        const TILT: f32 = limits::TILT_MAX_DEG as f32;
        let abs = libm::fabsf;
        let Pose { x_mm: x, z_mm: z, theta_x_deg: tx, theta_z_deg: tz, depth_mm: d } = *pose;
        if !(abs(x) <= XZ && abs(z) <= XZ && abs(d) <= DEPTH && abs(tx) <= TILT && abs(tz) <= TILT) {
            let finite = [x, z, tx, tz, d].into_iter().all(f32::is_finite);
            return if finite { InsertionFlags::OUT_OF_DOMAIN } else { InsertionFlags::NOT_FINITE };
        }
        let Some(last_d) = self.last_depth_mm else { return InsertionFlags::OK };
        let [lx, lz, ltx, ltz] = self.accepted;
        let mm = self.config.max_speed_mm_per_s * self.elapsed_s;
        let deg = self.config.max_turn_deg_per_s * self.elapsed_s;
        if abs(d - last_d) <= mm && abs(x - lx) <= mm && abs(z - lz) <= mm && abs(tx - ltx) <= deg && abs(tz - ltz) <= deg {
            InsertionFlags::OK
        } else {
            InsertionFlags::FAST_MOTION
        }
    }

    fn filter_velocity(&mut self, step_mm: f32) {
        let (t, tau) = (self.elapsed_s, self.config.velocity_time_constant_s);
        // t > 0 and tau >= 0 (checked in `new`; t is the period, plus periods after a
        // glitch): the divisions are by positive numbers
        let raw = step_mm / t;
        let alpha = t / (tau + t);
        self.velocity_mm_per_s += alpha * (raw - self.velocity_mm_per_s);
    }

    /// Path coordinates of the layers' upper boundaries for a needle of vertical axis
    /// component `a_y`, `+inf` past the last layer: `q_j = (sum of the thicknesses above
    /// it) / a_y` (`a_y >= cos 89°` for the clamped tilts), computed once per tick.
    fn boundaries(&self, a_y: f32) -> [f32; MAX_LAYERS + 1] {
        let mut q = [f32::INFINITY; MAX_LAYERS + 1];
        let mut above = 0.0f32;
        for (slot, l) in q.iter_mut().zip(self.layers()) {
            *slot = above / a_y;
            above += l.thickness_mm;
        }
        q
    }

    /// The deflection of the first intact boundary, with the punctures it causes.
    ///
    /// The boundary's wrench passes the layer's viscoelastic filter (the `viscoelastic`
    /// module; its stiffness times the filter's effective stiffness ratio `rho`,
    /// [`QlvCoefficients::effective_stiffness_ratio`], and with `rate` the filter's
    /// share for a guard: [`GuardTerms`]). A puncture
    /// releases the boundary's stored viscous force (the filter is reset: the lateral
    /// part kept as preload is the elastic one), as does the tip leaving the boundary
    /// (no deflected boundary in this tick): nothing stored is pushed into the hand.
    ///
    /// With `tissue-shape` (the M4F's loop tick, issue 64): a member other than the
    /// paper's tissue is `w < 1` on the bits (`new` checked `0 < w <= 1`: an integer test,
    /// not a float compare, for every layer of every stack); the softening is looked up
    /// after the filter (nothing of it is live across the filter's step) at
    /// `punctured % MAX_LAYERS`, which is `punctured` (`punctured < count <= MAX_LAYERS`,
    /// the loop's condition) and which the compiler sees in range (no test per tick).
    fn deflect(&mut self, pose: &Pose, a: Vec3, entry: Vec3, bounds: &[f32; MAX_LAYERS + 1], rate: bool) -> Deflected {
        let mut punctures = 0u8;
        while self.punctured < self.count {
            let q = bounds.get(self.punctured).copied().unwrap_or(f32::INFINITY);
            if pose.depth_mm <= q {
                break;
            }
            let (Some(layer), Some(qlv)) = (self.layers.get(self.punctured), self.qlv.get(self.punctured)) else { break };
            let indentation_mm = pose.depth_mm - q;
            #[cfg_attr(not(feature = "tissue-shape"), allow(unused_mut))]
            let (e, mut k) = deflection_at(pose, indentation_mm, layer.stiffness_scale, self.similarity, rate);
            #[cfg_attr(not(feature = "tissue-shape"), allow(unused_mut))]
            let mut elastic = e.wrench.to_array();
            #[cfg(feature = "tissue-shape")]
            if layer.family.weight().to_bits() < 1.0f32.to_bits() {
                let f1_n = libm::fabsf(elastic[0]) + libm::fabsf(elastic[1]) + libm::fabsf(elastic[2]);
                let g;
                (g, k) = member_gain(f1_n, k, indentation_mm, self.similarity, &layer.family);
                elastic = elastic.map(|x| x * g);
            }
            #[cfg_attr(not(feature = "tissue-shape"), allow(unused_mut))]
            let mut w = self.qlv_state.step(qlv, elastic);
            let axial_n = dot([w[0], w[1], w[2]], a);
            let boundary_n = axial_n + self.carried_cutting_n();
            #[cfg(feature = "tissue-shape")]
            let Some(soft) = self.soft.get(self.punctured % MAX_LAYERS) else {
                break;
            };
            #[cfg(feature = "tissue-shape")]
            let critical_n = soft.critical_n;
            #[cfg(not(feature = "tissue-shape"))]
            let critical_n = layer.puncture_force_n;
            if boundary_n < critical_n {
                #[cfg(feature = "tissue-shape")]
                if soft.active() {
                    // the tissue starting to fail: the boundary's wrench (and the guard's view
                    // of it) loses its share; the filter's state keeps the unsoftened one
                    let factor = soft.factor(boundary_n);
                    w = w.map(|x| x * factor);
                    elastic = elastic.map(|x| x * factor);
                    k *= factor;
                }
                let mut total = self.preload;
                for (t, x) in total.iter_mut().zip(w) {
                    *t += x;
                }
                if rate && qlv.is_active() {
                    self.guard_share = filter_terms(self.deflected_index(), &elastic, &w);
                }
                return Deflected { wrench: total, status: e.status, punctures, stiffness_n_per_mm: k * qlv.effective_stiffness_ratio() };
            }
            // the boundary's state at the puncture: softened to its share there
            #[cfg(feature = "tissue-shape")]
            let w = if soft.active() { elastic.map(|x| x * soft.factor(boundary_n)) } else { elastic };
            #[cfg(not(feature = "tissue-shape"))]
            let w = elastic;
            let axial_n = dot([w[0], w[1], w[2]], a);
            self.qlv_state.reset();
            // puncture: the axial force goes, the lateral force and the moments stay
            if self.track.is_none() {
                self.track = Some(Track { entry_mm: entry, axis: a });
            }
            let lateral = [w[0] - axial_n * a[0], w[1] - axial_n * a[1], w[2] - axial_n * a[2]];
            for (p, x) in self.preload.iter_mut().zip([lateral[0], lateral[1], lateral[2], w[3], w[4], w[5]]) {
                *p += x;
            }
            self.punctured += 1;
            self.track_end_mm = pose.depth_mm;
            #[cfg(feature = "shaft-presliding")]
            self.shaft.punctured(pose.depth_mm);
            punctures = punctures.saturating_add(1);
        }
        self.qlv_state.reset();
        Deflected { wrench: self.preload, status: Status::OK, punctures, stiffness_n_per_mm: 0.0 }
    }

    /// The deflected boundary's layer, `punctured`, for the guard's filter share: with
    /// `tissue-shape` as `punctured % MAX_LAYERS` (the same index, `punctured < count <=
    /// MAX_LAYERS`), which the compiler sees in range, so `filter_terms` tests no range
    /// (the epidural's guarded surface tick 1,725.9 -> 1,718.9); the default build's code
    /// as it was (there the same change moved other ticks by one instruction).
    #[inline(always)]
    fn deflected_index(&self) -> usize {
        if cfg!(feature = "tissue-shape") {
            self.punctured % MAX_LAYERS
        } else {
            self.punctured
        }
    }

    /// The cutting force of the last punctured layer (N; 0 before the first puncture):
    /// what the tip carries onto the next boundary.
    fn carried_cutting_n(&self) -> f32 {
        self.punctured.checked_sub(1).and_then(|j| self.layers.get(j)).map_or(0.0, |l| l.cutting_force_n)
    }

    /// Friction, cutting and the track's hold on the shaft, added to `w`; the phase, the
    /// axial force of Karnopp friction and ramped cutting (N, along `+a`: dissipative)
    /// and, with `shaft-presliding`, the presliding's held force and its stiffness (N
    /// along `+a`, N/mm).
    fn shaft(&mut self, pose: &Pose, a: Vec3, entry: Vec3, v: f32, bounds: &[f32; MAX_LAYERS + 1], w: &mut [f32; 6]) -> (Phase, f32, Held) {
        let depth = pose.depth_mm;
        let m = self.punctured;
        let index = |j: usize| u8::try_from(j).unwrap_or(u8::MAX);
        let bound = |j: usize| bounds.get(j).copied().unwrap_or(f32::INFINITY);
        if m == 0 {
            return (if depth > bound(0) { Phase::Deflecting(0) } else { Phase::Approach }, 0.0, NO_HELD);
        }
        let next = bound(m);
        let top = if depth < next { depth } else { next };
        let hub_q = depth - HUB_FROM_TIP_MM * self.similarity;
        let deviation = self.track.map(|t| t.deviation(entry, a, hub_q));
        let mut axial_n = 0.0f32;
        // the presliding's held force and its stiffness
        #[cfg(feature = "shaft-presliding")]
        let mut held = (0.0f32, 0.0f32);
        for j in 0..m {
            let (Some(layer), lo) = (self.layers.get(j), bound(j)) else { break };
            let hi = bound(j + 1);
            let (q1, q2) = (lo, if hi < top { hi } else { top });
            if q2 <= q1 {
                // the tip above the layer: its tissue lets go of the shaft
                #[cfg(feature = "shaft-presliding")]
                self.shaft.release(j);
                continue;
            }
            #[cfg(feature = "shaft-presliding")]
            let track_k = layer.track_stiffness_n_per_mm2;
            #[cfg(feature = "shaft-presliding")]
            self.add_friction(j, v, q2 - q1, (&mut held, &mut axial_n));
            #[cfg(not(feature = "shaft-presliding"))]
            let track_k = {
                axial_n += (q2 - q1) * layer.friction.per_mm(v);
                layer.track_stiffness_n_per_mm2
            };
            if let Some(d) = &deviation {
                d.add_hold(track_k, q1, q2, w);
            }
        }
        // cutting layer m - 1, or carrying its cutting force onto boundary m: ramped in
        // over the stick band (or, with a presliding, held at the tip)
        #[cfg(feature = "shaft-presliding")]
        let held_cutting = self.held_cutting(m, depth);
        let cutting = |v: f32| {
            let layer = self.layers.get(m - 1);
            #[cfg(feature = "shaft-presliding")]
            let layer = layer.filter(|_| held_cutting.is_none());
            layer.map_or(0.0, |l| {
                let ramp = v / l.friction.stick_band_mm_per_s;
                l.cutting_force_n * if ramp < 1.0 { ramp } else { 1.0 }
            })
        };
        let phase = if depth >= next {
            if v > 0.0 {
                axial_n += cutting(v);
            }
            Phase::Deflecting(index(m))
        } else if depth >= self.track_end_mm && v > 0.0 {
            axial_n += cutting(v);
            Phase::Cutting(index(m - 1))
        } else {
            let inside = (1..m).take_while(|&j| bound(j) < depth).count();
            Phase::InTrack(index(inside))
        };
        #[cfg(feature = "shaft-presliding")]
        let (total, held) = {
            let (c, k) = held_cutting.unwrap_or((0.0, 0.0));
            (axial_n + held.0 + c, (held.0 + c, held.1 + k))
        };
        #[cfg(not(feature = "shaft-presliding"))]
        let (total, held) = (axial_n, NO_HELD);
        if depth > self.track_end_mm && depth < next {
            self.track_end_mm = depth;
        }
        // the force on the needle opposes the motion: along +a (towards the hub) inserting
        w[0] += total * a[0];
        w[1] += total * a[1];
        w[2] += total * a[2];
        (phase, axial_n, held)
    }

    /// Layer `j`'s friction over `length_mm` of shaft in it at speed `v`, added to `to`: a
    /// presliding's ([`presliding::Shaft::held_friction`]) to the held force and its
    /// stiffness (N, N/mm), else the Karnopp friction to the axial force (N).
    #[cfg(feature = "shaft-presliding")]
    fn add_friction(&mut self, j: usize, v: f32, length_mm: f32, to: (&mut (f32, f32), &mut f32)) {
        let Some(&Layer { friction: k, thickness_mm, .. }) = self.layers.get(j) else { return };
        let levels = [k.coulomb_n_per_mm, k.static_n_per_mm, k.viscous_n_s_per_mm2];
        match self.shaft.held_friction(j, levels, v, length_mm, thickness_mm) {
            Some((f, stiffness)) => *to.0 = (to.0 .0 + f, to.0 .1 + stiffness),
            None => *to.1 += length_mm * k.per_mm(v),
        }
    }

    /// The cutting force of layer `m - 1` held at the tip at `depth_mm` and its stiffness
    /// (N, N/mm), `None` when the layer has no presliding (its cutting is ramped).
    #[cfg(feature = "shaft-presliding")]
    fn held_cutting(&self, m: usize, depth_mm: f32) -> Option<(f32, f32)> {
        let j = m.checked_sub(1)?;
        let l = self.layers.get(j)?;
        let c = self.shaft.cutting(j, l.cutting_force_n, depth_mm, self.track_end_mm)?;
        Some((c, self.shaft.stiffness(j, l.cutting_force_n)))
    }
}

/// The presliding's held force and its stiffness a shaft step reports (N along `+a`,
/// N/mm; nothing without the `shaft-presliding` feature).
#[cfg(feature = "shaft-presliding")]
type Held = (f32, f32);
#[cfg(feature = "shaft-presliding")]
const NO_HELD: Held = (0.0, 0.0);
/// Nothing without the `shaft-presliding` feature.
#[cfg(not(feature = "shaft-presliding"))]
type Held = ();
#[cfg(not(feature = "shaft-presliding"))]
const NO_HELD: Held = ();
