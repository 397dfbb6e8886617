//! The trace line of the loop examples (`insertion`, `rtic-lm3s6965`), one per printed
//! sample: `<prefix> t_ms=<n> depth_mm=<d> theta_x_deg=<d> fy_n=<d> cmd_y_n=<d>
//! duty=<x>,<y>,<z> en=<0|1> flags=0x<hhhh> bits=<x>,<z>,<tx>,<tz>,<depth>,<fy>`:
//! numbers rounded for reading, `bits` the exact f32 bits of the pose and of fy (the
//! host tests evaluate the library at that pose and compare), `duty` and `en` the
//! stand-in motor registers when the line is printed.
use super::device::read_reg;
use super::Out;
use needle_haptics::control::Sample;

/// Appends `v` rounded to `decimals` digits (|v| < 2^31 / 10^decimals).
pub fn fixed(out: &mut Out, v: f32, decimals: u32) {
    let scale = 10u32.pow(decimals) as f32;
    let n = (if v < 0.0 { -v } else { v } * scale + 0.5) as u64;
    if v < 0.0 && n != 0 {
        out.str("-");
    }
    let p = 10u64.pow(decimals);
    out.dec(n / p);
    out.str(".");
    let frac = n % p;
    let mut d = p / 10;
    while d > frac.max(1) && d > 1 {
        out.str("0");
        d /= 10;
    }
    out.dec(frac);
}

/// Appends the trace line of `s` (module docs).
pub fn print(out: &mut Out, prefix: &str, s: &Sample) {
    out.str(prefix);
    out.str(" t_ms=");
    out.dec(u64::from(s.tick));
    out.str(" depth_mm=");
    fixed(out, s.pose.depth_mm, 3);
    out.str(" theta_x_deg=");
    fixed(out, s.pose.theta_x_deg, 2);
    out.str(" fy_n=");
    fixed(out, s.wrench.fy_n, 5);
    out.str(" cmd_y_n=");
    fixed(out, s.force_cmd_n[1], 5);
    out.str(" duty=");
    out.dec(u64::from(read_reg(0)));
    out.str(",");
    out.dec(u64::from(read_reg(1)));
    out.str(",");
    out.dec(u64::from(read_reg(2)));
    out.str(" en=");
    out.dec(u64::from(read_reg(6)));
    out.str(" flags=");
    out.hex(u32::from(s.flags.bits()), 4);
    out.str(" bits=");
    let p = s.pose;
    for v in [p.x_mm, p.z_mm, p.theta_x_deg, p.theta_z_deg, p.depth_mm] {
        out.hex(v.to_bits(), 8);
        out.str(",");
    }
    out.hex(s.wrench.fy_n.to_bits(), 8);
    out.nl();
}
