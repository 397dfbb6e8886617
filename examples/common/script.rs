//! The scripted needle insertion the loop examples replay, one pose per 1 ms tick.
use core::ops::Range;
use needle_haptics::control::{PoseFault, PoseSource};
use needle_haptics::Pose;

/// At a fixed entry point (x, z): touch for `touch_ms`; insert from 0 to `depth_mm` in
/// `move_ms` while tilting theta_x from 0 to `theta_x_deg`; hold for `hold_ms`; withdraw
/// to 0 mm and 0 degrees in `move_ms`. The encoders are stale during `stale_ms`
/// (ticks, 1-based). Each [`PoseSource::read_pose`] is the next tick.
pub struct Insertion {
    /// Ticks read so far (the last pose's tick, ms).
    pub t: u32,
    pub x_mm: f32,
    pub z_mm: f32,
    pub touch_ms: u32,
    pub move_ms: u32,
    pub hold_ms: u32,
    pub depth_mm: f32,
    pub theta_x_deg: f32,
    pub stale_ms: Range<u32>,
}

impl Insertion {
    /// Ticks of the whole script (ms).
    pub const fn ticks(&self) -> u32 {
        self.touch_ms + 2 * self.move_ms + self.hold_ms
    }

    /// Fraction of the insertion at tick `t`: 0 while touching, rising to 1, 1 while
    /// holding, falling to 0 at the end.
    fn fraction(&self, t: u32) -> f32 {
        let inserted = self.touch_ms + self.move_ms;
        let held = inserted + self.hold_ms;
        let span = self.move_ms.max(1) as f32;
        if t < self.touch_ms {
            0.0
        } else if t < inserted {
            (t - self.touch_ms) as f32 / span
        } else if t < held {
            1.0
        } else {
            self.ticks().saturating_sub(t) as f32 / span
        }
    }
}

impl PoseSource for Insertion {
    fn read_pose(&mut self) -> Result<Pose, PoseFault> {
        self.t += 1;
        if self.stale_ms.contains(&self.t) {
            return Err(PoseFault::Stale);
        }
        let s = self.fraction(self.t);
        Ok(Pose::new(self.x_mm, self.z_mm, self.theta_x_deg * s, 0.0, self.depth_mm * s))
    }
}
