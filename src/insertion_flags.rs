//! [`InsertionFlags`]: what the insertion step did with its tick's pose and wrench (both
//! precisions), beside the surrogate's [`Status`](crate::Status).
use core::fmt;
use needle_contract::insertion_flags as bits;

/// Bit flags of one insertion tick (`Insertion::step` in f32 and in integers).
///
/// | flag | bit | meaning |
/// | --- | --- | --- |
/// | [`FAST_MOTION`](Self::FAST_MOTION) | `0x01` | the pose moved further since the last accepted pose than the configuration's largest speeds allow: a glitch |
/// | [`OUT_OF_DOMAIN`](Self::OUT_OF_DOMAIN) | `0x02` | the pose lies outside the insertion's domain (`\|x\|, \|z\| <= 64` mm, `\|depth\| <= 128` mm, tilts `\|θ\| <= 89`°): a glitch |
/// | [`NOT_FINITE`](Self::NOT_FINITE) | `0x04` | an input was NaN or infinite: a glitch (the status is also `ERROR`) |
/// | [`WRENCH_LIMITED`](Self::WRENCH_LIMITED) | `0x08` | the force (or moment) was beyond its bound and was scaled down to it |
///
/// A *glitch* tick is not integrated as motion: no puncture, no velocity, no track
/// change (the deflected boundary's viscoelastic filter relaxes over its held input);
/// the state stays the last accepted tick's, and the wrench and phase are held at the
/// last tick's (zero and `ERROR` for a pose that is not finite).
#[derive(Clone, Copy, PartialEq, Eq, Hash, Default)]
pub struct InsertionFlags(u8);

impl InsertionFlags {
    /// The pose was accepted and the wrench was within its bound.
    pub const OK: Self = Self(bits::OK);
    /// The pose moved too fast since the last accepted one: not integrated.
    pub const FAST_MOTION: Self = Self(bits::FAST_MOTION);
    /// The pose is outside the insertion's domain: not integrated.
    pub const OUT_OF_DOMAIN: Self = Self(bits::OUT_OF_DOMAIN);
    /// An input was NaN or infinite: not integrated.
    pub const NOT_FINITE: Self = Self(bits::NOT_FINITE);
    /// The wrench was scaled down to its bound.
    pub const WRENCH_LIMITED: Self = Self(bits::WRENCH_LIMITED);
    /// Any of the three glitch flags.
    pub const GLITCH: Self = Self(bits::GLITCH);

    /// Every flag with its name, in bit order (for printing).
    pub const FLAGS: [(Self, &'static str); 4] = [
        (Self::FAST_MOTION, "FAST_MOTION"),
        (Self::OUT_OF_DOMAIN, "OUT_OF_DOMAIN"),
        (Self::NOT_FINITE, "NOT_FINITE"),
        (Self::WRENCH_LIMITED, "WRENCH_LIMITED"),
    ];

    /// `true` when no flag is set.
    #[inline]
    #[must_use]
    pub const fn is_ok(self) -> bool {
        self.0 == 0
    }

    /// `true` when the tick was a glitch (any of the three glitch flags): not integrated.
    #[inline]
    #[must_use]
    pub const fn is_glitch(self) -> bool {
        self.0 & bits::GLITCH != 0
    }
}

crate::bit_flags::flag_bits!(InsertionFlags, u8);

/// The flag names joined by ` | `, or `OK`; bits no flag names in hex.
impl fmt::Display for InsertionFlags {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let named = Self::FLAGS.map(|(flag, name)| (u32::from(flag.0), name));
        crate::bit_flags::write_names(f, u32::from(self.0), &named, 2)
    }
}

/// `InsertionFlags(0x01: FAST_MOTION)`.
impl fmt::Debug for InsertionFlags {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "InsertionFlags({:#04x}: {})", self.0, self)
    }
}

/// `InsertionFlags(0x01)` (the bits; names are in the host-side `Display`).
#[cfg(feature = "defmt")]
impl defmt::Format for InsertionFlags {
    fn format(&self, f: defmt::Formatter<'_>) {
        defmt::write!(f, "InsertionFlags({=u8:#04x})", self.0);
    }
}
