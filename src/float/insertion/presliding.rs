//! The shaft's presliding (stuck) state: shaft friction and the tip's cutting force that
//! a needle at rest keeps, relaxing, and that turns over within twice a presliding
//! distance when the motion reverses (issue 65; the `shaft-presliding` feature).
//!
//! **The bristle** (an elasto-plastic, Dahl-like state per layer): `z` in `[-1, 1]`,
//! advanced by the tick's axial step over the layer's presliding distance `p`
//! (`z <- clamp(z + Δd / p, -1, 1)`); at rest it stays, reversing it crosses zero
//! within `p` and turns over within `2 p`.
//!
//! **Relaxation** (the shaft's own Prony terms, [`Presliding::shaft_prony`], FEBio's
//! long-term normalisation `G(t) = 1 + sum g_i exp(-t / tau_i)`, at most three terms):
//! each term is a bristle of its own, `z_i <- clamp(a_i z_i + Δd / p_i, -1, 1)` with the
//! QLV recursion's decay `a_i = exp(-dt / tau_i)` (the library's viscoelastic filter's
//! coefficient) and its slip distance `p_i = p_r tau_i / tau_min`, at most
//! `max(p, p_r)` (`p_r` [`Presliding::relaxation_slip_mm`], the shortest term's: every
//! term slips at the same speed `p_r / tau_min`): a Maxwell arm that slips at its share.
//! Sliding faster than that speed, every `z_i` is at ±1; at rest each decays with its time
//! constant, so a held force relaxes as `G(t) / G(0)` to `1 / (1 + sum g_i)` of the
//! sliding one, by the same share whatever the speed it slid at. A reversal turns each
//! term over within `2 p_i`: the slow terms over millimetres, as the long-term bristle.
//!
//! **Forces** (the tissue file's levels are the sliding ones, as the Karnopp friction's):
//! per mm of shaft in the layer
//! `f = coulomb (z + sum g_i z_i) / (1 + sum g_i) + viscous |v| z` (the viscous part only
//! while `z` has the motion's sign: it never pushes the needle the way it moves); the
//! tip's cutting force while the tip sits in its cut,
//! `cutting w (1 + sum g_i max(z_i, 0)) / (1 + sum g_i)` with `w` 1 at and past the
//! track's end `e`, falling linearly to 0 at `a = max(e - p, c)` behind it, `c` the depth
//! where the tip began to cut the layer (its puncture): the tissue ahead of the tip is
//! loaded over the first `p` of the cut, never at once.
//!
//! **The tissue's tent** ([`Presliding::tent_n_per_mm`], `k`; 0: none): the layer's
//! tissue around the shaft, lifted by a shaft that pulls it, is a spring to the ground in
//! series with its bristles (pushed down it rests on the tissue below: no tent while the
//! held force resists a deeper needle, so insertion and hold are as without one). While
//! the held force pulls, a tick's step `Δd` is shared: the bristles advance by `s`, the
//! solution of `k Δd + ΔR = k s + ΔF(s)`, `ΔR` the force the arms let go over the tick
//! and `ΔF` the bristles' change (piecewise linear: each a spring until it slips), and
//! the tissue by the rest, its lift set each tick to the held pull over `k`. So the pull
//! builds over about `ΔF / k` of travel (millimetres for soft tissue) instead of the
//! bristles' `2 p`, and the lift (capped at the layer's thickness) lengthens the shaft in
//! the layer. The lifted tissue is held by the stuck shaft: its level is the layer's
//! Karnopp static level `c_s` (the Coulomb one while the held force resists), so the
//! slipping pull is about `c_s L / (1 - c_s / k)` and grows while the tissue is lifted.
//! The lift goes when the tip leaves the layer (its length is zero) or the path ends.
//!
//! **Passive**: each bristle is a spring (stiffness `level / p`) that slips at its level,
//! each arm a spring and slider in series with a dashpot; the stored energy of a state is
//! `level ∫ (shaft length) (s - d0) / p ds >= 0` over its elastic stretch, slipping and
//! relaxing only lower it, and `w` is a function of the depth for a fixed track end
//! (which moves only while the tip cuts at full force, storing at most half the work:
//! `cutting (e - a) / 2`). A closed cycle of the insertion alone gives nothing back
//! (`host-tests/tests/insertion_energy.rs` holds it), nor does a ratchet out from inside
//! the tissue beyond what the held force stored (`insertion_ratchet.rs`). The control loop's passivity guard
//! renders the held force through a bristle of its own ([`HeldTerms`] is what it reads
//! of a tick; `control::held_bristle`, `docs/insertion.md`, "Presliding").
use crate::float::viscoelastic::{PronyTerms, MAX_TERMS};
use needle_contract::{MAX_TISSUE_LAYERS as MAX_LAYERS, PRESLIDING_MM_RANGE, RELAXATION_SLIP_MM_RANGE, TENT_N_PER_MM_RANGE};

