//! [`Stack`] and [`Layer`] in integers: the f32 tissue stacks
//! ([`crate::float::insertion::stacks`]) converted once, in `const` evaluation on the build host
//! ([`Stack::from_f32`]: the same integers on every target, no float at run time), into
//! the units the fixed-point insertion computes in.
//!
//! Units (every value rounded to nearest from the f32 value, through f64):
//!
//! | field | unit and scale |
//! | --- | --- |
//! | thickness, stick band | mm, mm/s × 2^16 (Q16.16) |
//! | stiffness scale | × 2^16 |
//! | puncture and cutting force | µN × 2^16 |
//! | friction levels | µN per mm of shaft × 2^16; the stick band's slope and the viscous term µN/mm per mm/s × 2^16 |
//! | track stiffness | µN/mm per mm of shaft × 2^8 |
//! | Prony terms | `g` × 2^16, `tau` µs ([`PronyTerms::from_f32`]) |
pub use super::softening::Softening;
use crate::fixed::depth_extension::round_i64;
pub use crate::fixed::family::FamilyMember;
#[cfg(feature = "viscoelastic")]
use crate::fixed::viscoelastic::PronyTerms;
use crate::float::insertion as f32_insertion;

/// Most layers a stack has.
pub use crate::float::insertion::MAX_LAYERS;

const Q16: f64 = 65536.0;
const MICRO: f64 = 1.0e6;

/// Shaft friction per mm of shaft, in integers ([`crate::float::insertion::Karnopp`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Karnopp {
    /// Static level over the stick band: the slope inside the band, µN/mm per mm/s, Q16.
    pub static_per_speed_q16: i64,
    /// Coulomb level above the band, µN/mm, Q16.
    pub coulomb_q16: i64,
    /// Viscous term above the band, µN/mm per mm/s, Q16.
    pub viscous_q16: i64,
    /// Half width of the stick band, mm/s, Q16 (> 0).
    pub stick_band_q16: i64,
}

impl Karnopp {
    /// Friction per mm of shaft at axial speed `v_q16` (mm/s, Q16), µN/mm in Q16: of the
    /// speed's sign, `static * |v| / band` inside the band, `coulomb + viscous |v|` above
    /// (products `floor(a b / 2^16)`; the viscous term's speed saturates at 1,024 mm/s,
    /// the level at 4.2 N/mm).
    #[inline]
    #[must_use]
    pub fn per_mm_q16(&self, v_q16: i64) -> i64 {
        // Bounds ([`Karnopp::in_range`], checked by `Insertion::new`): inside the band
        // `static_per_speed * speed < static_per_speed * band <= 2^38 2^16`; above it the
        // viscous term's speed is clamped to 2^26 and the term to 2^36: 2^62. The level
        // is clamped to 2^38 (4.2 N per mm of shaft), so times a length below 2^23
        // (128 mm) the friction force stays below 2^61.
        let speed = v_q16.unsigned_abs();
        let level = if speed < self.stick_band_q16.unsigned_abs() {
            (self.static_per_speed_q16 * speed as i64) >> 16
        } else {
            let viscous_speed = speed.min(VISCOUS_SPEED_MAX_Q16) as i64;
            self.coulomb_q16 + ((self.viscous_q16 * viscous_speed) >> 16)
        };
        let level = level.min(FRICTION_LEVEL_MAX_Q16);
        if v_q16 < 0 {
            -level
        } else {
            level
        }
    }
}

