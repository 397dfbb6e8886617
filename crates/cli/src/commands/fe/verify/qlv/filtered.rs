//! The library's QLV filter (`needle_haptics::viscoelastic`, f32, one tick of
//! `InsertionConfig::DEFAULT_1KHZ`) stepped along a ramp-and-hold run's depth-time path on
//! the elastic FE wrench: what `needle fe verify --qlv` scores and its figure draws.

use needle_contract::COMPONENT_COUNT;
use needle_fe::visco::qlv::QlvCase;
use needle_haptics::insertion::InsertionConfig;
use needle_haptics::viscoelastic::{PronyTerm, PronyTerms, WrenchQlv};

/// The filter's tick, s: the library's default pose stream (1 kHz).
pub fn tick_s() -> f64 {
    f64::from(InsertionConfig::DEFAULT_1KHZ.period_s)
}

/// The filter's wrench at each must point of `case` ([`filtered_at`]).
///
/// # Errors
/// The Prony series is refused by the library.
pub fn filtered(case: &QlvCase) -> anyhow::Result<Vec<[f64; COMPONENT_COUNT]>> {
    filtered_at(case, &case.times_s())
}

/// The filter's wrench at `times` (s, increasing): the filter stepped once per tick from
/// rest on the elastic wrench at the tick's end, its output linearly interpolated between
/// the two ticks around a time that falls between ticks.
///
/// # Errors
/// The Prony series is refused by the library.
pub fn filtered_at(case: &QlvCase, times: &[f64]) -> anyhow::Result<Vec<[f64; COMPONENT_COUNT]>> {
    let terms: Vec<PronyTerm> =
        case.prony.g.iter().zip(&case.prony.tau_s).map(|(&g, &t)| PronyTerm { g: g as f32, tau_s: t as f32 }).collect();
    let terms = PronyTerms::new(&terms).map_err(|e| anyhow::anyhow!("{}: {e}", case.run))?;
    let tick = InsertionConfig::DEFAULT_1KHZ.period_s;
    let mut filter = WrenchQlv::new(&terms, tick).map_err(|e| anyhow::anyhow!("{}: {e}", case.run))?;
    let dt = f64::from(tick);
    let mut out = Vec::with_capacity(times.len());
    let (mut n, mut prev) = (0u64, [0.0f64; COMPONENT_COUNT]);
    let mut next = prev;
    for &t in times {
        // step until the tick at or after t
        while (n as f64) * dt < t - 1e-9 * dt {
            n += 1;
            prev = next;
            let e = case.elastic_at_time(n as f64 * dt).map(|v| v as f32);
            next = filter.step(e).map(f64::from);
        }
        let t_next = n as f64 * dt;
        let f = if n == 0 { 1.0 } else { 1.0 - (t_next - t) / dt };
        out.push(std::array::from_fn(|c| prev[c] + f.clamp(0.0, 1.0) * (next[c] - prev[c])));
    }
    Ok(out)
}
