//! The quasi-linear viscoelastic filter (`needle_haptics::viscoelastic`) against the
//! closed-form QLV response of a ramp-and-hold (f64, written from the convolution
//! integral, not from the recursion), its passivity on random closed cycles, the
//! normalisation conversion against the two relaxation functions it relates, and the
//! refusals.
use needle_haptics::viscoelastic::{PronyTerm, PronyTerms, Qlv, QlvCoefficients, QlvError, QlvState, WrenchQlv};

const TICK_S: f32 = 0.001;

fn terms() -> PronyTerms {
    // three decades of time constants, weights of the order a soft tissue relaxes by
    // (test values for the filter's arithmetic, not a tissue's)
    PronyTerms::new(&[PronyTerm { g: 0.8, tau_s: 0.05 }, PronyTerm { g: 0.5, tau_s: 1.0 }, PronyTerm { g: 0.3, tau_s: 20.0 }])
        .expect("valid terms")
}

/// The QLV response to `S_e(t) = rate t` for `t <= ramp_s`, then held: the convolution
/// `S_e(t) + sum g_i int_0^t exp(-(t - s) / tau_i) dS_e(s)` in closed form.
fn ramp_hold_exact(terms: &PronyTerms, rate: f64, ramp_s: f64, t: f64) -> f64 {
    let tr = t.min(ramp_s);
    let elastic = rate * tr;
    let viscous: f64 = terms
        .as_slice()
        .iter()
        .map(|p| {
            let (g, tau) = (f64::from(p.g), f64::from(p.tau_s));
            // int_0^tr exp(-(t - s)/tau) rate ds
            g * rate * tau * ((-(t - tr) / tau).exp() - (-t / tau).exp())
        })
        .sum();
    elastic + viscous
}

#[test]
fn ramp_and_hold_matches_the_closed_form() {
    let terms = terms();
    for (rate, ramp_ticks) in [(1.0f64, 6000usize), (3.0, 2000), (10.0, 600)] {
        let mut q = Qlv::new(&terms, TICK_S).expect("filter");
        let (ramp_s, hold_ticks) = (ramp_ticks as f64 * f64::from(TICK_S), 30_000usize);
        let mut peak = 0.0f64;
        let mut worst = 0.0f64;
        for n in 1..=ramp_ticks + hold_ticks {
            let t = n as f64 * f64::from(TICK_S);
            let elastic = rate * t.min(ramp_s);
            let got = f64::from(q.step(elastic as f32));
            let want = ramp_hold_exact(&terms, rate, ramp_s, t);
            peak = peak.max(want.abs());
            worst = worst.max((got - want).abs());
        }
        println!("rate {rate}/s, ramp {ramp_ticks} ticks + 30 s hold: largest error {worst:.3e} of peak {peak:.4}");
        assert!(worst <= 5e-5 * peak, "rate {rate}: error {worst:e} against peak {peak}");
        // the hold relaxes towards the elastic value: after 30 s only the 20 s term is left
        let end = f64::from(q.step((rate * ramp_s) as f32));
        assert!(end > rate * ramp_s && end < rate * ramp_s * 1.3, "rate {rate}: end of hold {end}");
    }
}

#[test]
fn faster_loading_gives_a_larger_force_at_the_same_displacement() {
    let terms = terms();
    let at_6 = |rate: f32| {
        let mut q = Qlv::new(&terms, TICK_S).expect("filter");
        let ticks = (6.0 / (rate * TICK_S)).round() as usize;
        let mut out = 0.0;
        for n in 1..=ticks {
            out = q.step(rate * TICK_S * n as f32);
        }
        out
    };
    let (slow, mid, fast) = (at_6(1.0), at_6(3.0), at_6(10.0));
    println!("force at 6 (elastic 6): 1/s {slow}, 3/s {mid}, 10/s {fast}");
    assert!(6.0 < slow && slow < mid && mid < fast && fast < 6.0 * terms.instantaneous_ratio());
}