/// One layer in integers ([`crate::float::insertion::Layer`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Layer {
    /// Thickness along the vertical, mm, Q16.
    pub thickness_q16: i64,
    /// Stiffness scale s against the FE tissue, Q16.
    pub stiffness_scale_q16: i64,
    /// Axial force at which the upper boundary is punctured, µN, Q16.
    pub puncture_force_q16: i64,
    /// Axial cutting force at the tip, µN, Q16.
    pub cutting_force_q16: i64,
    /// The cutting force's ramp inside the stick band: `cutting / band`, µN per mm/s, Q16.
    pub cutting_per_speed_q16: i64,
    /// Shaft friction.
    pub friction: Karnopp,
    /// Lateral stiffness of the track, µN/mm per mm of shaft, Q8.
    pub track_stiffness_q8: i64,
    /// The boundary's relaxation function ([`crate::fixed::viscoelastic`]); only with
    /// the `viscoelastic` feature (an elastic build's layers carry none: flash).
    #[cfg(feature = "viscoelastic")]
    pub prony: PronyTerms,
    /// The material family's member ([`crate::fixed::family`]); only with the
    /// `tissue-shape` feature (a default build's layers carry none: flash).
    #[cfg(feature = "tissue-shape")]
    pub family: FamilyMember,
    /// The pre-puncture softening and the force that punctures (`tissue-shape`).
    #[cfg(feature = "tissue-shape")]
    pub softening: Softening,
}

/// A stack in integers: the layers and the needle's similarity to the FE needle.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Stack {
    /// The stack's name (its file's stem).
    pub name: &'static str,
    /// The layers from the surface down; the first `count` are used.
    pub layers: [Layer; MAX_LAYERS],
    /// Layers in use (1 to [`MAX_LAYERS`]; 0 for a stack [`Stack::from_f32`] refused).
    pub count: usize,
    /// `1 / λ` (λ: the needle's diameter over the FE needle's), Q30.
    pub inv_similarity_q30: i64,
    /// `λ^2` and `λ^3`, Q16: a layer's force and moment gains are `s λ^2`, `s λ^3`.
    pub similarity_pow_q16: [i64; 2],
    /// The hub's distance from the tip for this needle (`λ` times the FE needle's), mm, Q16.
    pub hub_from_tip_q16: i64,
    /// Whether [`Stack::from_f32`] refused the stack for a layer with a presliding (the
    /// f32 insertion's alone: [`InsertionError::FloatOnly`](crate::float::insertion::InsertionError::FloatOnly));
    /// only with the `shaft-presliding` feature.
    #[cfg(feature = "shaft-presliding")]
    pub float_only: bool,
}

/// Largest friction level (static or Coulomb), µN per mm of shaft in Q16 (2^38: 4.2 N/mm).
pub const FRICTION_LEVEL_MAX_Q16: i64 = 1 << 38;
/// Largest viscous term, µN/mm per mm/s in Q16 (2^36: 1.05 N/mm per mm/s).
pub const VISCOUS_MAX_Q16: i64 = 1 << 36;
/// Largest cutting force, µN in Q16 (2^44: 268 N).
pub const CUTTING_MAX_Q16: i64 = 1 << 44;
/// Largest stick band, mm/s in Q16 (2^31: 32,768 mm/s).
pub const STICK_BAND_MAX_Q16: i64 = 1 << 31;
/// The speed the viscous term sees is clamped here, mm/s in Q16 (2^26: 1,024 mm/s).
const VISCOUS_SPEED_MAX_Q16: u64 = 1 << 26;

impl Karnopp {
    /// Whether the friction's integer products cannot wrap: the static level (the slope
    /// times the band), the Coulomb level and the viscous term within their maxima.
    pub(super) fn in_range(&self) -> bool {
        let static_level = self.static_per_speed_q16.saturating_mul(self.stick_band_q16) >> 16;
        self.stick_band_q16 <= STICK_BAND_MAX_Q16
            && static_level <= FRICTION_LEVEL_MAX_Q16
            && self.coulomb_q16 <= FRICTION_LEVEL_MAX_Q16
            && self.viscous_q16 <= VISCOUS_MAX_Q16
    }
}

/// Largest similarity `λ` and stiffness scale the integer ranges are argued for (the
/// insertion module's overflow note); [`Stack::from_f32`] refuses a stack beyond them.
pub const SIMILARITY_MAX: f64 = 8.0;
/// Largest stiffness scale (see [`SIMILARITY_MAX`]).
pub const STIFFNESS_SCALE_MAX: f64 = 16_384.0;
/// Largest total thickness of a stack, mm (see [`SIMILARITY_MAX`]).
pub const TOTAL_THICKNESS_MAX_MM: f64 = 512.0;