/// A layer's presliding; [`Presliding::NONE`]: today's Karnopp friction, zero at rest.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Presliding {
    /// The presliding distance `p`, mm (0: none; else within
    /// `needle_contract::PRESLIDING_MM_RANGE`).
    pub distance_mm: f32,
    /// The distance within which the shortest Prony term's arm of the held force is
    /// loaded, mm; each longer term's is it times `tau_i / tau_min`, at most
    /// `max(distance_mm, relaxation_slip_mm)` ([`Presliding::term_slip_mm`]; within
    /// `needle_contract::RELAXATION_SLIP_MM_RANGE`; with no terms, any value in range).
    pub relaxation_slip_mm: f32,
    /// The relaxation of the held shaft force and cutting (none: no relaxation).
    pub shaft_prony: PronyTerms,
    /// The tissue's tent stiffness `k`, N/mm (0: none, the bristles move with the
    /// needle; else within `needle_contract::TENT_N_PER_MM_RANGE`).
    pub tent_n_per_mm: f32,
}

impl Presliding {
    /// No presliding: the layer's Karnopp friction and ramped cutting.
    pub const NONE: Self = Self { distance_mm: 0.0, relaxation_slip_mm: 0.0, shaft_prony: PronyTerms::NONE, tent_n_per_mm: 0.0 };

    /// Whether the layer has a presliding state.
    #[must_use]
    pub fn is_active(&self) -> bool {
        self.distance_mm > 0.0
    }

    /// [`Presliding::NONE`], or a distance within its range and checked terms (the
    /// tissue file's checks).
    #[must_use]
    #[allow(clippy::cast_possible_truncation)] // the range's bounds are exact in f32 to their use
    pub fn is_valid(&self) -> bool {
        let checked = PronyTerms::new(self.shaft_prony.as_slice()).is_ok();
        if !self.is_active() {
            return self.distance_mm == 0.0 && self.relaxation_slip_mm == 0.0 && self.shaft_prony.is_empty() && self.tent_n_per_mm == 0.0;
        }
        let in_range = |d: f32, (lo, hi): (f64, f64)| d.is_finite() && d >= lo as f32 && d <= hi as f32;
        let tent = self.tent_n_per_mm == 0.0 || in_range(self.tent_n_per_mm, TENT_N_PER_MM_RANGE);
        in_range(self.distance_mm, PRESLIDING_MM_RANGE) && in_range(self.relaxation_slip_mm, RELAXATION_SLIP_MM_RANGE) && checked && tent
    }