/// Work done on the filter, `sum S dx` with `x` the input, over random closed cycles
/// (the input returns to its start): never negative (passive).
#[test]
fn random_closed_cycles_only_dissipate() {
    let terms = terms();
    let mut seed = 0x2545_f491_4f6c_dd1du64;
    let mut next = move || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed >> 11) as f64 / (1u64 << 53) as f64
    };
    let mut least = f64::INFINITY;
    for _ in 0..200 {
        let mut q = Qlv::new(&terms, TICK_S).expect("filter");
        let ticks = 200 + (next() * 3000.0) as usize;
        let (mut x, mut work) = (0.0f64, 0.0f64);
        let mut out_prev = 0.0f64;
        let mut path: Vec<f64> = (0..ticks).map(|_| next() * 2.0 - 1.0).collect();
        // a closed cycle: the steps sum to zero, then hold at the start for 5 s
        let mean = path.iter().sum::<f64>() / ticks as f64;
        path.iter_mut().for_each(|d| *d -= mean);
        path.extend(std::iter::repeat_n(0.0, 5000));
        for d in path {
            let x_next = x + d * 0.01;
            let out = f64::from(q.step(x_next as f32));
            // the force is linear over the tick (the filter's premise): trapezoid
            work += 0.5 * (out_prev + out) * (x_next - x);
            (x, out_prev) = (x_next, out);
        }
        least = least.min(work);
    }
    println!("least work over 200 closed cycles: {least:e}");
    assert!(least >= -1e-9, "a closed cycle delivered {least:e}");
}

#[test]
fn the_wrench_filter_is_the_scalar_filter_per_component() {
    let terms = terms();
    let mut w = WrenchQlv::new(&terms, TICK_S).expect("filter");
    let mut s: Vec<Qlv> = (0..6).map(|_| Qlv::new(&terms, TICK_S).expect("filter")).collect();
    for n in 0..500 {
        let input: [f32; 6] = core::array::from_fn(|c| ((n * (c + 1)) as f32 * 0.01).sin() * (c as f32 + 1.0));
        let out = w.step(input);
        for c in 0..6 {
            assert_eq!(out[c].to_bits(), s[c].step(input[c]).to_bits(), "tick {n} component {c}");
        }
    }
    // no terms: the input passes, bit for bit, and the state stays at rest
    let mut state = QlvState::REST;
    let none = QlvCoefficients::new(&PronyTerms::NONE, TICK_S).expect("coefficients");
    let input = [1.5, -2.0, 3.25, 0.1, -0.2, 0.3];
    assert_eq!(state.step(&none, input), input);
    assert_eq!(state, QlvState::REST);
}

#[test]
fn reset_forgets_the_stored_response() {
    let terms = terms();
    let mut q = Qlv::new(&terms, TICK_S).expect("filter");
    for n in 1..=100 {
        q.step(n as f32 * 0.01);
    }
    q.reset();
    let fresh = Qlv::new(&terms, TICK_S).expect("filter");
    assert_eq!(q, fresh);
}

/// `G0 (1 - sum g' (1 - e_i)) = G_inf (1 + sum g e_i)` with `G_inf = G0 (1 - sum g')` at
/// every t: the two normalisations describe the same relaxation.
#[test]
fn instantaneous_normalised_weights_convert_to_the_same_relaxation() {
    let published = [PronyTerm { g: 0.35, tau_s: 0.2 }, PronyTerm { g: 0.25, tau_s: 4.0 }, PronyTerm { g: 0.1, tau_s: 60.0 }];
    let converted = PronyTerms::from_instantaneous_normalised(&published).expect("sum < 1");
    let sum_prime: f64 = published.iter().map(|p| f64::from(p.g)).sum();
    for t in [0.0f64, 0.01, 0.1, 1.0, 10.0, 100.0, 1000.0] {
        let abaqus: f64 = 1.0 - published.iter().map(|p| f64::from(p.g) * (1.0 - (-t / f64::from(p.tau_s)).exp())).sum::<f64>();
        let febio: f64 =
            (1.0 - sum_prime) * (1.0 + converted.as_slice().iter().map(|p| f64::from(p.g) * (-t / f64::from(p.tau_s)).exp()).sum::<f64>());
        assert!((abaqus - febio).abs() < 1e-6, "t = {t} s: {abaqus} against {febio}");
    }
    assert_eq!(
        PronyTerms::from_instantaneous_normalised(&[PronyTerm { g: 0.6, tau_s: 1.0 }, PronyTerm { g: 0.4, tau_s: 2.0 }]),
        Err(QlvError::WeightSum),
        "no long-term response"
    );
}

