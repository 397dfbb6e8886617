//! Passivity of the whole insertion on a 1-DOF device: 1,000 random trajectories
//! (insert, hold, withdraw, re-insert, jitter, leave) through every shipped stack, the
//! insertion model's force held between ticks (zero-order hold, 1 kHz), the hand moving
//! the needle along the vertical axis at the centre.
//!
//! The hand grips the device's handle and prescribes its motion `d(t)` (depth, mm), a
//! chain of smoothstep moves `d = d0 + Δ (3u² - 2u³)` that start and end at rest; the
//! device has mass `m` and physical damping `b`. The energy the device delivers to the
//! hand over a trajectory that starts and ends at rest, outside the tissue (a closed
//! cycle: the insertion state is back to its start, the needle above the surface), is
//!
//! ```text
//! E = Σ_k F_k Δd_k - b ∫ ḋ² dt       (N·mm; the mass gives back what it took)
//! ```
//!
//! with `F_k` the rendered axial force of tick k (fy, upward on the needle, resisting a
//! depth increase, so its power into the hand is `-fy ḋ`... written with the sign here:
//! the hand does work `fy Δd` against it) held over the tick's depth change `Δd_k`, and
//! `∫ ḋ² dt = 1.2 Δ² / T` exactly for each smoothstep move of length Δ and duration T.
//! Passive: `E <= 0` for every trajectory.
//!
//! The bound 1e-9 J (1e-6 N·mm) on what f32 round-off may add: the sums run in f64 over
//! f32 forces; a conservative field evaluated exactly would give `Σ F Δd` = the work
//! of the field, and f32 rounding of each force (relative 6e-8 of at most a few N)
//! over a path of at most 400 mm of travel changes it by less than 400 * 3 N * 6e-8 =
//! 7e-5 N·mm in the worst case, but only its non-cancelling part accumulates: the
//! dissipation of friction and puncture over any path is orders above it, so the
//! assertion is `E <= 1e-6 N·mm`.
use needle_haptics::insertion::{stacks, Insertion, InsertionConfig, Layer, Stack};
use needle_haptics::viscoelastic::{PronyTerm, PronyTerms};
use needle_haptics::Pose;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

const PERIOD_S: f64 = 0.001;
/// Device damping along the insertion, N·s/mm (1 N·s/m).
const DAMPING_N_S_PER_MM: f64 = 0.001;
const TRAJECTORIES: usize = 1000;
const BOUND_NMM: f64 = 1e-6;

/// One smoothstep move: from `from_mm` to `to_mm` over `duration_s`.
#[derive(Clone, Copy, Debug)]
struct Move {
    from_mm: f64,
    to_mm: f64,
    duration_s: f64,
}

impl Move {
    fn at(&self, t: f64) -> f64 {
        let u = (t / self.duration_s).clamp(0.0, 1.0);
        self.from_mm + (self.to_mm - self.from_mm) * u * u * (3.0 - 2.0 * u)
    }
    fn damping_integral(&self) -> f64 {
        // ∫ ḋ² dt over the move
        if self.duration_s > 0.0 {
            1.2 * (self.to_mm - self.from_mm).powi(2) / self.duration_s
        } else {
            0.0
        }
    }
}

/// Where the hand is at the end of `moves` (it starts 1 mm above the surface).
fn at(moves: &[Move]) -> f64 {
    moves.last().map_or(-1.0, |m| m.to_mm)
}

/// Appends a move from where the hand is to `to_mm` at about `speed_mm_per_s`.
fn go(moves: &mut Vec<Move>, to_mm: f64, speed_mm_per_s: f64) {
    let from_mm = at(moves);
    let duration_s = ((to_mm - from_mm).abs() / speed_mm_per_s).max(0.002);
    moves.push(Move { from_mm, to_mm, duration_s });
}