    /// The slip distance of the shaft term of time constant `tau_s`, mm: the relaxation
    /// slip distance times `tau_s / tau_min` (`tau_min` the shortest of
    /// [`Presliding::shaft_prony`]'s time constants: every term slips at one speed), at
    /// most `max(distance_mm, relaxation_slip_mm)`. The calibration loads each arm within
    /// the stick band's edge times its time constant, at most the presliding distance
    /// (`needle_calibrate::whole::hold::ShaftGuess::slip_mm`): the same distances for a
    /// stack whose `relaxation_slip_mm` is the shortest term's. Without terms (or a
    /// `tau_s` that is not finite and > 0), the relaxation slip distance.
    #[must_use]
    pub fn term_slip_mm(&self, tau_s: f32) -> f32 {
        let shortest = self.shaft_prony.as_slice().iter().map(|t| t.tau_s).fold(f32::INFINITY, f32::min);
        let longest_mm = if self.distance_mm > self.relaxation_slip_mm { self.distance_mm } else { self.relaxation_slip_mm };
        if !(shortest.is_finite() && shortest > 0.0 && tau_s.is_finite() && tau_s > 0.0) {
            return self.relaxation_slip_mm;
        }
        // shortest > 0 (above): no division by zero
        let slip_mm = self.relaxation_slip_mm * (tau_s / shortest);
        if slip_mm < longest_mm {
            slip_mm
        } else {
            longest_mm
        }
    }
}

/// What a passivity guard needs of a tick's presliding beside the rest of
/// [`GuardTerms`](super::GuardTerms) (`Insertion::step_with_stiffness`): the held force,
/// its stiffness, the axis it acts along and the step the bristles advanced by (the
/// control loop's guard renders it through a bristle of its own:
/// `control::held_bristle`).
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct HeldTerms {
    /// The held friction and cutting of every layer with a presliding, N, along the
    /// axis `+a` (towards the hub: resisting a deeper needle when positive); in the
    /// wrench (scaled with it when it was bounded), not in the guard's dissipative force.
    pub force_n: f32,
    /// Its stiffness along the axis, N/mm: the bristles' `level / p` (each arm's share
    /// over `p_r`) summed over the shaft in the layers and the held cutting.
    pub stiffness_n_per_mm: f32,
    /// The needle's axis `a` (unit, block frame).
    pub axis: [f32; 3],
    /// The tick's step along the axis, mm (the depth's change the bristles advanced by).
    pub step_mm: f32,
}

impl HeldTerms {
    /// Nothing held (no presliding layer in the tissue, the needle above the surface,
    /// or a tick without `step_with_stiffness`).
    pub const NONE: Self = Self { force_n: 0.0, stiffness_n_per_mm: 0.0, axis: [0.0; 3], step_mm: 0.0 };

    /// The held force `held` (N, N/mm) of a tick of `step_mm` along the axis `a`, in a
    /// wrench whose force was scaled from `sum_before_n` to `sum_after_n` (the sums of
    /// its components' magnitudes; the same when it was not bounded).
    pub(super) fn new(held: (f32, f32), a: [f32; 3], step_mm: f32, sum_before_n: f32, sum_after_n: f32) -> Self {
        // a bounded wrench (its sum above the bound, > 0) scales the held force with it
        let scale = if sum_after_n == sum_before_n {
            1.0
        } else if sum_before_n.is_finite() && sum_before_n > 0.0 {
            sum_after_n / sum_before_n
        } else {
            0.0
        };
        Self { force_n: held.0 * scale, stiffness_n_per_mm: held.1, axis: a, step_mm }
    }
}

/// A layer's per-tick coefficients (computed once, in `Insertion::new`).
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
struct Coefficients {
    /// `1 / p`, 1/mm (0: the layer has no presliding).
    per_mm: f32,
    /// Each term's `1 / p_i`, 1/mm (0 unused).
    arm_per_mm: [f32; MAX_TERMS],
    /// Each term's decay per tick, `exp(-dt / tau_i)` (0 for an unused term).
    decay: [f32; MAX_TERMS],
    /// Each term's share of the sliding force, `g_i / (1 + sum g)` (0 unused).
    share: [f32; MAX_TERMS],
    /// The long-term share, `1 / (1 + sum g)`.
    long_term: f32,
    /// The tissue's tent stiffness `k`, N/mm (0: none).
    tent: f32,
}

impl Coefficients {
    const NONE: Self =
        Self { per_mm: 0.0, arm_per_mm: [0.0; MAX_TERMS], decay: [0.0; MAX_TERMS], share: [0.0; MAX_TERMS], long_term: 1.0, tent: 0.0 };

