//! The wrench and its stiffness in f32: the evaluation algorithm of `coeffs/README.md`
//! ("Stiffness") bit for bit, sharing the wrench's operations.
use crate::float::cross::{add_cross, add_cross_rates, COUPLED, CROSS_SCALES};
use crate::float::eval::{
    clamp_to_domain, skip_sweep, sweep_t, unsolved_flag, BASELINE_STARTS, DEVIATION_MATS, ODD, ONE_THIRD, STARTS, SWEEP_SCALES,
};
use crate::float::horner::{horner_from, horner_from_shared, horner_with_rate_from, horner_with_rate_from_shared, MatrixStarts, Start};
use crate::float::stiffness::{Stiffness, StiffnessEvaluation, WrenchRate};
use crate::float::tables::{BASELINE, DEVIATION, FITTED};
use crate::{Pose, Status, Wrench};
use needle_contract::COMPONENT_COUNT;
use needle_contract::TERMS;

/// `SKIP[k][c]`: `D_kc` and all its derivatives are `+0.0` and adding them changes no
/// accumulator, so they are left out exactly: the matrix is all `+0.0` (see
/// `float::eval::skip_sweep`), and neither `B_c(u)` nor `B_c'(u)` can be `-0.0`
/// (`skip_sweep`'s `with_rates`). The x and z rates of a skipped matrix start from `+0.0` and
/// stay `+0.0` (`+0 - +0 = +0`).
const SKIP: [[bool; COMPONENT_COUNT]; 4] = {
    let [d0, d1, d2, d3] = &DEVIATION;
    [skip_sweep(d0, true), skip_sweep(d1, true), skip_sweep(d2, true), skip_sweep(d3, true)]
};

/// The wrench of [`wrench`](crate::wrench) (the same bits) and its exact partial
/// derivatives by depth, x and z, at `pose`, for a haptic loop that needs the stiffness
/// it renders (the passivity guard of [`control`](crate::control)).
///
/// Implements the contract's "Stiffness" section of `coeffs/README.md`; the golden file
/// `golden-stiffness-f32.csv` holds its bits for every golden pose:
///
/// - `u = depth/3 - 1`, `t_k = |v_k| * (2/V_k) - 1` as for the wrench;
/// - by depth: `a_c = B_c'(u) ± dD_kc/du` over the four sweeps (the wrench's signs),
///   then `a_c * (1/3)`;
/// - by x (and likewise z): `g_c = +0 ± dD_xc/dt`, minus when `x < 0` and component c is
///   *even* under the x mirror (the chain rule through `|x|`), then `g_c * (2/12)`;
/// - coupled form: each cross term `m * P(u)` adds `(m * P'(u)) * (1/3)` by depth and
///   `((e_x * m/xi) * P(u)) * (1/12)` by x;
/// - a rate along an input that was clamped (its `SAT_*` flag) is `+0.0`: the rendered
///   force does not change when the hand moves further outside the domain.
///
/// At `x = 0` (either sign of zero) the rate by x is the one for `x -> 0+` (the model
/// is a polynomial in `|x|`, so a component even under the mirror may have a kink there,
/// with the opposite rate for `x -> 0-`); likewise for z.
///
/// Constant work like [`wrench`](crate::wrench): no allocation, no input-dependent loop.
///
/// # Panics
/// Never (no indexing, no division, no unwrap).
#[must_use]
pub fn wrench_and_stiffness(pose: &Pose) -> StiffnessEvaluation {
    let error = |status| StiffnessEvaluation { wrench: Wrench::ZERO, stiffness: Stiffness::ZERO, status };
    if !FITTED {
        return error(Status::NO_MODEL | Status::ERROR);
    }
    let Some((clamped, status)) = clamp_to_domain(pose) else {
        return error(Status::ERROR);
    };
    let Pose { x_mm: x, z_mm: z, theta_x_deg: tx, theta_z_deg: tz, .. } = clamped;
    let status = status | unsolved_flag([x, z, tx, tz], clamped.depth_mm);
    let at = At::of(&clamped);
    let [sx, sz, _, _] = SWEEP_SCALES;
    let u = at.u;
    // Component by component (the contract's order within each component: baseline,
    // then the sweeps x, z, theta_x, theta_z), written out with constant indices so the
    // tables, parities and skip flags are constants in straight-line code and only one
    // component's four accumulators are live at a time.
    let mut w = [0.0_f32; COMPONENT_COUNT];
    let mut by_depth = [0.0_f32; COMPONENT_COUNT];
    let mut by_x = [0.0_f32; COMPONENT_COUNT];
    let mut by_z = [0.0_f32; COMPONENT_COUNT];
    let columns: [Component; COMPONENT_COUNT] = [
        component_of::<0>(&at),
        component_of::<1>(&at),
        component_of::<2>(&at),
        component_of::<3>(&at),
        component_of::<4>(&at),
        component_of::<5>(&at),
    ];
    for ((((r, wc), dc), xc), zc) in columns.iter().zip(w.iter_mut()).zip(by_depth.iter_mut()).zip(by_x.iter_mut()).zip(by_z.iter_mut()) {
        *wc = r.w;
        *dc = r.a * ONE_THIRD;
        *xc = r.gx * sx;
        *zc = r.gz * sz;
    }
    if COUPLED {
        let [cx, cz, ctx, ctz] = CROSS_SCALES;
        let n = [x * cx, z * cz, tx * ctx, tz * ctz];
        add_cross(n, u, &mut w);
        add_cross_rates(n, u, &mut by_depth, &mut by_x, &mut by_z);
    }
    // The rates along clamped inputs are zeroed after the result is built (a branch per
    // input, taken only when clamped), not selected while building it (measured on the
    // M4F: 1,134.1 instructions with the selects, 1,117.0 this way).
    let mut out = StiffnessEvaluation {
        wrench: Wrench::from_array(w),
        stiffness: Stiffness {
            by_depth: WrenchRate::from_array(by_depth),
            by_x: WrenchRate::from_array(by_x),
            by_z: WrenchRate::from_array(by_z),
        },
        status,
    };
    let rates = &mut out.stiffness;
    for (flag, rate) in [(Status::SAT_DEPTH, &mut rates.by_depth), (Status::SAT_X, &mut rates.by_x), (Status::SAT_Z, &mut rates.by_z)] {
        if status.contains(flag) {
            *rate = WrenchRate::ZERO;
        }
    }
    out
}

