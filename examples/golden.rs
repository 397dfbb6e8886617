//! Firmware example `golden`: evaluates every pose of the compiled-in set's
//! `golden-f32.csv` on the target and prints the results' bits, then every pose of its
//! `golden-fixed.csv` with the fixed-point evaluator and prints the integers, then the
//! stiffness of every pose of `golden-f32.csv` (`wrench_and_stiffness`) and of every pose
//! of `golden-fixed.csv` (`fixed::wrench_and_stiffness`), for the
//! host to compare with the golden files (host-tests/tests/firmware_golden.rs,
//! `needle firmware golden`).
//!
//! The poses are parsed from the CSV *at compile time* (const evaluation of
//! `include_str!` of `$NEEDLE_SET_DIR/golden-f32.csv`, the set build.rs selected) into a
//! `[[u32; 5]; ROWS]` table of f32 bits: the firmware holds the inputs only (20 bytes a
//! pose), never the expected outputs, and parses nothing at run time.
//!
//! Output (semihosting stdout), every line `\n`-terminated:
//!
//! ```text
//! needle-golden target=<target triple> set=<SET> fe_sha256=<hex> rows=<ROWS>
//! x_mm,z_mm,theta_x_deg,theta_z_deg,depth_mm,status,fx_n,fy_n,fz_n,mx_nmm,my_nmm,mz_nmm
//! <one row per pose in the golden file's format: inputs as read, status and wrench as computed>
//! needle-golden end rows=<ROWS>
//! needle-golden-fixed rows=<FIXED_ROWS>
//! <one row per pose in golden-fixed.csv's format: inputs as read, status and wrench as computed>
//! needle-golden-fixed end rows=<FIXED_ROWS>
//! needle-golden-stiffness rows=<ROWS>
//! <one row per pose of golden-f32.csv in golden-stiffness-f32.csv's format: inputs, status, 18 rates>
//! needle-golden-stiffness end rows=<ROWS> wrench_differs=<rows whose wrench_and_stiffness wrench is not wrench()'s>
//! needle-golden-stiffness-fixed rows=<FIXED_ROWS>
//! <one row per pose of golden-fixed.csv in golden-stiffness-fixed.csv's format: inputs, status, 18 integer rates>
//! needle-golden-stiffness-fixed end rows=<FIXED_ROWS> wrench_differs=<rows whose fixed::wrench_and_stiffness wrench is not fixed::wrench()'s>
//! ```
//!
//! ```text
//! cargo run --release --example golden --target thumbv7em-none-eabihf
//! ```
#![cfg_attr(target_os = "none", no_std, no_main)]
// The CSV parser runs in const evaluation only: its panics and out-of-bounds indexing are
// compile errors naming the malformed golden file, never run-time panics.
#![allow(clippy::indexing_slicing, clippy::panic)]

#[cfg(target_os = "none")]
mod common;

#[cfg(target_os = "none")]
mod firmware {
    use crate::common::{exit, Out};
    use core::hint::black_box;
    use needle_haptics::{fixed, model_info, wrench, wrench_and_stiffness, Pose};

    const HEADER: &str = "x_mm,z_mm,theta_x_deg,theta_z_deg,depth_mm,status,fx_n,fy_n,fz_n,mx_nmm,my_nmm,mz_nmm";

    /// The golden file of the set this build compiled in; used in const evaluation only
    /// (it is not in the firmware image).
    const CSV: &[u8] = include_bytes!(concat!(env!("NEEDLE_SET_DIR"), "/golden-f32.csv"));

    /// Number of data rows (lines after the header).
    const ROWS: usize = count_rows(CSV);

    /// The five input bits (x, z, theta_x, theta_z, depth) of every row, in file order.
    static POSES: [[u32; 5]; ROWS] = parse_poses(CSV);

    const fn header_len(s: &[u8]) -> usize {
        let h = HEADER.as_bytes();
        if s.len() <= h.len() || s[h.len()] != b'\n' {
            panic!("golden-f32.csv: the first line is not the golden-file header");
        }
        let mut i = 0;
        while i < h.len() {
            if s[i] != h[i] {
                panic!("golden-f32.csv: the first line is not the golden-file header");
            }
            i += 1;
        }
        h.len() + 1
    }

    const fn count_rows(s: &[u8]) -> usize {
        let mut i = header_len(s);
        let mut rows = 0;
        while i < s.len() {
            if s[i] == b'\n' {
                rows += 1;
            }
            i += 1;
        }
        if s[s.len() - 1] != b'\n' {
            panic!("golden-f32.csv: no final newline");
        }
        rows
    }