const fn q16(v: f32) -> i64 {
    round_i64(v as f64 * Q16)
}

const fn micro_q16(v: f32) -> i64 {
    round_i64(v as f64 * MICRO * Q16)
}

/// `v / band` in µN per mm/s (`v` in N), Q16; 0 for a band that is not > 0 (which
/// `Insertion::new` refuses).
const fn per_speed_q16(v: f32, band: f32) -> i64 {
    if band > 0.0 {
        round_i64(v as f64 * MICRO / band as f64 * Q16)
    } else {
        0
    }
}

impl Layer {
    /// The layer in integers (the module's units). `const`: the compiled-in stacks are
    /// converted at compile time.
    #[must_use]
    pub const fn from_f32(l: &f32_insertion::Layer) -> Self {
        let band = l.friction.stick_band_mm_per_s;
        // at least 1 (1.5e-11 N) for a positive force: a boundary that punctures at
        // contact (the tissue format's smallest force) stays positive
        let puncture_force_q16 =
            if l.puncture_force_n > 0.0 && micro_q16(l.puncture_force_n) < 1 { 1 } else { micro_q16(l.puncture_force_n) };
        Self {
            thickness_q16: q16(l.thickness_mm),
            stiffness_scale_q16: q16(l.stiffness_scale),
            puncture_force_q16,
            #[cfg(feature = "tissue-shape")]
            family: FamilyMember::from_f32(&l.family),
            #[cfg(feature = "tissue-shape")]
            softening: Softening::from_f32(&l.softening, l.puncture_force_n, puncture_force_q16),
            cutting_force_q16: micro_q16(l.cutting_force_n),
            cutting_per_speed_q16: per_speed_q16(l.cutting_force_n, band),
            friction: Karnopp {
                static_per_speed_q16: per_speed_q16(l.friction.static_n_per_mm, band),
                coulomb_q16: micro_q16(l.friction.coulomb_n_per_mm),
                viscous_q16: micro_q16(l.friction.viscous_n_s_per_mm2),
                stick_band_q16: q16(l.friction.stick_band_mm_per_s),
            },
            track_stiffness_q8: round_i64(l.track_stiffness_n_per_mm2 as f64 * MICRO * 256.0),
            #[cfg(feature = "viscoelastic")]
            prony: PronyTerms::from_f32(&l.prony),
        }
    }
}

const EMPTY_LAYER: Layer = Layer {
    thickness_q16: 0,
    stiffness_scale_q16: 0,
    puncture_force_q16: 0,
    cutting_force_q16: 0,
    cutting_per_speed_q16: 0,
    friction: Karnopp { static_per_speed_q16: 0, coulomb_q16: 0, viscous_q16: 0, stick_band_q16: 0 },
    track_stiffness_q8: 0,
    #[cfg(feature = "viscoelastic")]
    prony: PronyTerms::NONE,
    #[cfg(feature = "tissue-shape")]
    family: FamilyMember::PAPER,
    #[cfg(feature = "tissue-shape")]
    softening: Softening::REFUSED,
};