/// A random trajectory: start above the surface, a few random actions, leave.
fn trajectory(rng: &mut ChaCha8Rng, deepest_mm: f64) -> Vec<Move> {
    let mut moves = Vec::new();
    for _ in 0..rng.gen_range(2..8) {
        match rng.gen_range(0..5) {
            0 | 1 => {
                let to = rng.gen_range(0.0..deepest_mm);
                go(&mut moves, to, rng.gen_range(0.5..30.0));
            }
            2 => {
                let here = at(&moves);
                moves.push(Move { from_mm: here, to_mm: here, duration_s: rng.gen_range(0.01..0.5) });
            }
            3 => {
                let to = (at(&moves) - rng.gen_range(0.0..10.0)).max(-0.5);
                go(&mut moves, to, rng.gen_range(0.5..30.0));
            }
            _ => {
                let amplitude = rng.gen_range(0.005..0.5);
                let centre = at(&moves);
                for _ in 0..rng.gen_range(2..12) {
                    go(&mut moves, centre + amplitude, rng.gen_range(1.0..60.0));
                    go(&mut moves, centre - amplitude, rng.gen_range(1.0..60.0));
                }
                go(&mut moves, centre, 10.0);
            }
        }
    }
    go(&mut moves, -1.0, rng.gen_range(2.0..30.0));
    moves
}

/// Whether the hand goes below the surface (the others only dissipate in the device's
/// damping, or not even that: the report's worst case is over these).
fn enters(moves: &[Move]) -> bool {
    moves.iter().any(|m| m.to_mm > 0.0)
}

/// The hand's depth at time `t` along the chain of moves (the last one's end after it).
fn depth_at(moves: &[Move], mut t: f64) -> f64 {
    for m in moves {
        if t <= m.duration_s {
            return m.at(t);
        }
        t -= m.duration_s;
    }
    moves.last().map_or(0.0, |m| m.to_mm)
}

/// The energy delivered to the hand over the trajectory (N·mm), and the punctures: the
/// insertion model's own force.
fn energy(stack: &Stack<'_>, moves: &[Move]) -> (f64, usize) {
    let mut insertion = Insertion::new(stack, InsertionConfig::DEFAULT_1KHZ).expect("shipped stack");
    energy_of(moves, DAMPING_N_S_PER_MM, |p| {
        let e = insertion.step(&p);
        (e.wrench.fy_n, e.punctures)
    })
}

/// The energy delivered to the hand (N·mm) and the punctures, the force of each tick
/// from `render(pose)` (its fy and the tick's punctures), on a device of damping
/// `damping_n_s_per_mm`.
fn energy_of(moves: &[Move], damping_n_s_per_mm: f64, mut render: impl FnMut(Pose) -> (f32, u8)) -> (f64, usize) {
    let total_s: f64 = moves.iter().map(|m| m.duration_s).sum();
    let damping: f64 = moves.iter().map(|m| damping_n_s_per_mm * m.damping_integral()).sum();
    let (mut work, mut punctures) = (0.0, 0);
    let mut tick: u64 = 0;
    loop {
        let t = tick as f64 * PERIOD_S;
        if t >= total_s {
            break;
        }
        let d = depth_at(moves, t);
        let (fy_n, p) = render(Pose { depth_mm: d as f32, ..Pose::default() });
        punctures += usize::from(p);
        // the force of tick k, held until tick k + 1 (or the end of the trajectory)
        let next = ((tick + 1) as f64 * PERIOD_S).min(total_s);
        work += f64::from(fy_n) * (depth_at(moves, next) - d);
        tick += 1;
    }
    // the hand did `work` against the force (fy resists a depth increase): the device
    // gives `-work` back to the hand, minus what its damping took
    (-work - damping, punctures)
}

#[test]
fn no_closed_cycle_delivers_energy_to_the_hand() {
    assert!(!stacks::ALL.is_empty(), "the default set ships tissue stacks");
    for stack in &stacks::ALL {
        no_closed_cycle_delivers_energy(stack, TRAJECTORIES);
    }
}

