//! The public API of `needle-haptics` beyond the golden vectors: value types, status
//! flags, error handling and saturation, moving the moment reference point.
use needle_haptics::{model_info, wrench, Pose, Status, Wrench};

#[test]
fn wrench_array_round_trip_and_zero() {
    let a = [1.0, -2.0, 3.5, -0.0, 5.0, 6.25];
    let w = Wrench::from_array(a);
    assert_eq!(w.fy_n, -2.0);
    assert_eq!(w.mz_nmm, 6.25);
    assert_eq!(w.to_array().map(f32::to_bits), a.map(f32::to_bits));
    assert_eq!(Wrench::ZERO.to_array().map(f32::to_bits), [0; needle_contract::COMPONENT_COUNT]);
    assert_eq!(Wrench::default(), Wrench::ZERO);
}

#[test]
fn about_moves_the_moment_reference_point() {
    // A pure axial force F = (0, 2, 0) N at the tip; moments about the hub, which is
    // offset (3, 60, 0) mm from the tip, are M_hub = (hub->tip) x F = (-3, -60, 0) x (0, 2, 0).
    let f = [0.0f32, 2.0, 0.0];
    let hub_to_tip = [-3.0f32, -60.0, 0.0];
    let m_hub = [
        hub_to_tip[1] * f[2] - hub_to_tip[2] * f[1],
        hub_to_tip[2] * f[0] - hub_to_tip[0] * f[2],
        hub_to_tip[0] * f[1] - hub_to_tip[1] * f[0],
    ];
    assert_eq!(m_hub, [0.0, 0.0, -6.0]);
    let w = Wrench::from_array([f[0], f[1], f[2], m_hub[0], m_hub[1], m_hub[2]]);
    let at_tip = w.about(hub_to_tip);
    assert_eq!(at_tip.to_array(), [0.0, 2.0, 0.0, 0.0, 0.0, 0.0], "no moment about the point of application");
    // Moving back restores the hub moments; the force never changes.
    assert_eq!(at_tip.about([3.0, 60.0, 0.0]).to_array(), w.to_array());
    let general = Wrench::from_array([1.0, -2.0, 0.5, 10.0, -4.0, 7.0]).about([1.0, 2.0, -3.0]);
    // M_P = M - r x F with r x F = (2*0.5 - (-3)(-2), (-3)(1) - 1*0.5, 1(-2) - 2*1) = (-5, -3.5, -4)
    assert_eq!(general.to_array(), [1.0, -2.0, 0.5, 15.0, -0.5, 11.0]);
}

#[test]
fn status_flags() {
    let s = Status::SAT_X | Status::SAT_DEPTH;
    assert_eq!(s.bits(), 0x11);
    assert!(s.saturated() && !s.is_ok() && !s.is_error());
    assert!(s.contains(Status::SAT_X) && !s.contains(Status::SAT_Z));
    assert_eq!(format!("{s}"), "SAT_X | SAT_DEPTH");
    assert_eq!(format!("{s:?}"), "Status(0x11: SAT_X | SAT_DEPTH)");
    assert_eq!(format!("{}", Status::OK), "OK");
    assert!(Status::OK.is_ok() && Status::default().is_ok());
    let e = Status::NO_MODEL | Status::ERROR;
    assert_eq!(e.bits(), 0xc0);
    assert!(e.is_error() && !e.saturated());
    assert_eq!(format!("{}", Status::from_bits(0x21)), "SAT_X | FE_UNSOLVED");
    let u = Status::FE_UNSOLVED;
    assert_eq!(u.bits(), 0x20);
    assert!(u.fe_unsolved() && !u.is_ok() && !u.is_error() && !u.saturated(), "a flag beside the wrench, not an error");
    let all: u8 = Status::FLAGS.iter().fold(0, |a, (f, _)| a | f.bits());
    assert_eq!(all, 0xff);
}