    const fn hex_digit(b: u8) -> u32 {
        match b {
            b'0'..=b'9' => (b - b'0') as u32,
            b'a'..=b'f' => (b - b'a' + 10) as u32,
            _ => panic!("golden-f32.csv: an input is not 0x and 8 lower-case hex digits"),
        }
    }

    const fn parse_poses<const N: usize>(s: &[u8]) -> [[u32; 5]; N] {
        let mut out = [[0u32; 5]; N];
        let mut i = header_len(s);
        let mut r = 0;
        while r < N {
            let mut f = 0;
            while f < 5 {
                if s[i] != b'0' || s[i + 1] != b'x' || s[i + 10] != b',' {
                    panic!("golden-f32.csv: an input is not 0x and 8 lower-case hex digits");
                }
                let mut v = 0u32;
                let mut k = 0;
                while k < 8 {
                    v = (v << 4) | hex_digit(s[i + 2 + k]);
                    k += 1;
                }
                out[r][f] = v;
                i += 11;
                f += 1;
            }
            while s[i] != b'\n' {
                i += 1;
            }
            i += 1;
            r += 1;
        }
        out
    }

    /// The fixed-point golden file of the set (const evaluation only, like [`CSV`]).
    const CSV_FIXED: &[u8] = include_bytes!(concat!(env!("NEEDLE_SET_DIR"), "/golden-fixed.csv"));
    const HEADER_FIXED: &str =
        "x_mm_q16,z_mm_q16,theta_x_deg_q16,theta_z_deg_q16,depth_mm_q16,status,fx_un,fy_un,fz_un,mx_unmm,my_unmm,mz_unmm";
    const FIXED_ROWS: usize = count_lines_after(CSV_FIXED, HEADER_FIXED.len() + 1);
    /// The five Q16.16 inputs of every row of golden-fixed.csv, in file order.
    static POSES_FIXED: [[i32; 5]; FIXED_ROWS] = parse_fixed_poses(CSV_FIXED);

    const fn count_lines_after(s: &[u8], start: usize) -> usize {
        let mut i = start;
        let mut rows = 0;
        while i < s.len() {
            if s[i] == b'\n' {
                rows += 1;
            }
            i += 1;
        }
        rows
    }

    const fn parse_fixed_poses<const N: usize>(s: &[u8]) -> [[i32; 5]; N] {
        let h = HEADER_FIXED.as_bytes();
        let mut i = 0;
        while i < h.len() {
            if s[i] != h[i] {
                panic!("golden-fixed.csv: the first line is not the fixed golden-file header");
            }
            i += 1;
        }
        i += 1;
        let mut out = [[0i32; 5]; N];
        let mut r = 0;
        while r < N {
            let mut f = 0;
            while f < 5 {
                let negative = s[i] == b'-';
                if negative {
                    i += 1;
                }
                let mut v: i64 = 0;
                while s[i] != b',' {
                    if !s[i].is_ascii_digit() {
                        panic!("golden-fixed.csv: an input is not a decimal integer");
                    }
                    v = v * 10 + (s[i] - b'0') as i64;
                    i += 1;
                }
                out[r][f] = (if negative { -v } else { v }) as i32;
                i += 1;
                f += 1;
            }
            while s[i] != b'\n' {
                i += 1;
            }
            i += 1;
            r += 1;
        }
        out
    }

    /// A signed decimal.
    fn int(out: &mut Out, v: i32) {
        if v < 0 {
            out.str("-");
        }
        out.dec(u64::from(v.unsigned_abs()));
    }

    /// Evaluates every fixed-point golden pose and prints the rows.
    fn fixed_rows(out: &mut Out) {
        out.str("needle-golden-fixed rows=");
        out.dec(FIXED_ROWS as u64);
        out.nl();
        let poses: &[[i32; 5]] = black_box(&POSES_FIXED[..]);
        for p in poses {
            let [x, z, tx, tz, d] = *p;
            let e = fixed::wrench(black_box(&fixed::Pose::new(x, z, tx, tz, d)));
            for v in p {
                int(out, *v);
                out.str(",");
            }
            out.hex(u32::from(e.status.bits()), 2);
            for w in e.wrench.to_array() {
                out.str(",");
                int(out, w);
            }
            out.nl();
        }
        out.str("needle-golden-fixed end rows=");
        out.dec(poses.len() as u64);
        out.nl();
    }

