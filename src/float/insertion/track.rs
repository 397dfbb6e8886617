//! The needle's line and the cut track's lateral hold: geometry of one tick.
//!
//! The needle's axis from tip to hub is `a = (-sin θz cos θx, cos θz cos θx, sin θx)`
//! ([`orientation`](crate::orientation)); it crosses the top surface at the entry point
//! `E = (x, 0, z)`; a point of the shaft at path coordinate `q` (mm along the axis below
//! the surface plane) is `S(q) = E - q a`, the tip is at `q = depth`, the hub at
//! `q = depth - HUB_FROM_TIP_MM`.
//!
//! The track is the needle's line at the first puncture (`E0`, `a0`). A shaft point's
//! deviation from it, perpendicular to `a0`, is linear in `q`: `d(q) = D - q G` with
//! `D = perp(E - E0)` and `G = perp(a)` (`perp(v) = v - (v . a0) a0`). A layer holds the
//! shaft with `k` N/mm per mm of shaft: the force density on the needle is `-k d(q)`, so
//! over the part `[q1, q2]` of the shaft in the layer, with `Q1 = q2 - q1`,
//! `Q2 = (q2² - q1²) / 2`, `Q3 = (q2³ - q1³) / 3`:
//!
//! ```text
//! F = -k (D Q1 - G Q2)
//! M = a × k (D (Q2 - qh Q1) - G (Q3 - qh Q2))      about the hub, qh its path coordinate
//! ```
//!
//! (`M = ∫ (S(q) - S(qh)) × f dq` with `S(q) - S(qh) = -(q - qh) a`.) The springs store
//! energy only while the shaft is away from the track and give it back on the way
//! back: they are conservative, and a shaft leaving a layer leaves with it the springs
//! of that part (their force is lateral, so the axial motion that leaves does no work).

/// A vector of the block frame.
pub(crate) type Vec3 = [f32; 3];

const RAD_PER_DEG: f32 = core::f32::consts::PI / 180.0;

/// Largest tilt the geometry takes, degrees: a needle at 90 degrees no longer enters the
/// top surface; tilts beyond are clamped here (the surrogate clamps at its own domain).
pub(crate) const TILT_MAX_DEG: f32 = 89.0;

/// `(sin, cos)` of `deg` degrees, clamped to `±TILT_MAX_DEG`: Taylor polynomials in
/// `x = deg * π/180` (`|x| <= 1.554`) to `x^13` and `x^12`, in plain f32 (Horner, no FMA:
/// the same bits on every target). Truncation error below `x^15/15! < 6e-10` and
/// `x^14/14! < 6.5e-9` at the clamp, under f32 round-off (a few 1e-8). `libm::sinf`
/// works in f64, which costs about a thousand instructions a call on an FPU without
/// double precision (the Cortex-M4F).
// f32::clamp asserts `min <= max` (a panic path for the link-time no-panic check)
#[allow(clippy::manual_clamp)]
pub(crate) fn sin_cos_deg(deg: f32) -> (f32, f32) {
    let d = if deg > TILT_MAX_DEG {
        TILT_MAX_DEG
    } else if deg < -TILT_MAX_DEG {
        -TILT_MAX_DEG
    } else {
        deg
    };
    let x = d * RAD_PER_DEG;
    let x2 = x * x;
    let s = x
        * (1.0
            + x2 * (-1.0 / 6.0
                + x2 * (1.0 / 120.0
                    + x2 * (-1.0 / 5040.0 + x2 * (1.0 / 362_880.0 + x2 * (-1.0 / 39_916_800.0 + x2 * (1.0 / 6_227_020_800.0)))))));
    let c = 1.0
        + x2 * (-0.5
            + x2 * (1.0 / 24.0 + x2 * (-1.0 / 720.0 + x2 * (1.0 / 40_320.0 + x2 * (-1.0 / 3_628_800.0 + x2 * (1.0 / 479_001_600.0))))));
    (s, c)
}

/// The needle's unit axis from tip to hub for the tilts (degrees; NaN stays NaN).
pub(crate) fn axis(theta_x_deg: f32, theta_z_deg: f32) -> Vec3 {
    let (sx, cx) = sin_cos_deg(theta_x_deg);
    let (sz, cz) = sin_cos_deg(theta_z_deg);
    [-sz * cx, cz * cx, sx]
}

pub(crate) fn dot(a: Vec3, b: Vec3) -> f32 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn cross(a: Vec3, b: Vec3) -> Vec3 {
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
}

fn axpy(s: f32, x: Vec3, y: Vec3) -> Vec3 {
    [y[0] + s * x[0], y[1] + s * x[1], y[2] + s * x[2]]
}

/// The track: the needle's line at the first puncture.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub(crate) struct Track {
    /// Entry point on the top surface, mm.
    pub entry_mm: Vec3,
    /// Unit axis from tip to hub.
    pub axis: Vec3,
}

/// Where the shaft is against the track in this tick.
pub(crate) struct Deviation {
    d: Vec3,
    g: Vec3,
    a: Vec3,
    hub_q_mm: f32,
}

impl Track {
    fn perp(&self, v: Vec3) -> Vec3 {
        axpy(-dot(v, self.axis), self.axis, v)
    }

    /// The shaft's deviation for the needle line (`entry_mm`, `a`) whose hub is at path
    /// coordinate `hub_q_mm`.
    pub(crate) fn deviation(&self, entry_mm: Vec3, a: Vec3, hub_q_mm: f32) -> Deviation {
        let rel = [entry_mm[0] - self.entry_mm[0], entry_mm[1] - self.entry_mm[1], entry_mm[2] - self.entry_mm[2]];
        Deviation { d: self.perp(rel), g: self.perp(a), a, hub_q_mm }
    }
}

impl Deviation {
    /// The force (N) and moment about the hub (N·mm) on the needle from the part
    /// `[q1_mm, q2_mm]` of the shaft held with `k` N/mm per mm (the module's formulas),
    /// added to `wrench`.
    pub(crate) fn add_hold(&self, k: f32, q1_mm: f32, q2_mm: f32, wrench: &mut [f32; 6]) {
        let q1 = q2_mm - q1_mm;
        let q2 = (q2_mm * q2_mm - q1_mm * q1_mm) * 0.5;
        let q3 = (q2_mm * q2_mm * q2_mm - q1_mm * q1_mm * q1_mm) * (1.0 / 3.0);
        let qh = self.hub_q_mm;
        // F = -k (D Q1 - G Q2)
        let f = axpy(-q2, self.g, [self.d[0] * q1, self.d[1] * q1, self.d[2] * q1]);
        // M = a × k (D (Q2 - qh Q1) - G (Q3 - qh Q2))
        let (cd, cg) = (q2 - qh * q1, q3 - qh * q2);
        let lever = axpy(-cg, self.g, [self.d[0] * cd, self.d[1] * cd, self.d[2] * cd]);
        let m = cross(self.a, lever);
        let [w0, w1, w2, w3, w4, w5] = wrench;
        *w0 -= k * f[0];
        *w1 -= k * f[1];
        *w2 -= k * f[2];
        *w3 += k * m[0];
        *w4 += k * m[1];
        *w5 += k * m[2];
    }
}