/// Prony terms for the filter-on runs: inputs that exercise the filter, not a tissue's
/// values (of the shipped stacks only the epidural skin has a term, `coeffs/default/tissue/`,
/// and the stacks as shipped run too). `moderate`: weights
/// of the order a soft tissue relaxes by over three decades of time constants;
/// `extreme`: the largest sum the format allows (9) with time constants of the
/// trajectories' own time scales (1 ms to 0.1 s), where the filter acts most.
fn test_terms() -> [(&'static str, PronyTerms); 2] {
    let t = |g: f32, tau_s: f32| PronyTerm { g, tau_s };
    [
        ("moderate", PronyTerms::new(&[t(0.8, 0.05), t(0.5, 1.0), t(0.3, 20.0)]).expect("valid terms")),
        ("extreme", PronyTerms::new(&[t(3.0, 0.001), t(3.0, 0.01), t(3.0, 0.1)]).expect("valid terms")),
    ]
}

/// `stack`'s layers with `terms` on every layer.
fn with_terms(stack: &Stack<'_>, terms: PronyTerms) -> Vec<Layer> {
    stack.layers.iter().map(|l| Layer { prony: terms, ..*l }).collect()
}

/// The passivity test of the insertion model with the viscoelastic filter on every layer
/// of every shipped stack (a third of the trajectories each, both sets of terms), and the
/// guarded loop's (100 trajectories each, both sets). The extreme set through the guarded
/// loop failed before the guard filtered after limiting (issue 39: 18.5 N·mm delivered on
/// an epidural trajectory; the old rule reinstated on this insertion as a mutation
/// delivers 0.034 N·mm on epidural trajectory 21): the guard's offset then integrated the
/// relaxing viscous force, which is not a function of the path.
#[test]
fn with_the_viscoelastic_filter_no_closed_cycle_delivers_energy() {
    for stack in &stacks::ALL {
        for (label, terms) in test_terms() {
            let layers = with_terms(stack, terms);
            let name = format!("{} with {label} Prony terms", stack.name);
            let filtered = Stack { name: &name, layers: &layers, ..*stack };
            no_closed_cycle_delivers_energy(&filtered, TRAJECTORIES / 3);
            the_guarded_loop_delivers_no_energy(&filtered, 100);
        }
    }
}

/// Every shipped stack with the shaft's presliding (issue 65) on every layer, with and
/// without the moderate shaft terms, each run through `check`. The presliding distance of
/// each stack is set from Colgate's condition of the insertion test's device, not from a
/// tissue: the zero-order hold delivers `(K / 2) Σ Δd²` for a rendered stiffness `K` and
/// the device's damping takes `(b / T) Σ Δd²`, so the held force's stiffness (the
/// stack's largest cutting force plus all its shaft friction, over `p`) is kept at half
/// of `b / T` (`p = 2 (cutting + friction) T / b`, at least 0.5 mm); a stiffer bristle
/// is the guard's to render (`control::passivity`).
fn for_each_presliding_stack(check: impl FnMut(&Stack<'_>)) {
    for_each_presliding_stack_with_tent(0.0, check);
}

/// [`for_each_presliding_stack`] with the tissue's tent `tent_n_per_mm` (N/mm, 0: none)
/// on every layer.
fn for_each_presliding_stack_with_tent(tent_n_per_mm: f32, mut check: impl FnMut(&Stack<'_>)) {
    use needle_haptics::insertion::Presliding;
    for stack in &stacks::ALL {
        let held_n: f64 = stack.layers.iter().map(|l| f64::from(l.cutting_force_n)).fold(0.0, f64::max)
            + stack.layers.iter().map(|l| f64::from(l.friction.coulomb_n_per_mm * l.thickness_mm)).sum::<f64>();
        let p_mm = (2.0 * held_n * PERIOD_S / DAMPING_N_S_PER_MM).max(0.5) as f32;
        for (label, shaft_prony) in [("no", PronyTerms::NONE), test_terms()[0]] {
            let layers: Vec<Layer> = stack
                .layers
                .iter()
                .map(|l| Layer { presliding: Presliding { distance_mm: p_mm, relaxation_slip_mm: p_mm, shaft_prony, tent_n_per_mm }, ..*l })
                .collect();
            let name = format!("{} with presliding {p_mm} mm, {label} shaft terms and tent {tent_n_per_mm} N/mm", stack.name);
            check(&Stack { name: &name, layers: &layers, ..*stack });
        }
    }
}

/// The passivity test with the shaft's presliding on every layer of every shipped stack
/// ([`for_each_presliding_stack`]): held friction and cutting are springs that slip
/// (`insertion::presliding`), so a closed cycle must give nothing back.
#[test]
fn with_the_shaft_presliding_no_closed_cycle_delivers_energy() {
    for_each_presliding_stack(|held| no_closed_cycle_delivers_energy(held, TRAJECTORIES / 3));
}

/// The same with the tissue's tent on every layer (a soft one, 0.1 N/mm, and a stiff
/// one, 2 N/mm: the rig's fits lie between): the lifted tissue is a spring in series with
/// the bristles, and the shaft it lengthens is held at the lifted level; a closed cycle
/// must still give nothing back.
#[test]
fn with_the_tissue_s_tent_no_closed_cycle_delivers_energy() {
    for tent in [0.1, 2.0] {
        for_each_presliding_stack_with_tent(tent, |held| no_closed_cycle_delivers_energy(held, TRAJECTORIES / 3));
    }
}

/// The tent's stacks through the guarded loop on the weakly damped device (the held
/// force's stiffness the guard reads is the bristles' in series with the tent).
#[test]
fn with_the_tissue_s_tent_the_guarded_loop_delivers_no_energy() {
    for tent in [0.1, 2.0] {
        for_each_presliding_stack_with_tent(tent, |held| the_guarded_loop_delivers_no_energy(held, 100));
    }
}

/// The same stacks through the guarded loop on the weakly damped device (0.1 N·s/m:
/// the held force's stiffness, about `b / (2 T)` of the stronger device, is five times
/// the guard's). Before the guard rendered the held force as a bristle of its own
/// (`control::passivity`, "Presliding") it scaled the held force's changes like an
/// elastic force's, and its offset, no longer a function of the path (the held force
/// turns over on a reversal), delivered 15.8 N·mm on the liver's trajectory 2.
#[test]
fn with_the_shaft_presliding_the_guarded_loop_delivers_no_energy() {
    for_each_presliding_stack(|held| the_guarded_loop_delivers_no_energy(held, 100));
}

fn no_closed_cycle_delivers_energy(stack: &Stack<'_>, trajectories: usize) {
    {
        // one generator per stack: a stack added does not change another's trajectories
        let mut rng = ChaCha8Rng::seed_from_u64(20261126);
        let deepest: f64 = stack.layers.iter().map(|l| f64::from(l.thickness_mm)).sum::<f64>() + 5.0;
        let (mut worst, mut punctured) = (f64::NEG_INFINITY, 0);
        for n in 0..trajectories {
            let moves = trajectory(&mut rng, deepest);
            let (e, p) = energy(stack, &moves);
            punctured += usize::from(p > 0);
            assert!(e <= BOUND_NMM, "{}: trajectory {n} delivered {e:e} N·mm to the hand: {moves:?}", stack.name);
            if enters(&moves) {
                worst = worst.max(e);
            }
        }
        println!("{}: {trajectories} trajectories ({punctured} with a puncture), most energy to the hand of those entering the tissue {worst:e} N·mm", stack.name);
        assert!(punctured > trajectories / 4, "{}: only {punctured} trajectories punctured: the test must cross punctures", stack.name);
    }
}

/// The same through the control loop: `LoopCore` renders the insertion with the
/// passivity guard on, on a device of a tenth of the damping above (0.1 N·s/m, so the
/// guard's stiffness `b / T` = 0.1 N/mm is below the liver's deflection stiffness and the
/// guard acts), the commanded fy held over each tick. A closed cycle still delivers no
/// energy: the guard's offset is a function of the path in depth while a boundary
/// deflects, and a puncture clears it (the force drops; nothing stored is given back).
#[test]
fn the_loop_with_the_guard_delivers_no_energy_either() {
    for stack in &stacks::ALL {
        the_guarded_loop_delivers_no_energy(stack, 300);
    }
}

/// The guarded loops' configuration: one channel on Fy, limits far above the forces, and
/// the passivity guard for a device of damping `damping_n_s_per_mm` at the test's period.
fn guarded_loop_setup(damping_n_s_per_mm: f64) -> (needle_haptics::control::LoopConfig<1>, needle_haptics::control::Passivity) {
    use needle_haptics::control::{ChannelMap, LoopConfig, OverLimit, Passivity};
    let config = LoopConfig {
        channels: [ChannelMap { gains_per_n: [0.0, 0.01, 0.0], direction_inverted: false }],
        force_limit_n: 100.0,
        force_limit_max_n: 100.0,
        over_limit: OverLimit::Saturate,
        ramp_step_n: 0.01,
    };
    (config, Passivity { damping_n_s_per_mm: damping_n_s_per_mm as f32, period_s: PERIOD_S as f32 })
}

fn the_guarded_loop_delivers_no_energy(stack: &Stack<'_>, loop_trajectories: usize) {
    use needle_haptics::control::{LoopCore, LoopFlags};
    const WEAK_DAMPING_N_S_PER_MM: f64 = 0.0001;
    let (config, guard) = guarded_loop_setup(WEAK_DAMPING_N_S_PER_MM);
    {
        // one generator per stack: a stack added does not change another's trajectories
        let mut rng = ChaCha8Rng::seed_from_u64(20261127);
        let deepest: f64 = stack.layers.iter().map(|l| f64::from(l.thickness_mm)).sum::<f64>() + 5.0;
        let (mut worst, mut worst_punctured, mut limited, mut punctured) = (f64::NEG_INFINITY, f64::NEG_INFINITY, 0, 0);
        for n in 0..loop_trajectories {
            let moves = trajectory(&mut rng, deepest);
            let mut core = LoopCore::new(config).expect("config");
            core.set_passivity(Some(guard)).expect("guard");
            core.set_insertion(Some(Insertion::new(stack, InsertionConfig::DEFAULT_1KHZ).expect("shipped stack")));
            let mut was_limited = false;
            let (e, p) = energy_of(&moves, WEAK_DAMPING_N_S_PER_MM, |pose| {
                let s = core.step(Ok(pose));
                was_limited |= s.flags.contains(LoopFlags::STIFFNESS_LIMITED);
                (s.force_cmd_n[1], core.insertion_evaluation().map_or(0, |e| e.punctures))
            });
            limited += usize::from(was_limited);
            punctured += usize::from(p > 0);
            assert!(e <= BOUND_NMM, "{}: trajectory {n} through the loop delivered {e:e} N·mm to the hand: {moves:?}", stack.name);
            if enters(&moves) {
                worst = worst.max(e);
            }
            if p > 0 {
                worst_punctured = worst_punctured.max(e);
            }
        }
        println!(
            "{}: {loop_trajectories} trajectories through the guarded loop ({limited} stiffness-limited, {punctured} punctured), most energy to the hand of those entering the tissue {worst:e} N·mm, of those puncturing {worst_punctured:e} N·mm",
            stack.name
        );
        assert!(limited > loop_trajectories / 4, "{}: the guard acted in only {limited} trajectories", stack.name);
        assert!(punctured > loop_trajectories / 4, "{}: only {punctured} trajectories punctured", stack.name);
    }
}

/// Colgate's ratio measured through the guarded loop: the hand holds the needle on a
/// deflected boundary (the first layer of every stack, four times as stiff, its puncture
/// force raised so that it holds) and oscillates it by the samples `d_k = d0 + A sin(θ k + π/4)` (the phase:
/// not zero at every sample of the Nyquist frequency), θ = wT from a
/// fifth of the Nyquist frequency to it. The energy the loop's zero-order hold gives the
/// hand over whole periods, `W = -Σ F_k (d_{k+1} - d_k)`, over the device damping's
/// discrete budget `(b / T) Σ (d_{k+1} - d_k)²` is `r = K_eff T / (2 b)` for a rendered
/// spring of stiffness `K_eff` (`-Σ K d_k Δd_k = (K / 2) Σ Δd_k²` over a closed cycle):
/// Colgate's condition is `r < 1` at every frequency, and the guard renders at
/// `GUARD_FRACTION` of the bound, so `r <= 0.5`. With the viscoelastic filter `K_eff`
/// is `rho(θ) K`; the guard bounds it by the largest `rho`, at the Nyquist frequency,
/// so there `r` reaches 0.5: the assertion is `r <= 0.5 (1 + 1%)` (1%: the surrogate's
/// stiffness changes over the oscillation's 2A = 0.04 mm, the guard scales each tick's
/// change by the stiffness at its end), and `r >= 0.45` at the Nyquist frequency for
/// terms whose `rho` exceeds the tick gain `1 + sum b_i` (the extreme set: 9.77 against
/// 8.74, so a guard bounding by the tick gain gives 0.559 and fails).
#[test]
fn the_guarded_loop_renders_at_half_colgates_bound_at_every_frequency() {
    use needle_haptics::control::GUARD_FRACTION;
    let elastic = ("elastic", PronyTerms::NONE);
    for stack in &stacks::ALL {
        for (label, terms) in [elastic, test_terms()[0], test_terms()[1]] {
            // four times as stiff: the guard acts over the whole oscillation in either stack
            let first = stack.layers[0];
            let layer = Layer { prony: terms, puncture_force_n: 1.0e3, stiffness_scale: 4.0 * first.stiffness_scale, ..first };
            let layers = [layer];
            let one = Stack { layers: &layers, ..*stack };
            let d0 = 0.5 * f64::from(layer.thickness_mm).min(6.0);
            let worst = colgate_ratios(&one, d0, label);
            assert!(worst <= f64::from(GUARD_FRACTION) * 1.01, "{} {label}: r = {worst}", stack.name);
            if label == "extreme" {
                assert!(worst >= 0.45, "{} {label}: the largest r {worst} is not near the guard's 0.5", stack.name);
            }
        }
    }
}

/// The same with the shaft's presliding: the first layer of every stack punctured, its
/// shaft held (a presliding of 1 mm, so the bristles' `level / p` is above the guard's
/// share), the second layer's boundary (four times as stiff, holding) deflected. The
/// guard renders the held force at `HELD_SHARE k_g` and the boundary within the rest,
/// so together they stay at `GUARD_FRACTION` of the bound, and reach it at the Nyquist
/// frequency (`r >= 0.45`: a guard that left the held stiffness out of the boundary's
/// budget would render above 0.5).
#[test]
fn with_the_shaft_presliding_the_guarded_loop_renders_at_half_colgates_bound() {
    use needle_haptics::control::GUARD_FRACTION;
    use needle_haptics::insertion::Presliding;
    let presliding = Presliding { distance_mm: 1.0, relaxation_slip_mm: 1.0, shaft_prony: PronyTerms::NONE, tent_n_per_mm: 0.0 };
    for stack in &stacks::ALL {
        let (first, second) = (stack.layers[0], stack.layers[1]);
        let held = Layer { presliding, ..first };
        let below = Layer { presliding, puncture_force_n: 1.0e3, stiffness_scale: 4.0 * second.stiffness_scale, ..second };
        let layers = [held, below];
        let two = Stack { layers: &layers, ..*stack };
        let d0 = f64::from(first.thickness_mm) + 0.5 * f64::from(second.thickness_mm).min(6.0);
        let worst = colgate_ratios(&two, d0, "presliding");
        assert!(worst <= f64::from(GUARD_FRACTION) * 1.01, "{} presliding: r = {worst}", stack.name);
        assert!(worst >= 0.45, "{} presliding: the largest r {worst} is not near the guard's 0.5", stack.name);
    }
}

/// Colgate's ratio `r` through the guarded loop (the test above) with the needle held at
/// `d0_mm` on a deflected boundary of `stack` and oscillated at each θ; the largest.
fn colgate_ratios(stack: &Stack<'_>, d0_mm: f64, label: &str) -> f64 {
    use needle_haptics::control::{LoopCore, LoopFlags};
    const WEAK_DAMPING_N_S_PER_MM: f64 = 0.0001;
    const AMPLITUDE_MM: f64 = 0.02;
    let (config, guard) = guarded_loop_setup(WEAK_DAMPING_N_S_PER_MM);
    let mut worst = 0.0f64;
    // θ = π p / q: a period is 2q / p ticks, so 2q ticks are whole periods
    for (p, q) in [(1usize, 5usize), (1, 2), (4, 5), (9, 10), (19, 20), (1, 1)] {
        let fraction = p as f64 / q as f64;
        let theta = std::f64::consts::PI * fraction;
        let mut core = LoopCore::new(config).expect("config");
        core.set_passivity(Some(guard)).expect("guard");
        core.set_insertion(Some(Insertion::new(stack, InsertionConfig::DEFAULT_1KHZ).expect("stack")));
        // in at 5 mm/s from 1 mm above, then 2 s held (the filter relaxes; what
        // still relaxes drifts linearly over the oscillation, which gives no net work
        // over whole periods of a sine about d0)
        let ramp_ticks = ((d0_mm + 1.0) / 5.0 / PERIOD_S) as usize;
        let hold_ticks = 2000;
        let depth = |k: usize| -> f64 {
            if k < ramp_ticks {
                -1.0 + (d0_mm + 1.0) * k as f64 / ramp_ticks as f64
            } else if k < ramp_ticks + hold_ticks {
                d0_mm
            } else {
                d0_mm + AMPLITUDE_MM * (theta * (k - ramp_ticks - hold_ticks) as f64 + std::f64::consts::FRAC_PI_4).sin()
            }
        };
        // the oscillation: 200 ticks or more of warm-up, then 1,000 or more measured,
        // each a whole number of periods
        let whole = |ticks: usize| ticks.div_ceil(2 * q) * 2 * q;
        let start = ramp_ticks + hold_ticks + whole(200);
        let end = start + whole(1000);
        let (mut work, mut budget, mut limited, mut punctures) = (0.0f64, 0.0f64, true, 0);
        for k in 0..end {
            let s = core.step(Ok(Pose { depth_mm: depth(k) as f32, ..Pose::default() }));
            if k >= start {
                let step = f64::from(depth(k + 1) as f32) - f64::from(depth(k) as f32);
                work -= f64::from(s.force_cmd_n[1]) * step;
                budget += WEAK_DAMPING_N_S_PER_MM / PERIOD_S * step * step;
                limited &= s.flags.contains(LoopFlags::STIFFNESS_LIMITED);
                punctures += core.insertion_evaluation().map_or(0, |e| e.punctures);
            }
        }
        let r = work / budget;
        println!("{} {label}: wT = {fraction:.2} pi, energy to the hand over the damping's budget {r:.4}", stack.name);
        assert!(limited, "{} {label}: the guard must act in every tick of the oscillation", stack.name);
        assert_eq!(punctures, 0, "{} {label}: the boundary holds", stack.name);
        worst = worst.max(r);
    }
    worst
}

/// A glitch of the pose stream (issue 66), drawn per tick: with probability 2 % the
/// hand's pose is replaced by one of a faulty encoder's (depth or x at ±1e6 mm, depth
/// 100 mm further, a tilt of 60 degrees, NaN); the hand itself moves on as before.
fn glitched(rng: &mut ChaCha8Rng, p: Pose) -> Pose {
    if rng.gen_range(0..50) != 0 {
        return p;
    }
    match rng.gen_range(0..6) {
        0 => Pose { depth_mm: 1.0e6, ..p },
        1 => Pose { depth_mm: -1.0e6, ..p },
        2 => Pose { x_mm: 1.0e6, ..p },
        3 => Pose { depth_mm: p.depth_mm + 100.0, ..p },
        4 => Pose { theta_x_deg: 60.0, ..p },
        _ => Pose { depth_mm: f32::NAN, ..p },
    }
}

/// Issue 66: with glitches in the pose stream (2 % of the ticks, [`glitched`]) no closed
/// cycle delivers energy either, through the insertion alone and through the guarded
/// loop: a glitch tick holds the last wrench (or none), integrates nothing.
#[test]
fn with_glitches_in_the_pose_stream_no_closed_cycle_delivers_energy() {
    for stack in &stacks::ALL {
        glitched_cycles_deliver_no_energy(stack, 300);
    }
}

/// The glitch test with the shaft's presliding on every layer
/// ([`for_each_presliding_stack`]): a glitch tick advances no bristle (the arms relax),
/// and the guard's bristle keeps its state over it.
#[test]
fn with_the_shaft_presliding_and_glitches_no_closed_cycle_delivers_energy() {
    for_each_presliding_stack(|held| glitched_cycles_deliver_no_energy(held, 100));
}

/// `trajectories` random trajectories through `stack` with glitches in the pose stream,
/// through the insertion alone and through the guarded loop.
fn glitched_cycles_deliver_no_energy(stack: &Stack<'_>, trajectories: usize) {
    use needle_haptics::control::LoopCore;
    {
        let mut rng = ChaCha8Rng::seed_from_u64(20261206);
        let mut glitches = ChaCha8Rng::seed_from_u64(66);
        let deepest: f64 = stack.layers.iter().map(|l| f64::from(l.thickness_mm)).sum::<f64>() + 5.0;
        let (mut worst, mut worst_loop, mut punctured, mut flagged, mut fast_hand) =
            (f64::NEG_INFINITY, f64::NEG_INFINITY, 0, 0usize, 0usize);
        const WEAK_DAMPING_N_S_PER_MM: f64 = 0.0001;
        let (config, guard) = guarded_loop_setup(WEAK_DAMPING_N_S_PER_MM);
        for n in 0..trajectories {
            let moves = trajectory(&mut rng, deepest);
            let mut insertion = Insertion::new(stack, InsertionConfig::DEFAULT_1KHZ).expect("shipped stack");
            let (e, p) = energy_of(&moves, DAMPING_N_S_PER_MM, |pose| {
                let g = glitched(&mut glitches, pose);
                let e = insertion.step(&g);
                flagged += usize::from(e.flags.is_glitch());
                // the clean poses rejected: the hand faster than the largest speed
                fast_hand += usize::from(e.flags.is_glitch() && g == pose);
                (e.wrench.fy_n, e.punctures)
            });
            punctured += usize::from(p > 0);
            assert!(e <= BOUND_NMM, "{}: glitched trajectory {n} delivered {e:e} N·mm to the hand: {moves:?}", stack.name);
            let mut core = LoopCore::new(config).expect("config");
            core.set_passivity(Some(guard)).expect("guard");
            core.set_insertion(Some(Insertion::new(stack, InsertionConfig::DEFAULT_1KHZ).expect("shipped stack")));
            let (e_loop, _) = energy_of(&moves, WEAK_DAMPING_N_S_PER_MM, |pose| {
                let s = core.step(Ok(glitched(&mut glitches, pose)));
                (s.force_cmd_n[1], core.insertion_evaluation().map_or(0, |e| e.punctures))
            });
            assert!(
                e_loop <= BOUND_NMM,
                "{}: glitched trajectory {n} through the guarded loop delivered {e_loop:e} N·mm: {moves:?}",
                stack.name
            );
            if enters(&moves) {
                worst = worst.max(e);
                worst_loop = worst_loop.max(e_loop);
            }
        }
        println!(
            "{}: {trajectories} glitched trajectories ({punctured} punctured, {flagged} glitch ticks, {fast_hand} of them clean poses), most energy to the hand of those entering: {worst:e} N·mm, through the guarded loop {worst_loop:e} N·mm",
            stack.name
        );
        // about 2 % of some 2,000 ticks a trajectory are glitches
        assert!(
            punctured > trajectories / 4 && flagged > 10 * trajectories / 3,
            "{}: the test must cross punctures and glitches",
            stack.name
        );
    }
}