#[test]
fn loop_flags_text() {
    use needle_haptics::control::LoopFlags;
    let mut s = LoopFlags::RAMPING;
    s |= LoopFlags::POSE_STALE;
    assert_eq!(s.bits(), 0x0021);
    assert_eq!(format!("{s}"), "POSE_STALE | RAMPING");
    assert_eq!(format!("{s:?}"), "LoopFlags(0x0021: POSE_STALE | RAMPING)");
    assert_eq!(format!("{}", LoopFlags::OK), "OK");
    assert_eq!(format!("{}", LoopFlags::from_bits(0x0201)), "POSE_STALE | STIFFNESS_LIMITED");
    assert_eq!(format!("{}", LoopFlags::from_bits(0x0401)), "POSE_STALE | POSE_GLITCH");
    assert_eq!(format!("{}", LoopFlags::from_bits(0x0801)), "POSE_STALE | 0x0800");
    let all: u16 = LoopFlags::FLAGS.iter().fold(0, |a, (f, _)| a | f.bits());
    assert_eq!(all, 0x07ff);
}

const NON_FINITE: [f32; 4] = [f32::NAN, -f32::NAN, f32::INFINITY, f32::NEG_INFINITY];

#[test]
fn non_finite_input_gives_zero_wrench_and_error() {
    for bad in NON_FINITE {
        for i in 0..5 {
            let mut p = [1.0f32, -2.0, 3.0, -4.0, 2.5];
            p[i] = bad;
            let pose = Pose::new(p[0], p[1], p[2], p[3], p[4]);
            let e = wrench(&pose);
            let want = if model_info::FITTED { Status::ERROR } else { Status::NO_MODEL | Status::ERROR };
            assert_eq!(e.status, want, "input {i} = {bad}");
            assert_eq!(e.wrench.to_array().map(f32::to_bits), [0; needle_contract::COMPONENT_COUNT], "all +0.0");
        }
    }
}

#[test]
fn saturation_flags_and_clamped_values() {
    if !model_info::FITTED {
        // Unfitted build: every pose is NO_MODEL | ERROR with a zero wrench.
        let e = wrench(&Pose::default());
        assert_eq!(e.status, Status::NO_MODEL | Status::ERROR);
        assert_eq!(e.wrench, Wrench::ZERO);
        return;
    }
    let inside = wrench(&Pose::new(-12.0, 12.0, -15.0, 15.0, 6.0));
    assert_eq!(inside.status, Status::OK, "the domain's edges are inside");
    let outside = wrench(&Pose::new(-40.0, 12.5, -15.01, 1e30, 9.0));
    assert_eq!(outside.status, Status::SAT_X | Status::SAT_Z | Status::SAT_THETA_X | Status::SAT_THETA_Z | Status::SAT_DEPTH);
    assert_eq!(outside.wrench.to_array().map(f32::to_bits), inside.wrench.to_array().map(f32::to_bits));
    let shallow = wrench(&Pose::new(0.0, 0.0, 0.0, 0.0, -1.0));
    assert_eq!(shallow.status, Status::SAT_DEPTH);
    assert_eq!(shallow.wrench, wrench(&Pose::default()).wrench);
    // -0.0 is not a saturation and counts as positive.
    let neg_zero = wrench(&Pose::new(-0.0, -0.0, -0.0, -0.0, -0.0));
    assert_eq!(neg_zero.status, Status::OK);
    assert_eq!(neg_zero.wrench.to_array().map(f32::to_bits), wrench(&Pose::default()).wrench.to_array().map(f32::to_bits));
}

#[test]
fn model_info_describes_the_domain() {
    assert_eq!((model_info::X_MAX_MM, model_info::Z_MAX_MM, model_info::THETA_MAX_DEG, model_info::DEPTH_MAX_MM), (12.0, 12.0, 15.0, 6.0));
    assert_eq!(model_info::FORMAT, 1);
    assert!(model_info::C_HEADER.contains("#define NEEDLE_STATUS_NO_MODEL 0x40u"));
    if model_info::FITTED {
        assert_eq!(model_info::FE_SHA256.len(), 64);
    } else {
        assert!(model_info::FE_SHA256.is_empty());
    }
}
