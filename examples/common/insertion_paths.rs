//! The golden insertion trajectories: shared, as source, by the `insertion_golden`
//! firmware (QEMU) and the host tests that run the same ticks on the host, through the
//! C API and in wasm (host-tests/tests/insertion_golden.rs includes this file), so every
//! platform steps the same f32 poses. Plain f32 arithmetic (no FMA, no libm): the same
//! bits everywhere.
//!
//! Each path is a list of waypoints `(ticks to reach it, [x_mm, z_mm, theta_x_deg,
//! theta_z_deg, depth_mm])` from a start pose above the surface; between two waypoints
//! every input moves linearly, `a + (b - a) * (k / n)` at tick k of n. 1 kHz.
#![allow(dead_code)]

/// One waypoint: ticks to reach it from the previous one, and the pose there.
pub type Waypoint = (u32, [f32; 5]);

/// Five paths: a slow straight insertion and withdrawal; insert, hold, partial
/// withdrawal, re-insertion past the deepest point, leave; an offset tilted needle that
/// drifts sideways and tilts inside the track; jitter in depth at a puncture and deep
/// inside; fast in and out twice.
pub const PATHS: [&[Waypoint]; 5] = [
    &[(1, [0.0, 0.0, 0.0, 0.0, -1.0]), (14_000, [0.0, 0.0, 0.0, 0.0, 41.0]), (14_000, [0.0, 0.0, 0.0, 0.0, -1.0])],
    &[
        (1, [0.0, 0.0, 0.0, 0.0, -1.0]),
        (2_600, [0.0, 0.0, 0.0, 0.0, 25.0]),
        (200, [0.0, 0.0, 0.0, 0.0, 25.0]),
        (1_500, [0.0, 0.0, 0.0, 0.0, 10.0]),
        (3_000, [0.0, 0.0, 0.0, 0.0, 35.0]),
        (300, [0.0, 0.0, 0.0, 0.0, 35.0]),
        (3_600, [0.0, 0.0, 0.0, 0.0, -1.0]),
    ],
    &[
        (1, [2.0, -1.0, 5.0, -3.0, -1.0]),
        (6_000, [2.0, -1.0, 5.0, -3.0, 29.0]),
        (1_000, [2.5, -0.8, 6.0, -2.0, 31.0]),
        (1_000, [1.5, -1.2, 3.0, -4.0, 31.0]),
        (6_400, [2.0, -1.0, 5.0, -3.0, -1.0]),
    ],
    &[
        (1, [0.0, 0.0, 0.0, 0.0, -1.0]),
        (5_000, [0.0, 0.0, 0.0, 0.0, 14.0]),
        (40, [0.0, 0.0, 0.0, 0.0, 14.3]),
        (40, [0.0, 0.0, 0.0, 0.0, 13.9]),
        (40, [0.0, 0.0, 0.0, 0.0, 14.3]),
        (40, [0.0, 0.0, 0.0, 0.0, 13.9]),
        (3_000, [0.0, 0.0, 0.0, 0.0, 23.0]),
        (25, [0.0, 0.0, 0.0, 0.0, 23.2]),
        (25, [0.0, 0.0, 0.0, 0.0, 22.9]),
        (25, [0.0, 0.0, 0.0, 0.0, 23.2]),
        (25, [0.0, 0.0, 0.0, 0.0, 22.9]),
        (4_000, [0.0, 0.0, 0.0, 0.0, -1.0]),
    ],
    &[
        (1, [-1.0, 1.5, -2.0, 4.0, -1.0]),
        (1_300, [-1.0, 1.5, -2.0, 4.0, 38.0]),
        (1_300, [-1.0, 1.5, -2.0, 4.0, -1.0]),
        (1_300, [-1.0, 1.5, -2.0, 4.0, 38.0]),
        (1_300, [-1.0, 1.5, -2.0, 4.0, -1.0]),
    ],
];

/// One kind of glitch (issue 66: what a faulty encoder or pose stream gives): the tick's
/// pose with one input replaced, or an earlier pose replayed.
#[derive(Clone, Copy)]
pub enum Glitch {
    /// `depth_mm` set to this value, mm.
    Depth(f32),
    /// `x_mm` set to this value, mm.
    X(f32),
    /// `theta_x_deg` set to this value, degrees.
    TiltX(f32),
    /// `depth_mm` NaN (in Q16.16: `NaN as i32`, 0).
    NotANumber,
    /// `z_mm` infinite (in Q16.16: saturated, `i32::MAX`).
    Infinite,
    /// The pose of this many ticks before (time going backwards), at most
    /// [`HISTORY`] - 1.
    Back(u32),
}

/// How many earlier poses a [`Glitch::Back`] can reach.
pub const HISTORY: usize = 32;

/// A run of glitches: `(first tick, count, stride, glitch)`, the glitch at ticks `first +
/// k stride` for `k < count`.
pub type GlitchRun = (u32, u32, u32, Glitch);

