//! The fixed-point evaluator: `needle_fixed_wrench`, `needle_fixed_wrench_and_stiffness`
//! (integer arithmetic only, for cores without an FPU).
use crate::types::{needle_fixed_pose_t, needle_fixed_stiffness_t, needle_fixed_wrench_t};
use needle_haptics::fixed::{self, Pose, Stiffness, StiffnessEvaluation, Wrench};
use needle_haptics::Status;

pub(crate) fn pose_in(p: &needle_fixed_pose_t) -> Pose {
    Pose::new(p.x_mm_q16, p.z_mm_q16, p.theta_x_deg_q16, p.theta_z_deg_q16, p.depth_mm_q16)
}

pub(crate) fn wrench_out_of(w: &Wrench) -> needle_fixed_wrench_t {
    let [fx_un, fy_un, fz_un, mx_unmm, my_unmm, mz_unmm] = w.to_array();
    needle_fixed_wrench_t { fx_un, fy_un, fz_un, mx_unmm, my_unmm, mz_unmm }
}

/// The fixed-point wrench at `*pose` (Q16.16) into `*out` (µN, µN·mm); returns the status
/// bits (`NEEDLE_STATUS_*`).
///
/// Exactly the Rust `needle_haptics::fixed::wrench`, hence `golden-fixed.csv`. A NULL
/// `pose` returns `0x80` (ERROR) and writes the zero wrench to `out` when it is not
/// NULL; a NULL `out` still returns the status.
///
/// # Safety
/// `pose` and `out` are NULL or valid, aligned pointers to their types.
#[no_mangle]
pub unsafe extern "C" fn needle_fixed_wrench(pose: *const needle_fixed_pose_t, out: *mut needle_fixed_wrench_t) -> u8 {
    // SAFETY: the caller passes NULL or a valid pointer.
    let e = match unsafe { pose.as_ref() } {
        Some(p) => fixed::wrench(&pose_in(p)),
        None => fixed::Evaluation { wrench: Wrench::ZERO, status: Status::ERROR },
    };
    // SAFETY: as above.
    if let Some(o) = unsafe { out.as_mut() } {
        *o = wrench_out_of(&e.wrench);
    }
    e.status.bits()
}

/// The fixed-point wrench at `*pose` into `*wrench_out` (the integers of
/// `needle_fixed_wrench`) and its partial derivatives by depth, x and z (µN/mm, µN·mm/mm)
/// into `*stiffness_out`; returns the status bits.
///
/// Exactly the Rust `needle_haptics::fixed::wrench_and_stiffness`, hence
/// `golden-stiffness-fixed.csv` (coeffs/README.md, "Fixed-point stiffness"). A NULL
/// `pose` returns `0x80` (ERROR) and writes zeros to the outputs that are not NULL; a
/// NULL output is skipped.
///
/// # Safety
/// Each pointer is NULL or a valid, aligned pointer to its type.
#[no_mangle]
pub unsafe extern "C" fn needle_fixed_wrench_and_stiffness(
    pose: *const needle_fixed_pose_t,
    wrench_out: *mut needle_fixed_wrench_t,
    stiffness_out: *mut needle_fixed_stiffness_t,
) -> u8 {
    // SAFETY: the caller passes NULL or a valid pointer.
    let e = match unsafe { pose.as_ref() } {
        Some(p) => fixed::wrench_and_stiffness(&pose_in(p)),
        None => StiffnessEvaluation { wrench: Wrench::ZERO, stiffness: Stiffness::ZERO, status: Status::ERROR },
    };
    // SAFETY: as above.
    if let Some(o) = unsafe { wrench_out.as_mut() } {
        *o = wrench_out_of(&e.wrench);
    }
    // SAFETY: as above.
    if let Some(o) = unsafe { stiffness_out.as_mut() } {
        let s = e.stiffness;
        *o = needle_fixed_stiffness_t { by_depth: s.by_depth.to_array(), by_x: s.by_x.to_array(), by_z: s.by_z.to_array() };
    }
    e.status.bits()
}