/// Where the polynomials are evaluated: `t` and the sign (`-1` for a negative value) of
/// each sweep, and `u`.
pub(crate) struct At {
    pub(crate) t: [f32; 4],
    pub(crate) sign: [f32; 4],
    pub(crate) u: f32,
}

impl At {
    /// Where the polynomials are evaluated for a pose already clamped to the domain:
    /// `u = depth/3 - 1`, `t_k = |v_k| * (2/V_k) - 1` and the signs, as for the wrench.
    pub(crate) fn of(clamped: &Pose) -> Self {
        let Pose { x_mm: x, z_mm: z, theta_x_deg: tx, theta_z_deg: tz, depth_mm: d } = *clamped;
        let [sx, sz, stx, stz] = SWEEP_SCALES;
        Self {
            t: [sweep_t(x, sx), sweep_t(z, sz), sweep_t(tx, stx), sweep_t(tz, stz)],
            sign: [x, z, tx, tz].map(|v| if v < 0.0 { -1.0_f32 } else { 1.0 }),
            u: d * ONE_THIRD - 1.0,
        }
    }
}

/// One component's accumulators: the wrench `w`, and the rates by `u`, by `t_x`, by `t_z`
/// (before the chain rule's scale).
#[derive(Clone, Copy)]
pub(crate) struct Component {
    pub(crate) w: f32,
    pub(crate) a: f32,
    gx: f32,
    gz: f32,
}

