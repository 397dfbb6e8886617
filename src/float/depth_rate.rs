//! [`wrench_and_depth_rate`]: the wrench and the rate of its forces by depth only, for
//! a passivity guard that needs the stiffness along the insertion and nothing else (the
//! whole insertion's guard: [`LoopCore::set_insertion`](crate::control::LoopCore::set_insertion)).
//!
//! The same operations as [`wrench_and_stiffness`](crate::wrench_and_stiffness), component
//! by component, with the rates by x and z and the moments' depth rates left unused, so
//! the compiler drops them: the wrench and the three force rates are its bits exactly
//! (host-tests/tests/depth_rate.rs compares them on the golden poses).
use crate::float::cross::{add_cross, add_cross_rates, COUPLED, CROSS_SCALES};
use crate::float::eval::{clamp_to_domain, unsolved_flag, ONE_THIRD};
use crate::float::eval_stiffness::{component, At, Column};
use crate::float::tables::FITTED;
use crate::{Evaluation, Pose, Status, Wrench};
use needle_contract::COMPONENT_COUNT;

/// The wrench at `pose` (the bits of [`wrench`](crate::wrench)) and `[dfx, dfy, dfz]`
/// by depth, N/mm (the bits of [`wrench_and_stiffness`](crate::wrench_and_stiffness)'s
/// `by_depth`; `+0.0` when the depth was clamped, and for an error).
#[must_use]
pub fn wrench_and_depth_rate(pose: &Pose) -> (Evaluation, [f32; 3]) {
    let error = |status| (Evaluation { wrench: Wrench::ZERO, status }, [0.0; 3]);
    if !FITTED {
        return error(Status::NO_MODEL | Status::ERROR);
    }
    let Some((clamped, status)) = clamp_to_domain(pose) else {
        return error(Status::ERROR);
    };
    let Pose { x_mm: x, z_mm: z, theta_x_deg: tx, theta_z_deg: tz, .. } = clamped;
    let status = status | unsolved_flag([x, z, tx, tz], clamped.depth_mm);
    let at = At::of(&clamped);
    let u = at.u;
    let columns = [
        column::<0, true>(&at),
        column::<1, true>(&at),
        column::<2, true>(&at),
        column::<3, false>(&at),
        column::<4, false>(&at),
        column::<5, false>(&at),
    ];
    let mut w = [0.0_f32; COMPONENT_COUNT];
    let mut by_depth = [0.0_f32; COMPONENT_COUNT];
    for ((wc, dc), (cw, ca)) in w.iter_mut().zip(by_depth.iter_mut()).zip(columns) {
        *wc = cw;
        *dc = ca * ONE_THIRD;
    }
    if COUPLED {
        let [cx, cz, ctx, ctz] = CROSS_SCALES;
        let n = [x * cx, z * cz, tx * ctx, tz * ctz];
        add_cross(n, u, &mut w);
        let (mut unused_x, mut unused_z) = ([0.0_f32; COMPONENT_COUNT], [0.0_f32; COMPONENT_COUNT]);
        add_cross_rates(n, u, &mut by_depth, &mut unused_x, &mut unused_z);
    }
    let [dfx, dfy, dfz, ..] = by_depth;
    let rates = if status.contains(Status::SAT_DEPTH) { [0.0; 3] } else { [dfx, dfy, dfz] };
    (Evaluation { wrench: Wrench::from_array(w), status }, rates)
}

/// Component `C`: its wrench and, with `RATE`, its rate by `u` (else `0.0`, and the
/// compiler drops the rate's operations); not inlined, as in `float::eval_stiffness`.
#[inline(never)]
fn column<const C: usize, const RATE: bool>(at: &At) -> (f32, f32) {
    let c = component::<true>(&Column::<C>::TABLES, at);
    (c.w, if RATE { c.a } else { 0.0 })
}