#[test]
fn bad_terms_are_refused() {
    let ok = PronyTerm { g: 0.5, tau_s: 1.0 };
    let cases: [(&[PronyTerm], QlvError); 7] = [
        (&[ok, ok, ok, ok], QlvError::TermCount),
        (&[PronyTerm { g: -0.1, tau_s: 1.0 }], QlvError::Weight),
        (&[PronyTerm { g: f32::NAN, tau_s: 1.0 }], QlvError::Weight),
        (&[PronyTerm { g: 0.5, tau_s: 0.0 }], QlvError::TimeConstant),
        (&[PronyTerm { g: 0.5, tau_s: -1.0 }], QlvError::TimeConstant),
        (&[PronyTerm { g: 0.5, tau_s: f32::INFINITY }], QlvError::TimeConstant),
        (&[PronyTerm { g: 5.0, tau_s: 1.0 }, PronyTerm { g: 4.5, tau_s: 2.0 }], QlvError::WeightSum),
    ];
    for (t, e) in cases {
        assert_eq!(PronyTerms::new(t), Err(e), "{t:?}");
    }
    assert!(PronyTerms::new(&[PronyTerm { g: 5.0, tau_s: 1.0 }, PronyTerm { g: 4.0, tau_s: 2.0 }]).is_ok(), "sum 9 is allowed");
    // the sum is taken in f32, in order (the filter's arithmetic): 4 + (5 + 1 ulp) rounds to
    // 9 and is allowed, 4 + (5 + 2 ulp) is the next f32 above 9 and is refused; `new` and
    // `from_array` agree
    let over = |ulps: u32| {
        let g = (0..ulps).fold(5.0f32, |g, _| g.next_up());
        [PronyTerm { g: 4.0, tau_s: 1.0 }, PronyTerm { g, tau_s: 2.0 }, PronyTerm::default()]
    };
    assert!(PronyTerms::new(&over(1)[..2]).is_ok());
    assert!(PronyTerms::from_array(over(1), 2).is_some());
    assert_eq!(PronyTerms::new(&over(2)[..2]), Err(QlvError::WeightSum));
    assert_eq!(PronyTerms::from_array(over(2), 2), None);
    let nine = [PronyTerm { g: 4.0, tau_s: 1.0 }, PronyTerm { g: 5.0, tau_s: 2.0 }, PronyTerm::default()];
    assert_eq!(PronyTerms::from_array(nine, 2).ok_or(QlvError::WeightSum), PronyTerms::new(&nine[..2]));
    for tick in [0.0, -0.001, f32::NAN] {
        assert_eq!(Qlv::new(&terms(), tick), Err(QlvError::Tick));
    }
}

/// The fixed-point filter (`needle_haptics::fixed::viscoelastic`, integers only) on the
/// same ramp-and-hold, in µN Q16, against the same closed form; and through its
/// conversion from the f32 terms.
#[test]
fn the_fixed_point_filter_matches_the_closed_form() {
    use needle_haptics::fixed::viscoelastic as fx;
    let terms = terms();
    let fixed_terms = fx::PronyTerms::from_f32(&terms);
    let k = fx::QlvCoefficients::new(&fixed_terms, 1000).expect("in range");
    // forces of a few newtons, in µN Q16 (6 N at the end of the ramp)
    let unit = 1.0e6 * 65536.0;
    for (rate, ramp_ticks) in [(1.0f64, 6000usize), (3.0, 2000), (10.0, 600)] {
        let mut state = fx::QlvState::REST;
        let ramp_s = ramp_ticks as f64 * 1e-3;
        let (mut peak, mut worst) = (0.0f64, 0.0f64);
        for n in 1..=ramp_ticks + 30_000 {
            let t = n as f64 * 1e-3;
            let elastic = (rate * t.min(ramp_s) * unit).round() as i64;
            let out = state.step(&k, [elastic, -elastic, elastic / 3, 0, elastic * 2, -elastic / 7]);
            let want = ramp_hold_exact(&terms, rate, ramp_s, t);
            peak = peak.max(want.abs());
            worst = worst.max((out[0] as f64 / unit - want).abs()).max((-(out[1] as f64) / unit - want).abs());
            assert_eq!(out[3], 0, "a zero input stays zero");
        }
        println!("fixed, rate {rate}/s: largest error {worst:.3e} of peak {peak:.4}");
        assert!(worst <= 2e-6 * peak, "rate {rate}: error {worst:e} against peak {peak}");
    }
    // out of the integer ranges: refused
    let mut bad = fixed_terms;
    bad.g_q16[0] = 10 << 16;
    assert_eq!(fx::QlvCoefficients::new(&bad, 1000), None);
    assert_eq!(fx::QlvCoefficients::new(&fixed_terms, 0), None);
}