    /// The layer's coefficients for ticks of `period_s` (> 0); `None` for a presliding
    /// out of range.
    fn new(p: &Presliding, period_s: f32) -> Option<Self> {
        if !(p.is_valid() && period_s.is_finite() && period_s > 0.0) {
            return None;
        }
        if !p.is_active() {
            return Some(Self::NONE);
        }
        let terms = p.shaft_prony.as_slice();
        let total = 1.0 + terms.iter().map(|t| t.g).sum::<f32>();
        // total >= 1 (every g >= 0, checked), tau_s > 0 and both distances > 0 (checked):
        // no division by zero
        let mut out = Self { per_mm: 1.0 / p.distance_mm, long_term: 1.0 / total, tent: p.tent_n_per_mm, ..Self::NONE };
        for (((a, s), r), t) in out.decay.iter_mut().zip(out.share.iter_mut()).zip(out.arm_per_mm.iter_mut()).zip(terms) {
            *a = libm::expf(-period_s / t.tau_s);
            *s = t.g / total;
            // tau_s >= shortest > 0 (checked): p_i >= p_r > 0
            *r = 1.0 / p.term_slip_mm(t.tau_s);
        }
        Some(out)
    }
}

/// The shaft's presliding for a whole stack: each layer's coefficients and state.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub(super) struct Shaft {
    coefficients: [Coefficients; MAX_LAYERS],
    /// Each layer's bristle `z`.
    z: [f32; MAX_LAYERS],
    /// Each layer's arms `z_i`.
    arms: [[f32; MAX_TERMS]; MAX_LAYERS],
    /// Where the tip began to cut its present layer (its puncture's depth), mm.
    cut_from_mm: f32,
    /// Each layer's tissue displacement along the axis, mm (positive: dragged deeper; 0
    /// without a tent).
    tent_mm: [f32; MAX_LAYERS],
    /// Each layer's sliding level at the last tick (its friction level per mm over the
    /// shaft in it, the static one while lifted), N: the bristles' stiffness the next step
    /// is shared with.
    level_n: [f32; MAX_LAYERS],
}

fn clamp_unit(x: f32) -> f32 {
    x.clamp(-1.0, 1.0)
}

/// The held share of the sliding level: the long-term bristle's and each arm's.
fn held_share(c: &Coefficients, z: f32, arms: &[f32; MAX_TERMS]) -> f32 {
    let mut held = c.long_term * z;
    for (s, arm) in c.share.iter().zip(arms) {
        held += s * arm;
    }
    held
}

/// The step the bristles take when a tent of stiffness `c.tent` (> 0) shares `pull`
/// (N: the tent's stiffness times the needle's step, plus the force the arms let go) with
/// them at level `level_n`, mm: `pull = tent s + ΔF(s)`, `ΔF` their force's change,
/// piecewise linear (each bristle a spring until it reaches its slip at ±1); solved
/// exactly by moving the bristles that would pass their slip to it, at most once each.
fn shared_step(c: &Coefficients, z: f32, arms: &[f32; MAX_TERMS], level_n: f32, pull: f32) -> f32 {
    let dir = if pull > 0.0 { 1.0 } else { -1.0 };
    let mut parts = [(c.long_term * level_n, c.per_mm, z, false); 1 + MAX_TERMS];
    for (part, ((share, arm), rate)) in parts.iter_mut().skip(1).zip(c.share.iter().zip(arms).zip(c.arm_per_mm)) {
        *part = (share * level_n, rate, *arm, false);
    }
    for part in &mut parts {
        part.3 = part.2 * dir >= 1.0;
    }
    let mut s = 0.0;
    for _ in 0..=MAX_TERMS {
        let (mut fixed, mut stiffness) = (0.0, c.tent);
        for &(w, rate, x, at_slip) in &parts {
            if at_slip {
                fixed += w * (dir - x);
            } else {
                stiffness += w * rate;
            }
        }
        // stiffness >= tent > 0: no division by zero
        s = (pull - fixed) / stiffness;
        let mut more = false;
        for part in &mut parts {
            if !part.3 && (part.2 + s * part.1) * dir > 1.0 {
                part.3 = true;
                more = true;
            }
        }
        if !more {
            break;
        }
    }
    s
}

