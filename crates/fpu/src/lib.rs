//! The square root of the library's f32 code ([`sqrtf`]): on a hard-float Arm target
//! (`eabihf`: the Cortex-M4F's FPv4-SP, any VFP) the FPU's `vsqrt.f32`, one instruction,
//! where `libm::sqrtf` is a software routine of about 50 executed instructions (the
//! Cortex-M4F's loop tick calls it twice: the guard's stiffness and the force limit);
//! everywhere else `libm::sqrtf`.
//!
//! Guarantee: both are the IEEE 754 square root, correctly rounded (round to nearest,
//! ties to even): the same bits for every input, NaN in for NaN out, `-0.0` for `-0.0`,
//! NaN for a negative number. So the library's f32 results stay bit for bit the same on
//! the host, the hard-float Cortex-M, the soft-float ones, the C API and wasm; the
//! firmware test `firmware_sqrt` compares the two on the Cortex-M4F (QEMU) over a sweep
//! of bit patterns and the special values.
//!
//! Why a crate of its own: the instruction is written in assembly and called through
//! the hard-float ABI (argument and result in `s0`), which needs `unsafe`; the library
//! itself forbids `unsafe` code. Stable Rust has no safe square root in `core` (`f32::sqrt`
//! is `std`'s), and `libm` has no Arm32 hardware path. `no_std`, no panics.
#![cfg_attr(not(test), no_std)]
#![deny(unsafe_code)]

/// `sqrt(x)`, correctly rounded (module docs): the FPU's instruction on a hard-float Arm
/// target, `libm::sqrtf` elsewhere.
#[must_use]
#[inline(always)]
pub fn sqrtf(x: f32) -> f32 {
    #[cfg(all(target_arch = "arm", target_abi = "eabihf"))]
    {
        hard::sqrtf(x)
    }
    #[cfg(not(all(target_arch = "arm", target_abi = "eabihf")))]
    {
        libm::sqrtf(x)
    }
}

/// The instruction: a leaf function of the hard-float procedure-call standard (AAPCS-VFP:
/// the f32 argument and result in `s0`), assembled for the FPv4-SP (`vsqrt.f32` is in
/// every VFP version). A function rather than inline assembly: Rust's inline assembly
/// takes single-precision registers only with the `vfp2` target feature enabled on the
/// function, which stable Rust does not allow on Arm.
#[cfg(all(target_arch = "arm", target_abi = "eabihf"))]
#[allow(unsafe_code)]
mod hard {
    core::arch::global_asm!(
        ".fpu fpv4-sp-d16",
        ".section .text.needle_fpu_vsqrtf,\"ax\",%progbits",
        ".global needle_fpu_vsqrtf",
        ".type needle_fpu_vsqrtf,%function",
        ".thumb_func",
        "needle_fpu_vsqrtf:",
        "vsqrt.f32 s0, s0",
        "bx lr",
        ".size needle_fpu_vsqrtf, . - needle_fpu_vsqrtf",
    );

    extern "C" {
        fn needle_fpu_vsqrtf(x: f32) -> f32;
    }

    #[inline(always)]
    pub(super) fn sqrtf(x: f32) -> f32 {
        // SAFETY: `needle_fpu_vsqrtf` is defined above for this target: it reads `s0`,
        // writes `s0` and returns, touching no memory, no other register and no flag
        // the hard-float ABI makes the caller's; every f32 is a valid argument.
        unsafe { needle_fpu_vsqrtf(x) }
    }
}

#[cfg(test)]
mod tests {
    /// On the host `sqrtf` is libm's: the special values and a sweep of bit patterns
    /// against the exactly rounded root computed in f64 (a correctly rounded f64 root
    /// rounded to f32 is the correctly rounded f32 root: 53 >= 2 * 24 + 2 bits).
    #[test]
    fn is_the_correctly_rounded_root() {
        for bits in (0u32..=u32::MAX).step_by(4_099).chain([0, 0x8000_0000, 0x7f80_0000, 0xff80_0000, 0x7fc0_0000, 1, 0x7f7f_ffff]) {
            let x = f32::from_bits(bits);
            let got = super::sqrtf(x);
            let want = (f64::from(x)).sqrt() as f32;
            assert!(got.to_bits() == want.to_bits() || (got.is_nan() && want.is_nan()), "sqrt({x:e} = {bits:#010x}): {got:e} vs {want:e}");
        }
    }
}