/// Colgate's ratio `Re[(1 - e^{-iθ}) H(e^{iθ})] / (1 - cos θ)` at `θ = wT` of the
/// filter's transfer function per unit stiffness, `H(z) = 1 + sum b_i (1 - z^-1) /
/// (1 - a_i z^-1)` (the recursion `h_i <- a_i h_i + b_i (u_k - u_{k-1})`), in f64 complex
/// arithmetic from `g`, `tau` and the tick (not from the library's closed form).
fn colgate_ratio(terms: &PronyTerms, tick_s: f64, theta: f64) -> f64 {
    let mul = |(a, b): (f64, f64), (c, d): (f64, f64)| (a * c - b * d, a * d + b * c);
    let div = |x: (f64, f64), (c, d): (f64, f64)| {
        let n = c * c + d * d;
        let (re, im) = mul(x, (c, -d));
        (re / n, im / n)
    };
    let z_inv = (theta.cos(), -theta.sin()); // e^{-iθ}
    let one_minus = |k: f64| (1.0 - k * z_inv.0, -k * z_inv.1);
    let mut h = (1.0, 0.0);
    for t in terms.as_slice() {
        let x = tick_s / f64::from(t.tau_s);
        let (a, b) = ((-x).exp(), f64::from(t.g) * -(-x).exp_m1() / x);
        let term = div(one_minus(1.0), one_minus(a));
        h = (h.0 + b * term.0, h.1 + b * term.1);
    }
    mul(one_minus(1.0), h).0 / (1.0 - theta.cos())
}

/// `QlvCoefficients::effective_stiffness_ratio` (the closed form `1 + sum 2 b_i / (1 +
/// a_i)`, f32) against the largest of Colgate's ratio over a sweep of 100,000
/// frequencies in `(0, pi/T]` (f64), for time constants far below, at and far above the
/// tick and the energy test's sets: within 2e-6 relative (f32 round-off of `a_i`, `b_i`
/// and the sum, each below 1e-7 relative, a few of them). And the bounds the docs state:
/// at least the tick gain `1 + sum b_i`, at most `1 + sum g_i`; exactly 1 without terms.
#[test]
fn the_effective_stiffness_ratio_is_the_largest_colgate_ratio_over_frequency() {
    let t = |g: f32, tau_s: f32| PronyTerm { g, tau_s };
    let sets: [(&str, &[PronyTerm]); 9] = [
        ("none", &[]),
        ("tau << T", &[t(3.0, 1e-5)]),
        ("tau = T / 5", &[t(2.0, 2e-4)]),
        ("tau = T", &[t(3.0, 0.001)]),
        ("tau = 3 T", &[t(1.0, 0.003)]),
        ("tau >> T", &[t(3.0, 100.0)]),
        ("mixed", &[t(3.0, 1e-5), t(3.0, 0.001), t(3.0, 100.0)]),
        ("moderate (insertion_energy)", &[t(0.8, 0.05), t(0.5, 1.0), t(0.3, 20.0)]),
        ("extreme (insertion_energy)", &[t(3.0, 0.001), t(3.0, 0.01), t(3.0, 0.1)]),
    ];
    const N: usize = 100_000;
    let tick = f64::from(TICK_S);
    for (name, set) in sets {
        let terms = PronyTerms::new(set).expect("valid terms");
        let c = QlvCoefficients::new(&terms, TICK_S).expect("coefficients");
        let rho = f64::from(c.effective_stiffness_ratio());
        let (mut max, mut at) = (f64::NEG_INFINITY, 0.0);
        for j in 1..=N {
            let theta = std::f64::consts::PI * j as f64 / N as f64;
            let r = colgate_ratio(&terms, tick, theta);
            if r > max {
                (max, at) = (r, theta);
            }
        }
        println!(
            "{name}: rho {rho:.6}, swept max {max:.6} at wT = {at:.4}, tick gain {:.6}, 1 + sum g {:.6}",
            c.tick_gain(),
            terms.instantaneous_ratio()
        );
        assert!((rho - max).abs() <= 2e-6 * max, "{name}: rho {rho} against the swept maximum {max}");
        assert!(rho >= f64::from(c.tick_gain()) * (1.0 - 1e-6), "{name}: rho {rho} below the tick gain {}", c.tick_gain());
        assert!(rho <= f64::from(terms.instantaneous_ratio()) * (1.0 + 1e-6), "{name}: rho {rho} above 1 + sum g");
        if set.is_empty() {
            assert_eq!(c.effective_stiffness_ratio(), 1.0, "no terms: exactly 1");
        }
    }
}
