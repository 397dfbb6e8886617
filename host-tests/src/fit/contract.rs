//! The fixed vocabulary of the model contract (coeffs/README.md): component and sweep
//! order, half-ranges, which components are odd under which sweep's mirror, status bits.

/// Polynomial degree in depth and in each swept variable.
pub const DEGREE: usize = 4;
/// Coefficients per polynomial (`DEGREE + 1`).
pub const NCOEF: usize = DEGREE + 1;

/// Wrench components, in contract order (index c = 0..5). Forces in N, moments in N·mm.
pub const COMPONENTS: [&str; 6] = ["fx_n", "fy_n", "fz_n", "mx_nmm", "my_nmm", "mz_nmm"];

/// Unit of component `c`: `"N"` for forces (c < 3), `"N*mm"` for moments.
pub fn unit(c: usize) -> &'static str {
    if c < 3 {
        "N"
    } else {
        "N*mm"
    }
}

/// Largest depth of the domain, mm.
pub const DEPTH_MAX_MM: f64 = 6.0;

/// A pose in f64: x and z in mm, the tilts in degrees, depth in mm (contract order
/// `[x_mm, z_mm, theta_x_deg, theta_z_deg, depth_mm]`).
pub type Pose64 = [f64; 5];
/// Largest |x|, |z| of the domain, mm.
pub const XZ_MAX_MM: f64 = 12.0;
/// Largest |theta_x|, |theta_z| of the domain, degrees.
pub const THETA_MAX_DEG: f64 = 15.0;

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
        match self {
            Sweep::X => "x",
            Sweep::Z => "z",
            Sweep::ThetaX => "theta_x",
            Sweep::ThetaZ => "theta_z",
        }
    }

    /// Half-range `V_k` of the swept variable (mm for x and z, degrees for the tilts).
    pub fn half_range(self) -> f64 {
        match self {
            Sweep::X | Sweep::Z => XZ_MAX_MM,
            Sweep::ThetaX | Sweep::ThetaZ => THETA_MAX_DEG,
        }
    }

    /// Unit of the swept variable.
    pub fn unit(self) -> &'static str {
        match self {
            Sweep::X | Sweep::Z => "mm",
            Sweep::ThetaX | Sweep::ThetaZ => "deg",
        }
    }

    /// Whether component `c` changes sign under this sweep's mirror: x and theta_z
    /// (mirror x -> -x): fx, my, mz; z and theta_x (mirror z -> -z): fz, mx, my.
    pub fn is_odd(self, c: usize) -> bool {
        match self {
            Sweep::X | Sweep::ThetaZ => matches!(c, 0 | 4 | 5),
            Sweep::Z | Sweep::ThetaX => matches!(c, 2..=4),
        }
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

/// Status bit: x was clamped to the domain.
pub const STATUS_SAT_X: u8 = 0x01;
/// Status bit: z was clamped.
pub const STATUS_SAT_Z: u8 = 0x02;
/// Status bit: theta_x was clamped.
pub const STATUS_SAT_THETA_X: u8 = 0x04;
/// Status bit: theta_z was clamped.
pub const STATUS_SAT_THETA_Z: u8 = 0x08;
/// Status bit: depth was clamped.
pub const STATUS_SAT_DEPTH: u8 = 0x10;
/// Status: an input was NaN or infinite; the wrench is zero and no other bit is set.
pub const STATUS_ERROR: u8 = 0x80;