impl Stack {
    /// The stack in integers; `count` 0 (which [`Insertion::new`](super::Insertion::new)
    /// refuses) for a stack with no layer or more than [`MAX_LAYERS`], a needle diameter
    /// whose `λ` is not within `1/SIMILARITY_MAX ..= SIMILARITY_MAX`, a stiffness scale
    /// above [`STIFFNESS_SCALE_MAX`], a total thickness above [`TOTAL_THICKNESS_MAX_MM`]
    /// or, without the `viscoelastic` feature, a layer with Prony terms. The other checks (positive thickness, scale, ...) are
    /// `Insertion::new`'s. `const`: the compiled-in stacks are converted at compile time.
    #[must_use]
    pub const fn from_f32(s: &f32_insertion::Stack<'static>) -> Self {
        let lambda = s.needle_diameter_mm as f64 / f32_insertion::FE_NEEDLE_DIAMETER_MM as f64;
        let refused = Self { name: s.name, ..EMPTY_STACK };
        if lambda.is_nan() || lambda > SIMILARITY_MAX || lambda * SIMILARITY_MAX < 1.0 || s.layers.is_empty() || s.layers.len() > MAX_LAYERS
        {
            return refused;
        }
        let mut layers = [EMPTY_LAYER; MAX_LAYERS];
        let mut slots: &mut [Layer] = &mut layers;
        let mut rest = s.layers;
        let mut total = 0.0;
        while let [l, tail @ ..] = rest {
            let [slot, free @ ..] = slots else { return refused };
            let scale = l.stiffness_scale as f64;
            if scale.is_nan() || scale > STIFFNESS_SCALE_MAX {
                return refused;
            }
            // an elastic build's layers carry no terms: a layer with terms is refused
            if cfg!(not(feature = "viscoelastic")) && l.prony.as_array().1 > 0 {
                return refused;
            }
            // nor, without `tissue-shape`, a family member or a softening
            if cfg!(not(feature = "tissue-shape")) && (l.family.weight() < 1.0 || l.softening.fraction != 0.0) {
                return refused;
            }
            // nor a presliding: the fixed-point insertion has none (the f32 one's alone)
            #[cfg(feature = "shaft-presliding")]
            if l.presliding.distance_mm != 0.0 {
                return Self { float_only: true, ..refused };
            }
            total += l.thickness_mm as f64;
            *slot = Layer::from_f32(l);
            slots = free;
            rest = tail;
        }
        if total.is_nan() || total > TOTAL_THICKNESS_MAX_MM {
            return refused;
        }
        Self {
            name: s.name,
            layers,
            count: s.layers.len(),
            inv_similarity_q30: round_i64((1u64 << 30) as f64 / lambda),
            similarity_pow_q16: [round_i64(lambda * lambda * Q16), round_i64(lambda * lambda * lambda * Q16)],
            hub_from_tip_q16: round_i64(f32_insertion::HUB_FROM_TIP_MM as f64 * lambda * Q16),
            #[cfg(feature = "shaft-presliding")]
            float_only: false,
        }
    }

    /// The layers in use.
    #[must_use]
    pub fn layers(&self) -> &[Layer] {
        self.layers.get(..self.count).unwrap_or(&[])
    }
}

/// The compiled-in stacks ([`crate::float::insertion::stacks::ALL`]) in integers, same order.
pub mod stacks {
    use super::Stack;
    use crate::float::insertion::stacks as f32_stacks;

    /// Every stack of the set, in integers (a `static`: an insertion borrows its stack).
    #[allow(clippy::indexing_slicing)] // const evaluation only: an index out of range is a compile error
    pub static ALL: [Stack; f32_stacks::ALL.len()] = {
        let mut out = [super::EMPTY_STACK; f32_stacks::ALL.len()];
        let mut i = 0;
        while i < out.len() {
            out[i] = Stack::from_f32(&f32_stacks::ALL[i]);
            i += 1;
        }
        out
    };

    /// The compiled-in stack named `name` (its file's stem) in integers, `None` when
    /// [`ALL`] has no such stack (the f32 twin: `float::insertion::stacks::by_name`).
    #[must_use]
    pub fn by_name(name: &str) -> Option<&'static Stack> {
        ALL.iter().find(|s| s.name == name)
    }
}

const EMPTY_STACK: Stack = Stack {
    name: "",
    layers: [EMPTY_LAYER; MAX_LAYERS],
    count: 0,
    inv_similarity_q30: 0,
    similarity_pow_q16: [0, 0],
    hub_from_tip_q16: 0,
    #[cfg(feature = "shaft-presliding")]
    float_only: false,
};
