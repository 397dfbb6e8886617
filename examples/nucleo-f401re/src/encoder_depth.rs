//! The insertion depth from a quadrature encoder on a 32-bit timer: the needle slides
//! along a fixed axis through a fixed entry point (a one-axis insertion rig), so the
//! pose is the entry point's x, z and tilts plus the encoder's depth.
use needle_haptics::control::{PoseFault, PoseSource};
use needle_haptics::Pose;
use stm32f4xx_hal::hal_02::Qei as _;
use stm32f4xx_hal::pac::TIM2;
use stm32f4xx_hal::qei::Qei;

/// The pose source of the rig.
pub struct EncoderDepth {
    qei: Qei<TIM2>,
    /// The pose at depth 0 (the needle tip on the tissue surface).
    entry: Pose,
    /// Encoder counts per mm of insertion (four per line in quadrature mode).
    counts_per_mm: f32,
    /// The count at depth 0.
    zero: u32,
    /// Largest plausible change of count between two ticks; a bigger jump is a glitch
    /// or a lost encoder signal, reported as [`PoseFault::Stale`].
    max_step_counts: u32,
    last: u32,
}

impl EncoderDepth {
    /// The rig with the needle at depth 0 now: the encoder's count now is the surface.
    /// `counts_per_mm` must be finite and > 0, `max_step_counts` > 0.
    pub fn homed_here(qei: Qei<TIM2>, entry: Pose, counts_per_mm: f32, max_step_counts: u32) -> Self {
        let zero = qei.count();
        Self { qei, entry, counts_per_mm, zero, max_step_counts, last: zero }
    }
}

impl PoseSource for EncoderDepth {
    fn read_pose(&mut self) -> Result<Pose, PoseFault> {
        let count = self.qei.count();
        let step = count.wrapping_sub(self.last) as i32;
        if step.unsigned_abs() > self.max_step_counts {
            return Err(PoseFault::Stale);
        }
        self.last = count;
        // Counts from the surface, positive into the tissue (wrapping 32-bit counter).
        let counts = count.wrapping_sub(self.zero) as i32;
        let depth_mm = counts as f32 / self.counts_per_mm;
        Ok(Pose { depth_mm, ..self.entry })
    }
}
