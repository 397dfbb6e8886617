//! The evaluator: `needle_wrench`, `needle_wrench_and_stiffness`, `needle_model_info`.
use crate::types::{needle_model_info_t, needle_pose_t, needle_stiffness_t, needle_wrench_t};
use needle_haptics::{model_info, wrench, wrench_and_stiffness, Pose, Status, Wrench};

pub(crate) fn pose_in(p: &needle_pose_t) -> Pose {
    Pose::new(p.x_mm, p.z_mm, p.theta_x_deg, p.theta_z_deg, p.depth_mm)
}

pub(crate) fn pose_out(p: &Pose) -> needle_pose_t {
    needle_pose_t { x_mm: p.x_mm, z_mm: p.z_mm, theta_x_deg: p.theta_x_deg, theta_z_deg: p.theta_z_deg, depth_mm: p.depth_mm }
}

pub(crate) fn wrench_out_of(w: &Wrench) -> needle_wrench_t {
    needle_wrench_t { fx_n: w.fx_n, fy_n: w.fy_n, fz_n: w.fz_n, mx_nmm: w.mx_nmm, my_nmm: w.my_nmm, mz_nmm: w.mz_nmm }
}

/// The wrench at `*pose` into `*out`; returns the status bits (`NEEDLE_STATUS_*`).
///
/// Bit for bit the Rust evaluator (`needle_haptics::wrench`), hence the golden vectors.
/// A NULL `pose` returns `0x80` (ERROR) and writes the zero wrench to `out` when it is
/// not NULL; a NULL `out` still returns the status.
///
/// # Safety
/// `pose` and `out` are NULL or valid, aligned pointers to their types.
#[no_mangle]
pub unsafe extern "C" fn needle_wrench(pose: *const needle_pose_t, out: *mut needle_wrench_t) -> u8 {
    // SAFETY: the caller passes NULL or a valid pointer.
    let e = match unsafe { pose.as_ref() } {
        Some(p) => wrench(&pose_in(p)),
        None => needle_haptics::Evaluation { wrench: Wrench::ZERO, status: Status::ERROR },
    };
    // SAFETY: as above.
    if let Some(o) = unsafe { out.as_mut() } {
        *o = wrench_out_of(&e.wrench);
    }
    e.status.bits()
}

/// The wrench at `*pose` into `*wrench_out` (the bits of `needle_wrench`) and its partial
/// derivatives by depth, x and z into `*stiffness_out`; returns the status bits.
///
/// Bit for bit the Rust `needle_haptics::wrench_and_stiffness`, hence
/// `golden-stiffness-f32.csv` (coeffs/README.md, "Stiffness"). A NULL `pose` returns
/// `0x80` (ERROR) and writes zeros to the outputs that are not NULL; a NULL output is
/// skipped.
///
/// # Safety
/// Each pointer is NULL or a valid, aligned pointer to its type.
#[no_mangle]
pub unsafe extern "C" fn needle_wrench_and_stiffness(
    pose: *const needle_pose_t,
    wrench_out: *mut needle_wrench_t,
    stiffness_out: *mut needle_stiffness_t,
) -> u8 {
    // SAFETY: the caller passes NULL or a valid pointer.
    let e = match unsafe { pose.as_ref() } {
        Some(p) => wrench_and_stiffness(&pose_in(p)),
        None => {
            needle_haptics::StiffnessEvaluation { wrench: Wrench::ZERO, stiffness: needle_haptics::Stiffness::ZERO, status: Status::ERROR }
        }
    };
    // SAFETY: as above.
    if let Some(o) = unsafe { wrench_out.as_mut() } {
        *o = wrench_out_of(&e.wrench);
    }
    // SAFETY: as above.
    if let Some(o) = unsafe { stiffness_out.as_mut() } {
        let s = e.stiffness;
        *o = needle_stiffness_t { by_depth: s.by_depth.to_array(), by_x: s.by_x.to_array(), by_z: s.by_z.to_array() };
    }
    e.status.bits()
}

/// The point the moments are taken about (the hub), as its distance from the tip along
/// the needle's axis, mm (the set's `[needle] reference_from_tip_mm`): where a device's
/// handle holds the needle when it applies the wrench's moments unchanged.
#[no_mangle]
pub extern "C" fn needle_hub_from_tip_mm() -> f32 {
    needle_haptics::insertion::HUB_FROM_TIP_MM
}

/// Copies `s` into `dst` with a NUL, truncated to `dst.len() - 1` bytes.
fn c_string<const N: usize>(s: &str) -> [u8; N] {
    let mut dst = [0u8; N];
    for (d, b) in dst.iter_mut().take(N.saturating_sub(1)).zip(s.bytes()) {
        *d = b;
    }
    dst
}

/// Writes the compiled-in model's set name, FE hash, fitted flag and domain to `*out`.
/// Returns `NEEDLE_OK`, or `NEEDLE_E_NULL` when `out` is NULL.
///
/// # Safety
/// `out` is NULL or a valid, aligned pointer.
#[no_mangle]
pub unsafe extern "C" fn needle_model_info(out: *mut needle_model_info_t) -> i32 {
    // SAFETY: the caller passes NULL or a valid pointer.
    let Some(o) = (unsafe { out.as_mut() }) else {
        return crate::types::NEEDLE_E_NULL;
    };
    *o = needle_model_info_t {
        set: c_string(model_info::SET),
        fe_sha256: c_string(model_info::FE_SHA256),
        fitted: model_info::FITTED,
        x_max_mm: model_info::X_MAX_MM,
        z_max_mm: model_info::Z_MAX_MM,
        theta_max_deg: model_info::THETA_MAX_DEG,
        depth_max_mm: model_info::DEPTH_MAX_MM,
    };
    crate::types::NEEDLE_OK
}