/// One component's tables: its baseline and where its Horner starts, and per sweep its
/// deviation matrix, the starts of its Horner evaluations, parity and skip flag.
pub(crate) struct ComponentTables {
    baseline: [f32; TERMS],
    /// Where its Horner starts (`float::eval::BASELINE_STARTS`).
    baseline_start: Start,
    /// Per sweep its matrix in [`DEVIATION_MATS`] (a reference: one copy of the
    /// matrices for every user; constants to the optimiser all the same).
    mats: [&'static [[f32; TERMS]; TERMS]; 4],
    starts: [MatrixStarts; 4],
    odd: [bool; 4],
    skip: [bool; 4],
}

/// The tables of component `c` (`c < 6`; const evaluation only).
#[allow(clippy::indexing_slicing)]
const fn component_tables(c: usize) -> ComponentTables {
    ComponentTables {
        baseline: BASELINE[c],
        baseline_start: BASELINE_STARTS[c],
        mats: [&DEVIATION_MATS[0][c], &DEVIATION_MATS[1][c], &DEVIATION_MATS[2][c], &DEVIATION_MATS[3][c]],
        starts: [STARTS[0][c], STARTS[1][c], STARTS[2][c], STARTS[3][c]],
        odd: [ODD[0][c], ODD[1][c], ODD[2][c], ODD[3][c]],
        skip: [SKIP[0][c], SKIP[1][c], SKIP[2][c], SKIP[3][c]],
    }
}

/// The tables of component `C` as an associated constant (evaluated at compile time per
/// `C`; an index out of range is a compile error, not a run-time panic).
pub(crate) struct Column<const C: usize>;

impl<const C: usize> Column<C> {
    pub(crate) const TABLES: ComponentTables = component_tables(C);
}

/// Component `C` with its tables as constants, not inlined: each component is scheduled
/// on its own, so the FPU's 32 registers hold one component's work (measured on the M4F
/// for wrench and stiffness: inlined, the compiler interleaved the six components and
/// spilled, 1,320 instructions and 540 B of stack; with the tables passed at run time,
/// 1,437; this way 1,255 and 300 B; these under an earlier `bench` harness that moved
/// the result, +121; two components in one function: no gain, 1,117.0 either way).
#[inline(never)]
fn component_of<const C: usize>(at: &At) -> Component {
    component::<false>(&Column::<C>::TABLES, at)
}

/// One component: the baseline and its rate, then per sweep `w ± D`, `a ± dD/du`, and for
/// x and z `g ± dD/dt`. `w + sign * D` is `w - D` for `sign = -1` (the product is exact,
/// and `w + (-D)` is `w - D` by definition; `+0 + -0 = +0 = +0 - +0`): one multiply-add
/// on the FPU and no branch. Every Horner starts where the tables say (`crate::float::horner`).
///
/// `SHARED`: the sweeps and their Horner evaluations through one out-of-line copy each on
/// soft-float cores ([`add_along_shared`], [`add_across_shared`]: the passivity guard's
/// `float::depth_rate`, whose image has a flash budget, issue 64), else written out per
/// component with the tables' starts as constants (`wrench_and_stiffness`, as fast as
/// before). The same operations either way; on hard-float cores the same code.
#[inline(always)]
pub(crate) fn component<const SHARED: bool>(tables: &ComponentTables, at: &At) -> Component {
    let ComponentTables { baseline, baseline_start, mats, starts, odd, skip } = tables;
    let u = at.u;
    let (w, a) = if SHARED {
        horner_with_rate_from_shared(baseline, u, *baseline_start)
    } else {
        horner_with_rate_from(baseline, u, *baseline_start)
    };
    let mut c = Component { w, a, gx: 0.0, gz: 0.0 };
    let [mx, mz, mtx, mtz] = mats;
    let [sx, sz, stx, stz] = starts;
    let [ox, oz, otx, otz] = *odd;
    let [kx, kz, ktx, ktz] = *skip;
    let [tx, tz, ttx, ttz] = at.t;
    let [nx, nz, ntx, ntz] = at.sign;
    if !kx {
        c.gx += if SHARED { add_along_shared(&mut c, mx, sx, ox, nx, tx, u) } else { add_along::<false>(&mut c, mx, sx, ox, nx, tx, u) };
    }
    if !kz {
        c.gz += if SHARED { add_along_shared(&mut c, mz, sz, oz, nz, tz, u) } else { add_along::<false>(&mut c, mz, sz, oz, nz, tz, u) };
    }
    if !ktx {
        if SHARED {
            add_across_shared(&mut c, mtx, stx, otx, ntx, ttx, u);
        } else {
            add_across::<false>(&mut c, mtx, stx, otx, ntx, ttx, u);
        }
    }
    if !ktz {
        if SHARED {
            add_across_shared(&mut c, mtz, stz, otz, ntz, ttz, u);
        } else {
            add_across::<false>(&mut c, mtz, stz, otz, ntz, ttz, u);
        }
    }
    c
}

/// [`add_across`] with its Horner evaluations shared: one out-of-line copy on soft-float
/// cores, where every f32 operation is a call into the float runtime anyway (flash, issue
/// 64); inlined on hard-float cores (the same code as [`add_across`] there).
#[cfg_attr(target_abi = "eabihf", inline(always))]
#[cfg_attr(not(target_abi = "eabihf"), inline(never))]
fn add_across_shared(c: &mut Component, m: &[[f32; TERMS]; TERMS], s: &MatrixStarts, odd: bool, sign: f32, t: f32, u: f32) {
    add_across::<true>(c, m, s, odd, sign, t, u);
}

/// [`add_along`] as [`add_across_shared`].
#[cfg_attr(target_abi = "eabihf", inline(always))]
#[cfg_attr(not(target_abi = "eabihf"), inline(never))]
fn add_along_shared(c: &mut Component, m: &[[f32; TERMS]; TERMS], s: &MatrixStarts, odd: bool, sign: f32, t: f32, u: f32) -> f32 {
    add_along::<true>(c, m, s, odd, sign, t, u)
}

/// A theta sweep: `w ± D`, `a ± dD/du` (`SHARED`: through the shared Horner).
#[inline(always)]
fn add_across<const SHARED: bool>(c: &mut Component, m: &[[f32; TERMS]; TERMS], s: &MatrixStarts, odd: bool, sign: f32, t: f32, u: f32) {
    let h = |p: &[f32; TERMS], w: f32, start: Start| if SHARED { horner_from_shared(p, w, start) } else { horner_from(p, w, start) };
    let hr = |p: &[f32; TERMS], w: f32, start: Start| {
        if SHARED {
            horner_with_rate_from_shared(p, w, start)
        } else {
            horner_with_rate_from(p, w, start)
        }
    };
    let [m0, m1, m2, m3, m4] = m;
    let [s0, s1, s2, s3, s4] = s.rows;
    let rows = [h(m0, t, s0), h(m1, t, s1), h(m2, t, s2), h(m3, t, s3), h(m4, t, s4)];
    let (dev, du) = hr(&rows, u, s.outer);
    if odd {
        c.w += sign * dev;
        c.a += sign * du;
    } else {
        c.w += dev;
        c.a += du;
    }
}

/// The x or z sweep: as [`add_across`], and `±dD/dt` returned (the caller adds it to the
/// rate by t, `g = g ± dD/dt`), each row evaluated once with its t-rate
/// ([`horner_with_rate_from`]).
#[inline(always)]
fn add_along<const SHARED: bool>(
    c: &mut Component,
    m: &[[f32; TERMS]; TERMS],
    s: &MatrixStarts,
    odd: bool,
    sign: f32,
    t: f32,
    u: f32,
) -> f32 {
    let h = |p: &[f32; TERMS], w: f32, start: Start| if SHARED { horner_from_shared(p, w, start) } else { horner_from(p, w, start) };
    let hr = |p: &[f32; TERMS], w: f32, start: Start| {
        if SHARED {
            horner_with_rate_from_shared(p, w, start)
        } else {
            horner_with_rate_from(p, w, start)
        }
    };
    let [m0, m1, m2, m3, m4] = m;
    let [s0, s1, s2, s3, s4] = s.rows;
    let (r0, q0) = hr(m0, t, s0);
    let (r1, q1) = hr(m1, t, s1);
    let (r2, q2) = hr(m2, t, s2);
    let (r3, q3) = hr(m3, t, s3);
    let (r4, q4) = hr(m4, t, s4);
    let (dev, du) = hr(&[r0, r1, r2, r3, r4], u, s.outer);
    let dt = h(&[q0, q1, q2, q3, q4], u, s.outer_rate);
    if odd {
        c.w += sign * dev;
        c.a += sign * du;
        dt
    } else {
        c.w += dev;
        c.a += du;
        sign * dt
    }
}