impl Shaft {
    /// The coefficients of the layers' `presliding` for ticks of `period_s`, every state
    /// at rest; `None` for a presliding out of range.
    pub(super) fn new<'a>(presliding: impl Iterator<Item = &'a Presliding>, period_s: f32) -> Option<Self> {
        let mut coefficients = [Coefficients::NONE; MAX_LAYERS];
        for (c, p) in coefficients.iter_mut().zip(presliding) {
            *c = Coefficients::new(p, period_s)?;
        }
        Some(Self {
            coefficients,
            z: [0.0; MAX_LAYERS],
            arms: [[0.0; MAX_TERMS]; MAX_LAYERS],
            cut_from_mm: 0.0,
            tent_mm: [0.0; MAX_LAYERS],
            level_n: [0.0; MAX_LAYERS],
        })
    }

    /// One tick of `step_mm` along the axis (0: at rest, or a glitch tick: the arms relax).
    pub(super) fn advance(&mut self, step_mm: f32) {
        for (((c, z), arms), level_n) in self.coefficients.iter().zip(self.z.iter_mut()).zip(self.arms.iter_mut()).zip(self.level_n) {
            if c.per_mm <= 0.0 {
                continue;
            }
            let before = held_share(c, *z, arms);
            if c.tent > 0.0 && before <= 0.0 {
                // the arms relax first; the tissue, lifted in equilibrium with the held
                // pull before, follows what they let go and the step: the bristles see the
                // rest
                for (arm, a) in arms.iter_mut().zip(c.decay) {
                    *arm *= a;
                }
                let pull = c.tent * step_mm + level_n * (before - held_share(c, *z, arms));
                let s = shared_step(c, *z, arms, level_n, pull);
                *z = clamp_unit(*z + s * c.per_mm);
                for (arm, rate) in arms.iter_mut().zip(c.arm_per_mm) {
                    *arm = clamp_unit(*arm + s * rate);
                }
            } else {
                *z = clamp_unit(*z + step_mm * c.per_mm);
                for ((arm, a), rate) in arms.iter_mut().zip(c.decay).zip(c.arm_per_mm) {
                    *arm = clamp_unit(a * *arm + step_mm * rate);
                }
            }
        }
    }

    /// Every state at rest (the path ended).
    pub(super) fn reset(&mut self) {
        self.z = [0.0; MAX_LAYERS];
        self.arms = [[0.0; MAX_TERMS]; MAX_LAYERS];
        self.cut_from_mm = 0.0;
        self.tent_mm = [0.0; MAX_LAYERS];
        self.level_n = [0.0; MAX_LAYERS];
    }

    /// The shaft in layer `j` counting the tissue lifted with it, mm, for `length_mm` of
    /// shaft below the layer's boundary (0: the tip is above the layer), the lift capped
    /// at the layer's `thickness_mm`.
    fn lifted_length_mm(&self, j: usize, length_mm: f32, thickness_mm: f32) -> f32 {
        match self.tent_mm.get(j) {
            Some(&u) if length_mm > 0.0 && u < 0.0 => length_mm + if -u < thickness_mm { -u } else { thickness_mm },
            _ => length_mm,
        }
    }

    /// The tip has left layer `j`: its tissue lets go of the shaft (no lift, no level).
    pub(super) fn release(&mut self, j: usize) {
        if let (Some(u), Some(l)) = (self.tent_mm.get_mut(j), self.level_n.get_mut(j)) {
            (*u, *l) = (0.0, 0.0);
        }
    }

    /// A boundary punctured with the tip at `depth_mm`: the tip begins to cut there.
    pub(super) fn punctured(&mut self, depth_mm: f32) {
        self.cut_from_mm = depth_mm;
    }

    /// Layer `j`'s held friction over `length_mm` of shaft below its boundary, moving at
    /// `v` (mm/s, its viscous part zero when against the last motion), and its stiffness:
    /// `(N, N/mm)`, of the force's sign along the axis; `None` when the layer has no
    /// presliding (its Karnopp friction). `levels`: the layer's Coulomb and static levels,
    /// N/mm, and its viscous one, N·s/mm². The level per mm is the static one while the
    /// tent is lifted (the stuck shaft holds the tissue with it), else the Coulomb one (the
    /// held force is zero where they meet); the length counts the lifted tissue (capped at
    /// `thickness_mm`); the layer's tissue is then settled in equilibrium with the held
    /// force (without its viscous part), the level kept for the next step.
    pub(super) fn held_friction(&mut self, j: usize, levels: [f32; 3], v: f32, length_mm: f32, thickness_mm: f32) -> Option<(f32, f32)> {
        let (c, z, arms) = self.layer(j)?;
        let (tent, held) = (c.tent, held_share(c, z, arms));
        let [coulomb, static_level, viscous] = levels;
        let per_mm = if tent > 0.0 && held < 0.0 { static_level } else { coulomb };
        let viscous = if z * v > 0.0 { viscous * libm::fabsf(v) * z } else { 0.0 };
        let f = per_mm * held + viscous;
        let length_mm = self.lifted_length_mm(j, length_mm, thickness_mm);
        let level_n = per_mm * length_mm;
        let pull = level_n * held;
        if let (Some(u), Some(l)) = (self.tent_mm.get_mut(j), self.level_n.get_mut(j)) {
            *l = level_n;
            // only lifted (a pull), tent > 0: no division by zero
            *u = if tent > 0.0 && pull < 0.0 { pull / tent } else { 0.0 };
        }
        Some((length_mm * f, self.stiffness(j, level_n)))
    }

    /// Layer `j`'s cutting force `cutting_n` held at the tip, N, with the tip at
    /// `depth_mm` and the track's end at `track_end_mm`; `None` when the layer has no
    /// presliding.
    pub(super) fn cutting(&self, j: usize, cutting_n: f32, depth_mm: f32, track_end_mm: f32) -> Option<f32> {
        let (c, _, arms) = self.layer(j)?;
        // per_mm > 0 (`layer`): the distance is finite and > 0
        let behind = track_end_mm - 1.0 / c.per_mm;
        let from = if behind > self.cut_from_mm { behind } else { self.cut_from_mm };
        let span = track_end_mm - from;
        let w = if depth_mm >= track_end_mm {
            1.0
        } else if span > 0.0 {
            ((depth_mm - from) / span).clamp(0.0, 1.0)
        } else {
            0.0
        };
        let mut held = c.long_term;
        for (s, arm) in c.share.iter().zip(arms) {
            held += s * if *arm > 0.0 { *arm } else { 0.0 };
        }
        Some(cutting_n * w * held)
    }

    /// The stiffness along the axis of layer `j`'s bristles holding `level_n` (its shaft
    /// friction or its cutting at their sliding level), N/mm: the long-term share over
    /// `p`, each arm's share over `p_r`; 0 without presliding.
    pub(super) fn stiffness(&self, j: usize, level_n: f32) -> f32 {
        let s = level_n * self.gain(j);
        match self.coefficients.get(j) {
            // in series with the tissue's tent (s >= 0, tent > 0: no division by zero)
            Some(c) if c.tent > 0.0 => s * c.tent / (s + c.tent),
            _ => s,
        }
    }

    /// The bristles' stiffness per unit level, 1/mm.
    fn gain(&self, j: usize) -> f32 {
        self.coefficients.get(j).map_or(0.0, |c| c.long_term * c.per_mm + c.share.iter().zip(c.arm_per_mm).map(|(s, r)| s * r).sum::<f32>())
    }

    fn layer(&self, j: usize) -> Option<(&Coefficients, f32, &[f32; MAX_TERMS])> {
        let c = self.coefficients.get(j).filter(|c| c.per_mm > 0.0)?;
        Some((c, self.z.get(j).copied()?, self.arms.get(j)?))
    }
}
