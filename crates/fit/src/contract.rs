//! The fixed vocabulary of the model contract (coeffs/README.md): component and sweep
//! order, half-ranges, which components are odd under which sweep's mirror, status bits.
//!
//! The constants are the `needle-contract` crate's, where each is defined once.
pub use needle_contract::{COMPONENTS, COMPONENT_COUNT, DEGREE, DEPTH_MAX_MM, TERMS as NCOEF, THETA_MAX_DEG, XZ_MAX_MM};

/// Unit of component `c`: `"N"` for forces (the contract's first `FORCE_COUNT`), `"N*mm"` for moments.
pub fn unit(c: usize) -> &'static str {
    needle_contract::UNITS.get(c).copied().unwrap_or("?")
}

/// A pose in f64: x and z in mm, the tilts in degrees, depth in mm (contract order
/// `[x_mm, z_mm, theta_x_deg, theta_z_deg, depth_mm]`).
pub type Pose64 = [f64; 5];

/// One of the four single-axis sweeps, in contract order (index k = 0..3).
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum Sweep {
    /// Tip x, mm.
    X,
    /// Tip z, mm.
    Z,
    /// Tilt about x, degrees.
    ThetaX,
    /// Tilt about z, degrees.
    ThetaZ,
}

impl Sweep {
    /// All sweeps in contract order.
    pub const ALL: [Sweep; 4] = [Sweep::X, Sweep::Z, Sweep::ThetaX, Sweep::ThetaZ];

    /// Index k in contract order.
    pub fn index(self) -> usize {
        self as usize
    }

    /// The name used in model.toml: `x`, `z`, `theta_x`, `theta_z`.
    pub fn name(self) -> &'static str {
        needle_contract::SWEEPS[self.index()]
    }

    /// Half-range `V_k` of the swept variable (mm for x and z, degrees for the tilts).
    pub fn half_range(self) -> f64 {
        needle_contract::HALF_RANGES[self.index()]
    }

    /// Unit of the swept variable.
    pub fn unit(self) -> &'static str {
        needle_contract::SWEEP_UNITS[self.index()]
    }

    /// Whether component `c` changes sign under this sweep's mirror: x and theta_z
    /// (mirror x -> -x): fx, my, mz; z and theta_x (mirror z -> -z): fz, mx, my.
    pub fn is_odd(self, c: usize) -> bool {
        needle_contract::ODD[self.index()].get(c).copied().unwrap_or(false)
    }

    /// Normalised sweep variable of the fit, `t = |v| * 2 / V_k - 1` (f64).
    pub fn t_of(self, v: f64) -> f64 {
        v.abs() * 2.0 / self.half_range() - 1.0
    }
}

/// Normalised depth of the fit, `u = d / 3 - 1` (f64, d in mm).
pub fn u_of(depth_mm: f64) -> f64 {
    depth_mm / 3.0 - 1.0
}

pub use needle_contract::status::{
    ERROR as STATUS_ERROR, FE_UNSOLVED as STATUS_FE_UNSOLVED, SAT_DEPTH as STATUS_SAT_DEPTH, SAT_THETA_X as STATUS_SAT_THETA_X,
    SAT_THETA_Z as STATUS_SAT_THETA_Z, SAT_X as STATUS_SAT_X, SAT_Z as STATUS_SAT_Z,
};
