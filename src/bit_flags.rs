//! What the bit-flag types ([`Status`](crate::Status),
//! [`InsertionFlags`](crate::InsertionFlags) and
//! [`LoopFlags`](crate::control::LoopFlags)) share: the `|` operators and the
//! `NAME | NAME` text.
use core::fmt;

/// For a `struct $t($bits)` flag type: `from_bits`, `bits`, `contains`, and
/// `impl BitOr, BitOrAssign`.
macro_rules! flag_bits {
    ($t:ty, $bits:ty) => {
        impl $t {
            /// The flags from their bits (kept as given, unknown bits included).
            #[inline]
            #[must_use]
            pub const fn from_bits(bits: $bits) -> Self {
                Self(bits)
            }

            /// The bits.
            #[inline]
            #[must_use]
            pub const fn bits(self) -> $bits {
                self.0
            }

            /// `true` when every flag set in `other` is also set here.
            #[inline]
            #[must_use]
            pub const fn contains(self, other: Self) -> bool {
                self.0 & other.0 == other.0
            }
        }

        impl core::ops::BitOr for $t {
            type Output = Self;
            #[inline]
            fn bitor(self, rhs: Self) -> Self {
                Self(self.0 | rhs.0)
            }
        }

        impl core::ops::BitOrAssign for $t {
            #[inline]
            fn bitor_assign(&mut self, rhs: Self) {
                self.0 |= rhs.0;
            }
        }
    };
}
pub(crate) use flag_bits;

/// Writes the names of the flags of `named` set in `bits`, in the table's order, joined by
/// ` | `, then any set bit no name covers in hex (`0x20`, `hex_digits` wide); `OK` when
/// `bits` is 0.
pub(crate) fn write_names(f: &mut fmt::Formatter<'_>, bits: u32, named: &[(u32, &str)], hex_digits: usize) -> fmt::Result {
    if bits == 0 {
        return f.write_str("OK");
    }
    let mut first = true;
    let mut known = 0;
    for &(flag, name) in named {
        known |= flag;
        if bits & flag == flag && flag != 0 {
            if !first {
                f.write_str(" | ")?;
            }
            f.write_str(name)?;
            first = false;
        }
    }
    let unknown = bits & !known;
    if unknown != 0 {
        if !first {
            f.write_str(" | ")?;
        }
        write!(f, "{unknown:#0w$x}", w = hex_digits + 2)?;
    }
    Ok(())
}
