//! An independent f32 implementation of the contract's stiffness (coeffs/README.md,
//! "Stiffness"): the exact partial derivatives of the wrench by depth, x and z. It writes
//! `golden-stiffness-f32.csv`, so like [`crate::eval::float32`] it must not call the
//! `needle-haptics` library; it skips nothing (no zero-matrix shortcut) and computes
//! every derivative coefficient at run time.

use crate::contract::COMPONENT_COUNT;
use crate::contract::{NCOEF, STATUS_ERROR, STATUS_SAT_DEPTH, STATUS_SAT_X, STATUS_SAT_Z};
use crate::eval::float32::{clamp32, eval, h32, horner_n32, monomial32, Tables32, ODD, ONE_THIRD, R_THETA, R_XZ, S_THETA, S_XZ};

/// `(h(p, w), h'(p, w))` in f32: the value by [`h32`]'s operations, the derivative
/// accumulated alongside (`d = p4`, then `d = d*w + b` after the steps for p3, p2, p1,
/// `b` the value so far), written out.
pub fn hd32(p: &[f32; NCOEF], w: f32) -> (f32, f32) {
    let mut b = p[NCOEF - 1];
    let mut d = b;
    for i in (1..NCOEF - 1).rev() {
        b = b * w + p[i];
        d = d * w + b;
    }
    (b * w + p[0], d)
}

/// The wrench's rates at `pose = [x_mm, z_mm, theta_x_deg, theta_z_deg, depth_mm]`:
/// `[by_depth, by_x, by_z]`, each `[fx, fy, fz, mx, my, mz]` in N/mm and N·mm/mm, and
/// the status byte, bit for bit as coeffs/README.md specifies.
pub fn eval_rates(t: &Tables32, pose: [f32; 5]) -> ([[f32; COMPONENT_COUNT]; 3], u8) {
    let (_, status) = eval(t, pose);
    if status & STATUS_ERROR != 0 {
        return ([[0.0; COMPONENT_COUNT]; 3], status);
    }
    let [x, z, tx, tz, d] = pose;
    let clamp = |v: f32, m: f32| clamp32(v, -m, m);
    let (xc, zc, txc, tzc) = (clamp(x, 12.0), clamp(z, 12.0), clamp(tx, 15.0), clamp(tz, 15.0));
    let dc = clamp32(d, 0.0, 6.0);
    let u = dc * ONE_THIRD - 1.0;
    let vals = [xc, zc, txc, tzc];
    let scales = [S_XZ, S_XZ, S_THETA, S_THETA];
    let mut a = [0.0f32; COMPONENT_COUNT];
    let mut g = [[0.0f32; COMPONENT_COUNT]; 2];
    for c in 0..COMPONENT_COUNT {
        a[c] = hd32(&t.baseline[c], u).1;
        for k in 0..4 {
            let tt = vals[k].abs() * scales[k] - 1.0;
            let negative = vals[k] < 0.0;
            let m = &t.rows[k][c];
            let rows: [(f32, f32); NCOEF] = std::array::from_fn(|i| hd32(&m[i], tt));
            let du = hd32(&rows.map(|(r, _)| r), u).1;
            if negative && ODD[k][c] {
                a[c] -= du;
            } else {
                a[c] += du;
            }
            if k < 2 {
                let dt = h32(&rows.map(|(_, q)| q), u);
                if negative && !ODD[k][c] {
                    g[k][c] -= dt;
                } else {
                    g[k][c] += dt;
                }
            }
        }
    }
    let mut rates = [a.map(|v| v * ONE_THIRD), g[0].map(|v| v * S_XZ), g[1].map(|v| v * S_XZ)];
    // The coupled form's cross terms, per term in file order.
    let n = [xc * R_XZ, zc * R_XZ, txc * R_THETA, tzc * R_THETA];
    for (c, terms) in t.cross.iter().enumerate() {
        for (e, p) in terms {
            if p.len() > 1 {
                let q: Vec<f32> = p.iter().enumerate().skip(1).map(|(k, v)| k as f32 * v).collect();
                rates[0][c] += (monomial32(*e, &n) * horner_n32(&q, u)) * ONE_THIRD;
            }
            for k in 0..2 {
                if e[k] > 0 {
                    let mut reduced = *e;
                    reduced[k] -= 1;
                    rates[k + 1][c] += (f32::from(e[k]) * monomial32(reduced, &n)) * horner_n32(p, u) * R_XZ;
                }
            }
        }
    }
    for (i, flag) in [STATUS_SAT_DEPTH, STATUS_SAT_X, STATUS_SAT_Z].into_iter().enumerate() {
        if status & flag != 0 {
            rates[i] = [0.0; COMPONENT_COUNT];
        }
    }
    (rates, status)
}
