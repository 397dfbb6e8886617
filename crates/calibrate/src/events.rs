//! Puncture events of a measured curve: a peak of the force followed by a drop.
use crate::measured::Point;

/// How a puncture is told from noise.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EventRule {
    /// Smallest drop, as a fraction of the peak force.
    pub drop_fraction: f64,
    /// The drop must happen within this much needle travel after the peak, mm.
    pub drop_within_mm: f64,
    /// After the drop the force must stay below the peak over this much travel, mm (a
    /// digitising glitch comes back above it).
    pub stay_below_mm: f64,
    /// Smallest peak, as a fraction of the curve's largest force (the noise of the
    /// approach, before contact, has peaks and drops too).
    pub min_peak_fraction: f64,
}

impl Default for EventRule {
    fn default() -> Self {
        Self { drop_fraction: 0.25, drop_within_mm: 0.5, stay_below_mm: 1.0, min_peak_fraction: 0.2 }
    }
}

/// One puncture: the peak before the drop and the lowest point of the drop.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Puncture {
    /// Index of the peak point.
    pub peak: usize,
    /// Index of the lowest point of the drop (the next interval starts there).
    pub bottom: usize,
}

/// The punctures of `points` (in file order), first to last.
#[must_use]
pub fn punctures(points: &[Point], rule: EventRule) -> Vec<Puncture> {
    let mut found = Vec::new();
    let largest = points.iter().map(|p| p.force_n).fold(0.0, f64::max);
    let mut i = 0;
    while i < points.len() {
        let Some(peak) = points.get(i) else { break };
        // only a peak above the noise of the approach can be a puncture (checked first:
        // the window below is long on a dense curve)
        if peak.force_n.partial_cmp(&(rule.min_peak_fraction * largest)) != Some(std::cmp::Ordering::Greater) {
            i += 1;
            continue;
        }
        // the drop: the lowest point within the window, if the force never rose above the peak before it
        let mut bottom: Option<(usize, &Point)> = None;
        for (j, p) in points.iter().enumerate().skip(i + 1) {
            if p.position_mm - peak.position_mm > rule.drop_within_mm || p.force_n > peak.force_n {
                break;
            }
            if bottom.is_none_or(|(_, low)| p.force_n.total_cmp(&low.force_n).is_lt()) {
                bottom = Some((j, p));
            }
        }
        if let Some((b, low)) = bottom {
            let dropped = low.force_n <= peak.force_n * (1.0 - rule.drop_fraction);
            let stays = points
                .iter()
                .skip(b)
                .take_while(|p| p.position_mm - low.position_mm <= rule.stay_below_mm)
                .all(|p| p.force_n < peak.force_n);
            if dropped && stays {
                found.push(Puncture { peak: i, bottom: b });
                i = b + 1;
                continue;
            }
        }
        i += 1;
    }
    found
}