/// The glitch paths: a golden path of [`PATHS`] (by index) with glitches laid over it,
/// numbered after [`PATHS`] (path 5, 6, 7). Issue 66's cases: a depth jump of 1e6 mm
/// while deflecting and one while cutting, with the path's tilt; x jumping to 1e6 mm while
/// cutting, and alternating every tick; NaN, infinity, poses replayed backwards; an
/// in-domain jump of depth (to 120 mm) and of tilt (to 60 degrees).
pub const GLITCH_PATHS: [(usize, &[GlitchRun]); 3] = [
    (
        0,
        &[
            (4_000, 1, 1, Glitch::Depth(1.0e6)),
            (9_000, 1, 1, Glitch::NotANumber),
            (11_000, 3, 1, Glitch::Back(20)),
            (20_000, 1, 1, Glitch::X(1.0e6)),
        ],
    ),
    (
        2,
        &[
            (3_000, 1, 1, Glitch::Depth(1.0e6)),
            (5_000, 60, 2, Glitch::X(1.0e6)),
            (5_500, 1, 1, Glitch::TiltX(60.0)),
            (6_500, 1, 1, Glitch::Infinite),
            (12_000, 10, 1, Glitch::Back(25)),
        ],
    ),
    (
        3,
        &[
            (2_400, 1, 1, Glitch::Depth(120.0)),
            (5_100, 1, 1, Glitch::X(-1.0e9)),
            (8_200, 40, 1, Glitch::Depth(1.0e6)),
            (10_000, 1, 1, Glitch::Back(31)),
        ],
    ),
];

/// Every golden path: [`PATHS`], then [`GLITCH_PATHS`].
pub const PATH_COUNT: usize = PATHS.len() + GLITCH_PATHS.len();

/// The glitch of `runs` at `tick`, if any.
fn glitch_at(runs: &[GlitchRun], tick: u32) -> Option<Glitch> {
    for &(first, count, stride, g) in runs {
        let (since, stride) = (tick.wrapping_sub(first), stride.max(1));
        if tick >= first && since / stride * stride == since && since / stride < count {
            return Some(g);
        }
    }
    None
}

/// Path `i` of [`PATH_COUNT`] (its waypoints and glitch runs; none for [`PATHS`]).
fn path_and_glitches(i: usize) -> (&'static [Waypoint], &'static [GlitchRun]) {
    match PATHS.get(i) {
        Some(p) => (p, &[]),
        None => match GLITCH_PATHS.get(i - PATHS.len()) {
            Some(&(base, runs)) => (PATHS.get(base).copied().unwrap_or(&[]), runs),
            None => (&[], &[]),
        },
    }
}

/// Every tick's pose of path `i` of [`PATH_COUNT`] (f32, [`for_each_tick`]), with its
/// glitches laid over it (the clean poses are the history [`Glitch::Back`] replays).
pub fn for_each_path_tick(i: usize, depth_scale: f32, mut f: impl FnMut(u32, [f32; 5])) {
    let (path, runs) = path_and_glitches(i);
    let mut history = [[0.0f32; 5]; HISTORY];
    for_each_tick(path, depth_scale, |tick, p| {
        history[tick as usize % HISTORY] = p;
        let mut q = p;
        match glitch_at(runs, tick) {
            None => {}
            Some(Glitch::Depth(v)) => q[4] = v,
            Some(Glitch::X(v)) => q[0] = v,
            Some(Glitch::TiltX(v)) => q[2] = v,
            Some(Glitch::NotANumber) => q[4] = f32::NAN,
            Some(Glitch::Infinite) => q[1] = f32::INFINITY,
            Some(Glitch::Back(k)) => q = history[(tick as usize + HISTORY - (k as usize % HISTORY)) % HISTORY],
        }
        f(tick, q);
    });
}

/// Every tick's Q16.16 pose of path `i` of [`PATH_COUNT`] ([`for_each_tick_q16`]), with
/// its glitches laid over it in Q16.16 ([`q16`] of the glitch's value: saturated; NaN 0).
pub fn for_each_path_tick_q16(i: usize, depth_scale: f32, mut f: impl FnMut(u32, [i32; 5])) {
    let (path, runs) = path_and_glitches(i);
    let mut history = [[0i32; 5]; HISTORY];
    let one = |v: f32| q16([v, 0.0, 0.0, 0.0, 0.0])[0];
    for_each_tick_q16(path, depth_scale, |tick, p| {
        history[tick as usize % HISTORY] = p;
        let mut q = p;
        match glitch_at(runs, tick) {
            None => {}
            Some(Glitch::Depth(v)) => q[4] = one(v),
            Some(Glitch::X(v)) => q[0] = one(v),
            Some(Glitch::TiltX(v)) => q[2] = one(v),
            Some(Glitch::NotANumber) => q[4] = one(f32::NAN),
            Some(Glitch::Infinite) => q[1] = one(f32::INFINITY),
            Some(Glitch::Back(k)) => q = history[(tick as usize + HISTORY - (k as usize % HISTORY)) % HISTORY],
        }
        f(tick, q);
    });
}

/// The deepest waypoint of [`PATHS`], mm: the stack depth they were drawn for.
pub const PATHS_DEEPEST_MM: f32 = deepest();

