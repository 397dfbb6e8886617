//! Firmware example `insertion_golden`: every golden insertion trajectory, the glitch
//! paths included (`common/insertion_paths.rs`), through every compiled-in tissue stack, at 1 kHz, with
//! the insertion model; prints per path the tick count, the punctures and the FNV-1a
//! digest of every tick's output (six wrench bits, status, phase code, punctures, flags), for
//! the host to compare with its own run of the same ticks
//! (host-tests/tests/insertion_golden.rs); then the same for the fixed-point insertion
//! (`fixed::insertion`, the Q16.16 poses of the same paths), lines prefixed `fixed `.
//!
//! Output (semihosting stdout):
//!
//! ```text
//! needle-insertion-golden target=<triple> set=<SET> stacks=<n> paths=<n>
//! stack=<name> path=<i> ticks=<n> punctures=<n> digest_hi=0x<8 hex> digest_lo=0x<8 hex>
//! ...
//! fixed stack=<name> path=<i> ticks=<n> punctures=<n> digest_hi=0x<8 hex> digest_lo=0x<8 hex>
//! ...
//! needle-insertion-golden end
//! ```
#![cfg_attr(target_os = "none", no_std, no_main)]

#[cfg(target_os = "none")]
mod common;

#[cfg(target_os = "none")]
mod firmware {
    use crate::common::insertion_paths::{depth_scale, for_each_path_tick, for_each_path_tick_q16, Digest, PATH_COUNT};
    use crate::common::{exit, Out};
    use needle_haptics::fixed;
    use needle_haptics::fixed::insertion::{stacks as fixed_stacks, Insertion as FixedInsertion, InsertionConfig as FixedConfig};
    use needle_haptics::insertion::{stacks, Insertion, InsertionConfig};
    use needle_haptics::{model_info, Pose};

    /// One path's line: `<prefix><name> path=<i> ticks=<n> punctures=<n> digest_hi=.. digest_lo=..`.
    fn line(out: &mut Out, prefix: &str, name: &str, i: usize, ticks: u64, punctures: u64, digest: Digest) {
        out.str(prefix);
        out.str(name);
        out.str(" path=");
        out.dec(i as u64);
        out.str(" ticks=");
        out.dec(ticks);
        out.str(" punctures=");
        out.dec(punctures);
        out.str(" digest_hi=");
        out.hex((digest.0 >> 32) as u32, 8);
        out.str(" digest_lo=");
        out.hex(digest.0 as u32, 8);
        out.nl();
    }

    #[cortex_m_rt::entry]
    fn main() -> ! {
        let mut out = Out::new();
        out.str("needle-insertion-golden target=");
        out.str(crate::common::target_name());
        out.str(" set=");
        out.str(model_info::SET);
        out.str(" stacks=");
        out.dec(stacks::ALL.len() as u64);
        out.str(" paths=");
        out.dec(PATH_COUNT as u64);
        out.nl();
        let mut ok = true;
        for stack in &stacks::ALL {
            for i in 0..PATH_COUNT {
                let Ok(mut insertion) = Insertion::new(stack, InsertionConfig::DEFAULT_1KHZ) else {
                    ok = false;
                    continue;
                };
                let mut digest = Digest::new();
                let (mut ticks, mut punctures) = (0u64, 0u64);
                for_each_path_tick(i, depth_scale(stack), |_, p| {
                    let e = insertion.step(&Pose { x_mm: p[0], z_mm: p[1], theta_x_deg: p[2], theta_z_deg: p[3], depth_mm: p[4] });
                    digest.tick(e.wrench.to_array(), e.status.bits(), e.phase.code(), e.punctures, e.flags.bits());
                    ticks += 1;
                    punctures += u64::from(e.punctures);
                });
                line(&mut out, "stack=", stack.name, i, ticks, punctures, digest);
            }
        }
        // the fixed-point insertion on the same paths (Q16.16 poses, integer interpolation)
        for (stack, scale_of) in fixed_stacks::ALL.iter().zip(&stacks::ALL) {
            for i in 0..PATH_COUNT {
                let Ok(mut insertion) = FixedInsertion::new(stack, FixedConfig::DEFAULT_1KHZ) else {
                    ok = false;
                    continue;
                };
                let mut digest = Digest::new();
                let (mut ticks, mut punctures) = (0u64, 0u64);
                for_each_path_tick_q16(i, depth_scale(scale_of), |_, p| {
                    let e = insertion.step(&fixed::Pose::new(p[0], p[1], p[2], p[3], p[4]));
                    digest.tick_fixed(e.wrench.to_array(), e.status.bits(), e.phase.code(), e.punctures, e.flags.bits());
                    ticks += 1;
                    punctures += u64::from(e.punctures);
                });
                line(&mut out, "fixed stack=", stack.name, i, ticks, punctures, digest);
            }
        }
        out.str("needle-insertion-golden end");
        out.nl();
        out.flush();
        exit(ok)
    }
}

#[cfg(not(target_os = "none"))]
fn main() {
    eprintln!("`insertion_golden` is firmware: cargo run --release --example insertion_golden --target thumbv7em-none-eabihf");
}