    /// Evaluates the wrench and stiffness of every pose of golden-f32.csv and prints the
    /// status and the 18 rates per row (golden-stiffness-f32.csv's format, same poses);
    /// the end line counts the rows whose wrench differs in any bit from [`wrench`]'s.
    fn stiffness_rows(out: &mut Out) {
        out.str("needle-golden-stiffness rows=");
        out.dec(ROWS as u64);
        out.nl();
        let poses: &[[u32; 5]] = black_box(&POSES[..]);
        let mut wrench_differs = 0u64;
        for p in poses {
            let [x, z, tx, tz, d] = *p;
            let pose = Pose::new(f32::from_bits(x), f32::from_bits(z), f32::from_bits(tx), f32::from_bits(tz), f32::from_bits(d));
            let e = wrench_and_stiffness(black_box(&pose));
            let plain = wrench(black_box(&pose));
            if plain.status != e.status || plain.wrench.to_array().map(f32::to_bits) != e.wrench.to_array().map(f32::to_bits) {
                wrench_differs += 1;
            }
            for v in p {
                out.hex(*v, 8);
                out.str(",");
            }
            out.hex(u32::from(e.status.bits()), 2);
            let s = e.stiffness;
            for rates in [s.by_depth, s.by_x, s.by_z] {
                for r in rates.to_array() {
                    out.str(",");
                    out.hex(r.to_bits(), 8);
                }
            }
            out.nl();
        }
        out.str("needle-golden-stiffness end rows=");
        out.dec(poses.len() as u64);
        out.str(" wrench_differs=");
        out.dec(wrench_differs);
        out.nl();
    }

    /// Evaluates the fixed-point wrench and stiffness of every pose of golden-fixed.csv
    /// and prints the status and the 18 integer rates per row (golden-stiffness-fixed.csv's
    /// format, same poses); the end line counts the rows whose wrench or status differs
    /// from [`fixed::wrench`]'s.
    fn stiffness_fixed_rows(out: &mut Out) {
        out.str("needle-golden-stiffness-fixed rows=");
        out.dec(FIXED_ROWS as u64);
        out.nl();
        let poses: &[[i32; 5]] = black_box(&POSES_FIXED[..]);
        let mut wrench_differs = 0u64;
        for p in poses {
            let [x, z, tx, tz, d] = *p;
            let pose = fixed::Pose::new(x, z, tx, tz, d);
            let e = fixed::wrench_and_stiffness(black_box(&pose));
            let plain = fixed::wrench(black_box(&pose));
            if plain.status != e.status || plain.wrench != e.wrench {
                wrench_differs += 1;
            }
            for v in p {
                int(out, *v);
                out.str(",");
            }
            out.hex(u32::from(e.status.bits()), 2);
            let s = e.stiffness;
            for rates in [s.by_depth, s.by_x, s.by_z] {
                for r in rates.to_array() {
                    out.str(",");
                    int(out, r);
                }
            }
            out.nl();
        }
        out.str("needle-golden-stiffness-fixed end rows=");
        out.dec(poses.len() as u64);
        out.str(" wrench_differs=");
        out.dec(wrench_differs);
        out.nl();
    }

    #[cortex_m_rt::entry]
    fn main() -> ! {
        let mut out = Out::new();
        out.str("needle-golden target=");
        out.str(crate::common::target_name());
        out.str(" set=");
        out.str(model_info::SET);
        out.str(" fe_sha256=");
        out.str(model_info::FE_SHA256);
        out.str(" rows=");
        out.dec(ROWS as u64);
        out.nl();
        out.str(HEADER);
        out.nl();
        // Read the table through black_box so the compiler cannot evaluate the model at
        // compile time: every wrench below is computed by the target's instructions.
        let poses: &[[u32; 5]] = black_box(&POSES[..]);
        for p in poses {
            let [x, z, tx, tz, d] = *p;
            let pose = Pose::new(f32::from_bits(x), f32::from_bits(z), f32::from_bits(tx), f32::from_bits(tz), f32::from_bits(d));
            let e = wrench(black_box(&pose));
            for v in p {
                out.hex(*v, 8);
                out.str(",");
            }
            out.hex(u32::from(e.status.bits()), 2);
            for w in e.wrench.to_array() {
                out.str(",");
                out.hex(w.to_bits(), 8);
            }
            out.nl();
        }
        out.str("needle-golden end rows=");
        out.dec(poses.len() as u64);
        out.nl();
        fixed_rows(&mut out);
        stiffness_rows(&mut out);
        stiffness_fixed_rows(&mut out);
        out.flush();
        exit(true)
    }
}

/// On the host this example does nothing: it is firmware.
#[cfg(not(target_os = "none"))]
fn main() {
    eprintln!(
        "`golden` is firmware: cargo run --release --example golden --target thumbv7em-none-eabihf \
         (or thumbv7m-none-eabi, thumbv6m-none-eabi; runners in .cargo/config.toml)"
    );
}