const fn deepest() -> f32 {
    let mut d = 0.0f32;
    let mut paths: &[&[Waypoint]] = &PATHS;
    while let [path, rest @ ..] = paths {
        let mut waypoints: &[Waypoint] = path;
        while let [(_, p), more @ ..] = waypoints {
            if p[4] > d {
                d = p[4];
            }
            waypoints = more;
        }
        paths = rest;
    }
    d
}

/// The factor on every waypoint's depth for `stack`: 1 for a stack no thicker than
/// [`PATHS_DEEPEST_MM`] (the paths as drawn: the `liver`), else its total thickness over
/// it, so the paths reach as far down a thicker stack (the `epidural`'s epidural space).
/// Plain f32 (a sum in layer order, one division): the same bits everywhere.
pub fn depth_scale(stack: &needle_haptics::insertion::Stack<'_>) -> f32 {
    let mut total = 0.0f32;
    for l in stack.layers {
        total += l.thickness_mm;
    }
    if total > PATHS_DEEPEST_MM {
        total / PATHS_DEEPEST_MM
    } else {
        1.0
    }
}

/// Every tick's pose of `path`, its waypoints' depths times `depth_scale`, in order,
/// passed to `f(tick, pose)`.
pub fn for_each_tick(path: &[Waypoint], depth_scale: f32, mut f: impl FnMut(u32, [f32; 5])) {
    let scaled = |(n, mut p): Waypoint| {
        p[4] *= depth_scale;
        (n, p)
    };
    let Some(&(_, start)) = path.first().map(|w| scaled(*w)).as_ref() else { return };
    let mut tick = 0u32;
    f(tick, start);
    let mut from = start;
    for (n, to) in path.iter().skip(1).map(|w| scaled(*w)) {
        for k in 1..=n {
            tick += 1;
            let u = k as f32 / n as f32;
            let mut p = [0.0f32; 5];
            for ((q, a), b) in p.iter_mut().zip(from).zip(to) {
                *q = a + (b - a) * u;
            }
            f(tick, p);
        }
        from = to;
    }
}

/// A waypoint's pose in Q16.16 (mm and degrees times 65536, rounded to nearest): the
/// fixed-point insertion's input.
pub fn q16(pose: [f32; 5]) -> [i32; 5] {
    pose.map(|v| (v * 65536.0 + if v < 0.0 { -0.5 } else { 0.5 }) as i32)
}

/// Every tick's Q16.16 pose of `path`, its waypoints' depths times `depth_scale` (in
/// f32, as [`for_each_tick`]), in order, passed to `f(tick, pose)`: the waypoints in
/// Q16.16 ([`q16`]), and between two of them, at tick k of n, `a + (b - a) k / n` in
/// integers (`i64`, the quotient rounded toward zero).
pub fn for_each_tick_q16(path: &[Waypoint], depth_scale: f32, mut f: impl FnMut(u32, [i32; 5])) {
    let scaled = |mut p: [f32; 5]| {
        p[4] *= depth_scale;
        q16(p)
    };
    let Some(&(_, start)) = path.first() else { return };
    let mut tick = 0u32;
    let start = scaled(start);
    f(tick, start);
    let mut from = start;
    for &(n, to) in path.iter().skip(1) {
        let to = scaled(to);
        for k in 1..=n {
            tick += 1;
            let mut p = [0i32; 5];
            for ((q, a), b) in p.iter_mut().zip(from).zip(to) {
                *q = a + ((i64::from(b) - i64::from(a)) * i64::from(k) / i64::from(n)) as i32;
            }
            f(tick, p);
        }
        from = to;
    }
}

/// FNV-1a over 32-bit words: the digest of a path's outputs (each tick's six wrench
/// bits, status, phase code, punctures and flags).
#[derive(Clone, Copy)]
pub struct Digest(pub u64);

impl Digest {
    /// The empty digest.
    pub const fn new() -> Self {
        Self(0xcbf2_9ce4_8422_2325)
    }
    /// Adds one tick: the six wrench bits, the status, the phase code, the punctures and
    /// the step's flags.
    pub fn tick(&mut self, wrench: [f32; 6], status: u8, phase: u16, punctures: u8, flags: u8) {
        for c in wrench {
            self.word(c.to_bits());
        }
        self.word(u32::from(status));
        self.word(u32::from(phase));
        self.word(u32::from(punctures));
        self.word(u32::from(flags));
    }

    /// Adds one fixed-point tick: the six wrench integers (µN, µN·mm), the status, the
    /// phase code, the punctures and the step's flags.
    pub fn tick_fixed(&mut self, wrench: [i32; 6], status: u8, phase: u16, punctures: u8, flags: u8) {
        for c in wrench {
            self.word(c as u32);
        }
        self.word(u32::from(status));
        self.word(u32::from(phase));
        self.word(u32::from(punctures));
        self.word(u32::from(flags));
    }

    /// Adds one word.
    pub fn word(&mut self, w: u32) {
        for b in w.to_le_bytes() {
            self.0 ^= u64::from(b);
            self.0 = self.0.wrapping_mul(0x0000_0100_0000_01b3);
        }
    }
}
