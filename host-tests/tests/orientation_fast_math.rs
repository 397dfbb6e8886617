//! Tilt angles from a needle axis or a quaternion (`needle_haptics::orientation`): the
//! libm path against f64, and the `fast-math` (micromath) path's error in degrees and in
//! the resulting wrench, over tilts up to 30° (the model's domain is 15°).
use needle_haptics::orientation::{self, exact, fast, Tilt};
use needle_haptics::{wrench, Pose};

/// The campaign's axis (tip to hub) of tilts (θx, θz), in f64.
fn axis(tx_deg: f64, tz_deg: f64) -> [f64; 3] {
    let (sx, cx) = tx_deg.to_radians().sin_cos();
    let (sz, cz) = tz_deg.to_radians().sin_cos();
    [-sz * cx, cz * cx, sx]
}

/// The quaternion [w, x, y, z] of Rz(θz) * Rx(θx).
fn quaternion(tx_deg: f64, tz_deg: f64) -> [f32; 4] {
    let (sx, cx) = (tx_deg.to_radians() / 2.0).sin_cos();
    let (sz, cz) = (tz_deg.to_radians() / 2.0).sin_cos();
    // (cz, 0, 0, sz) * (cx, sx, 0, 0)
    [(cz * cx) as f32, (cz * sx) as f32, (sz * sx) as f32, (sz * cx) as f32]
}

fn grid(max_deg: f64) -> Vec<(f64, f64)> {
    let n = (max_deg * 4.0) as i32;
    let mut g = Vec::new();
    for i in -n..=n {
        for j in -n..=n {
            g.push((f64::from(i) * 0.25, f64::from(j) * 0.25));
        }
    }
    g
}

fn err_deg(t: Tilt, tx: f64, tz: f64) -> f64 {
    (f64::from(t.theta_x_deg) - tx).abs().max((f64::from(t.theta_z_deg) - tz).abs())
}

#[test]
fn libm_tilts_are_within_f32_rounding() {
    let mut worst = 0.0f64;
    for (tx, tz) in grid(30.0) {
        let a = axis(tx, tz).map(|v| v as f32);
        let t = exact::tilt_from_axis(a).expect("upward axis");
        worst = worst.max(err_deg(t, tx, tz));
        let q = exact::tilt_from_quaternion(quaternion(tx, tz)).expect("quaternion");
        worst = worst.max(err_deg(q, tx, tz));
    }
    println!("libm: worst tilt error {worst:.2e} deg over |theta| <= 30 deg");
    assert!(worst < 2e-5, "libm tilt error {worst} deg");
}

#[test]
fn fast_math_tilt_and_wrench_errors_are_bounded() {
    let (mut worst_deg, mut worst_q_deg) = (0.0f64, 0.0f64);
    let (mut worst_f_n, mut peak_fy_n) = (0.0f32, 0.0f32);
    for (tx, tz) in grid(30.0) {
        let a = axis(tx, tz).map(|v| v as f32);
        let t = fast::tilt_from_axis(a).expect("upward axis");
        worst_deg = worst_deg.max(err_deg(t, tx, tz));
        worst_q_deg = worst_q_deg.max(err_deg(fast::tilt_from_quaternion(quaternion(tx, tz)).expect("q"), tx, tz));
        if tx.abs() <= 15.0 && tz.abs() <= 15.0 {
            for depth in [2.0f32, 4.0, 6.0] {
                let p_fast = Pose::new(2.0, -1.0, t.theta_x_deg, t.theta_z_deg, depth);
                let p_exact = Pose::new(2.0, -1.0, tx as f32, tz as f32, depth);
                let (wf, we) = (wrench(&p_fast).wrench, wrench(&p_exact).wrench);
                peak_fy_n = peak_fy_n.max(we.fy_n.abs());
                for (a, b) in [(wf.fx_n, we.fx_n), (wf.fy_n, we.fy_n), (wf.fz_n, we.fz_n)] {
                    worst_f_n = worst_f_n.max((a - b).abs());
                }
            }
        }
    }
    println!(
        "fast-math (micromath): worst tilt error {worst_deg:.4} deg (axis), {worst_q_deg:.4} deg (quaternion) over |theta| <= 30 deg; \
         worst force error {worst_f_n:.2e} N ({:.3} % of peak |Fy| {peak_fy_n:.4} N) over the domain",
        100.0 * worst_f_n / peak_fy_n
    );
    // Bounds: measured 0.162 deg and 1.17e-3 N (1.46 % of peak |Fy|) with micromath 2.1.
    assert!(worst_deg < 0.2 && worst_q_deg < 0.2, "tilt error {worst_deg} / {worst_q_deg} deg (bound 0.2 deg)");
    assert!(worst_f_n < 0.002, "force error {worst_f_n} N (bound 2 mN, peak |Fy| {peak_fy_n} N)");
    // The feature selects the fast path for the plain functions.
    let a = axis(7.0, -3.0).map(|v| v as f32);
    assert_eq!(orientation::tilt_from_axis(a), fast::tilt_from_axis(a));
}

#[test]
fn degenerate_axes_give_the_reason() {
    use needle_haptics::orientation::AxisError;
    for (a, why) in [
        ([0.0, 0.0, 0.0], AxisError::Zero),
        ([0.0, -1.0, 0.0], AxisError::NotUpward),
        ([1.0, 0.0, 0.0], AxisError::NotUpward),
        ([f32::NAN, 1.0, 0.0], AxisError::NotFinite),
        ([0.0, f32::INFINITY, 0.0], AxisError::NotFinite),
        ([1e30, 1e30, 0.0], AxisError::NotFinite),
    ] {
        assert_eq!(exact::tilt_from_axis(a), Err(why), "{a:?}");
        assert_eq!(fast::tilt_from_axis(a), Err(why), "{a:?}");
    }
    assert!(AxisError::NotUpward.to_string().contains("a_y <= 0"));
    let p = orientation::pose_from_axis(1.0, 2.0, [0.0, 2.0, 0.0], 3.0).expect("vertical");
    assert_eq!(p, Pose::new(1.0, 2.0, 0.0, 0.0, 3.0));
}
