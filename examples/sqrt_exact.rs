//! Firmware example `sqrt_exact`: the library's square root ([`needle_fpu::sqrtf`], the
//! FPU's `vsqrt.f32` on a hard-float Cortex-M) against `libm::sqrtf` (the software root
//! every other target uses): the same bits, or the library's f32 results would differ
//! between the Cortex-M4F and the host. Both are meant to be the correctly rounded IEEE
//! root; this compares them on the device, over every 4,099th bit pattern (1,047,809
//! values: both signs, zeros, subnormals, normals, infinities, NaNs) and the special
//! values, and counts the executed instructions of one root each way (as `bench`).
//!
//! ```text
//! cargo run --release --example sqrt_exact --target thumbv7em-none-eabihf
//! ```
//!
//! Output: `needle-sqrt target=... deterministic=yes|no`, `needle-sqrt compared=<n>
//! differing=<n>` (NaN against NaN counts as equal), the first differing input if any
//! (`needle-sqrt differs x=0x... fpu=0x... libm=0x...`), then one line per root
//! `needle-sqrt what=fpu|libm instructions=<n.n>`, then `needle-sqrt end`.
#![cfg_attr(target_os = "none", no_std, no_main)]

#[cfg(target_os = "none")]
mod common;

#[cfg(target_os = "none")]
mod firmware {
    use crate::common::icount::{elapsed, Calibration};
    use crate::common::{exit, target_name, Out};
    use core::hint::black_box;
    use cortex_m::peripheral::SYST;

    const CALLS: u32 = 256;
    const SPECIAL: [u32; 8] = [0, 0x8000_0000, 1, 0x7f7f_ffff, 0x7f80_0000, 0xff80_0000, 0x7fc0_0000, 0x3f80_0000];

    fn same(a: f32, b: f32) -> bool {
        a.to_bits() == b.to_bits() || (a.is_nan() && b.is_nan())
    }

    #[inline(never)]
    fn time(root: fn(f32) -> f32, calls: u32) -> u32 {
        let start = SYST::get_current();
        for k in 0..calls {
            black_box(root(black_box(k as f32 + 0.5)));
        }
        elapsed(start, SYST::get_current())
    }

    #[inline(never)]
    fn time_empty(calls: u32) -> u32 {
        let start = SYST::get_current();
        for k in 0..calls {
            black_box(black_box(k as f32 + 0.5));
        }
        elapsed(start, SYST::get_current())
    }

    #[cortex_m_rt::entry]
    fn main() -> ! {
        let Some(mut cp) = cortex_m::Peripherals::take() else { exit(false) };
        let cal = Calibration::start(&mut cp.SYST);
        let mut out = Out::new();
        out.str("needle-sqrt target=");
        out.str(target_name());
        out.str(if cal.deterministic { " deterministic=yes\n" } else { " deterministic=no\n" });
        let (mut compared, mut differing, mut first) = (0u64, 0u64, None);
        let sweep = (0..=u32::MAX).step_by(4_099).chain(SPECIAL);
        for bits in sweep {
            let x = f32::from_bits(bits);
            let (fpu, soft) = (needle_fpu::sqrtf(black_box(x)), libm::sqrtf(black_box(x)));
            compared += 1;
            if !same(fpu, soft) {
                differing += 1;
                first = first.or(Some((bits, fpu.to_bits(), soft.to_bits())));
            }
        }
        out.str("needle-sqrt compared=");
        out.dec(compared);
        out.str(" differing=");
        out.dec(differing);
        out.str("\n");
        if let Some((x, a, b)) = first {
            out.str("needle-sqrt differs x=");
            out.hex(x, 8);
            out.str(" fpu=");
            out.hex(a, 8);
            out.str(" libm=");
            out.hex(b, 8);
            out.str("\n");
        }
        let empty = time_empty(CALLS);
        for (what, root) in [("fpu", needle_fpu::sqrtf as fn(f32) -> f32), ("libm", libm::sqrtf as fn(f32) -> f32)] {
            let tenths = cal.tenths_per_call(time(black_box(root), CALLS), empty, CALLS);
            out.str("needle-sqrt what=");
            out.str(what);
            out.str(" instructions=");
            out.tenths(tenths);
            out.str("\n");
        }
        out.str("needle-sqrt end\n");
        out.flush();
        exit(differing == 0)
    }
}

/// On the host this example does nothing: it is firmware.
#[cfg(not(target_os = "none"))]
fn main() {
    eprintln!("`sqrt_exact` is firmware: cargo run --release --example sqrt_exact --target thumbv7em-none-eabihf");
}
