//! [`Status`]: what an evaluation had to do to its input, as bit flags.
use core::fmt;

/// Status of an evaluation: bit flags, `0` ([`Status::OK`]) when the pose was inside the
/// domain and the model is present.
///
/// | flag | bit | meaning |
/// | --- | --- | --- |
/// | [`SAT_X`](Self::SAT_X) | `0x01` | `x_mm` was outside `±12` and was clamped |
/// | [`SAT_Z`](Self::SAT_Z) | `0x02` | `z_mm` was outside `±12` and was clamped |
/// | [`SAT_THETA_X`](Self::SAT_THETA_X) | `0x04` | `theta_x_deg` was outside `±15` and was clamped |
/// | [`SAT_THETA_Z`](Self::SAT_THETA_Z) | `0x08` | `theta_z_deg` was outside `±15` and was clamped |
/// | [`SAT_DEPTH`](Self::SAT_DEPTH) | `0x10` | `depth_mm` was outside `0..=6` and was clamped |
/// | [`FE_UNSOLVED`](Self::FE_UNSOLVED) | `0x20` | the (clamped) pose lies in the region where the set's FE campaign could not solve: the wrench is the model's extrapolation |
/// | [`NO_MODEL`](Self::NO_MODEL) | `0x40` | the library was built without a fitted model (always with `ERROR`) |
/// | [`ERROR`](Self::ERROR) | `0x80` | no wrench: an input was NaN or infinite, or `NO_MODEL`; the wrench is zero |
///
/// A saturated evaluation is still a valid wrench (of the clamped pose), and so is one
/// flagged [`FE_UNSOLVED`](Self::FE_UNSOLVED): neither zeroes the wrench.
#[derive(Clone, Copy, PartialEq, Eq, Hash, Default)]
pub struct Status(u8);

impl Status {
    /// Nothing to report: the pose was in the domain.
    pub const OK: Self = Self(needle_contract::status::OK);
    /// `x_mm` was clamped to `±X_MAX_MM`.
    pub const SAT_X: Self = Self(needle_contract::status::SAT_X);
    /// `z_mm` was clamped to `±Z_MAX_MM`.
    pub const SAT_Z: Self = Self(needle_contract::status::SAT_Z);
    /// `theta_x_deg` was clamped to `±THETA_MAX_DEG`.
    pub const SAT_THETA_X: Self = Self(needle_contract::status::SAT_THETA_X);
    /// `theta_z_deg` was clamped to `±THETA_MAX_DEG`.
    pub const SAT_THETA_Z: Self = Self(needle_contract::status::SAT_THETA_Z);
    /// `depth_mm` was clamped to `0..=DEPTH_MAX_MM`.
    pub const SAT_DEPTH: Self = Self(needle_contract::status::SAT_DEPTH);
    /// The pose (after clamping) lies in the set's unsolved region: near a pose whose FE
    /// run failed every attempt, deeper than that run reached (`coeffs/README.md`, "The
    /// unsolved region"; the set's `unsolved.toml`). The wrench is still computed: it is
    /// the model's extrapolation from the runs that solved, with no FE result to back it.
    pub const FE_UNSOLVED: Self = Self(needle_contract::status::FE_UNSOLVED);
    /// The library has no fitted model (its set had no `model.toml` at build time).
    /// Always reported together with [`ERROR`](Self::ERROR).
    pub const NO_MODEL: Self = Self(needle_contract::status::NO_MODEL);
    /// No wrench could be computed; the wrench is zero. Alone when an input was NaN or
    /// infinite, with [`NO_MODEL`](Self::NO_MODEL) when there is no model.
    pub const ERROR: Self = Self(needle_contract::status::ERROR);
    /// All five saturation flags.
    pub const SATURATION: Self = Self(needle_contract::status::SATURATION);

    /// Every flag with its name, in bit order (for printing).
    pub const FLAGS: [(Self, &'static str); 8] = [
        (Self::SAT_X, "SAT_X"),
        (Self::SAT_Z, "SAT_Z"),
        (Self::SAT_THETA_X, "SAT_THETA_X"),
        (Self::SAT_THETA_Z, "SAT_THETA_Z"),
        (Self::SAT_DEPTH, "SAT_DEPTH"),
        (Self::FE_UNSOLVED, "FE_UNSOLVED"),
        (Self::NO_MODEL, "NO_MODEL"),
        (Self::ERROR, "ERROR"),
    ];

    /// `true` when no flag is set: the pose was in the domain and the wrench is the model's.
    #[inline]
    #[must_use]
    pub const fn is_ok(self) -> bool {
        self.0 == 0
    }

    /// `true` when [`ERROR`](Self::ERROR) is set: the wrench is zero, not a model value.
    #[inline]
    #[must_use]
    pub const fn is_error(self) -> bool {
        self.0 & Self::ERROR.0 != 0
    }

    /// `true` when the pose lies in the set's unsolved region ([`FE_UNSOLVED`](Self::FE_UNSOLVED)).
    #[inline]
    #[must_use]
    pub const fn fe_unsolved(self) -> bool {
        self.0 & Self::FE_UNSOLVED.0 != 0
    }

    /// `true` when at least one input was clamped to the domain (any `SAT_*` flag).
    #[inline]
    #[must_use]
    pub const fn saturated(self) -> bool {
        self.0 & Self::SATURATION.0 != 0
    }
}

crate::bit_flags::flag_bits!(Status, u8);

/// The flag names joined by ` | `, or `OK` (for example `SAT_X | SAT_DEPTH`); bits no
/// flag names in hex.
impl fmt::Display for Status {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let named = Self::FLAGS.map(|(flag, name)| (u32::from(flag.0), name));
        crate::bit_flags::write_names(f, u32::from(self.0), &named, 2)
    }
}

/// `Status(0x11: SAT_X | SAT_DEPTH)`.
impl fmt::Debug for Status {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "Status({:#04x}: {})", self.0, self)
    }
}

/// `Status(0x11)` (the bits; names are in the host-side `Display`).
#[cfg(feature = "defmt")]
impl defmt::Format for Status {
    fn format(&self, f: defmt::Formatter<'_>) {
        defmt::write!(f, "Status({=u8:#04x})", self.0);
    }
}
