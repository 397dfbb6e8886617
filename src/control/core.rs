//! [`LoopCore`]: the control law of one tick, free of any hardware: pose in, force
//! command and channel commands out. [`ControlLoop`](super::ControlLoop) wraps it with
//! embedded-hal outputs; the C API drives it directly.
use super::config::check_limit;
use super::passivity::Guard;
use super::{ConfigError, LoopConfig, LoopFlags, OverLimit, Passivity, PoseFault, Sample};
use crate::float::insertion::{GuardTerms, Insertion, InsertionEvaluation};
use crate::{Pose, Status, Wrench};

/// One channel's command: a duty fraction and a direction.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ChannelCommand {
    /// `|c|` clipped to `0..=1` (fraction of full scale).
    pub fraction: f32,
    /// The direction pin level: `(c >= 0) != direction_inverted`.
    pub direction_high: bool,
}

impl ChannelCommand {
    /// The duty cycle for a PWM whose full scale is `max_duty`:
    /// `(fraction * max_duty as f32 + 0.5) as u16` (round half up; never above
    /// `max_duty` since `fraction <= 1`).
    #[inline]
    #[must_use]
    pub fn duty(self, max_duty: u16) -> u16 {
        // `as` saturates: no panic path for any f32.
        (self.fraction * f32::from(max_duty) + 0.5) as u16
    }
}

/// The control law and its state: the configuration, the tick count, the last pose and
/// the force commanded last tick (the ramp starts from it).
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct LoopCore<const N: usize> {
    config: LoopConfig<N>,
    last: Sample,
    commands: [ChannelCommand; N],
    passivity: Option<Passivity>,
    guard: Guard,
    insertion: Option<Insertion>,
    insertion_last: Option<InsertionEvaluation>,
}

impl<const N: usize> LoopCore<N> {
    /// A loop at rest: tick 0, zero command, flags `DISABLED`.
    ///
    /// # Errors
    /// The configuration is invalid ([`LoopConfig::validate`]).
    pub fn new(config: LoopConfig<N>) -> Result<Self, ConfigError> {
        config.validate()?;
        let rest = ChannelCommand { fraction: 0.0, direction_high: false };
        let commands = config.channels.map(|ch| ChannelCommand { direction_high: !ch.direction_inverted, ..rest });
        Ok(Self {
            config,
            last: Sample { flags: LoopFlags::DISABLED, ..Sample::default() },
            commands,
            passivity: None,
            guard: Guard::default(),
            insertion: None,
            insertion_last: None,
        })
    }

    /// The configuration.
    #[inline]
    #[must_use]
    pub const fn config(&self) -> &LoopConfig<N> {
        &self.config
    }

    /// The last tick's sample (tick 0 and `DISABLED` before the first tick).
    #[inline]
    #[must_use]
    pub const fn last(&self) -> &Sample {
        &self.last
    }

    /// Sets the device force limit (takes effect at the next tick).
    ///
    /// # Errors
    /// [`ConfigError::ForceLimit`] unless `0 < limit_n <= force_limit_max_n`; the limit is
    /// then unchanged.
    pub fn set_force_limit_n(&mut self, limit_n: f32) -> Result<(), ConfigError> {
        check_limit(limit_n, self.config.force_limit_max_n)?;
        self.config.force_limit_n = limit_n;
        Ok(())
    }

    /// Turns the passivity guard on with `Some` (the device's damping and the loop period)
    /// or off with `None` (takes effect at the next tick; the guard starts without
    /// history). With the guard on, each tick evaluates
    /// [`wrench_and_depth_rate`](crate::wrench_and_depth_rate) instead of
    /// [`wrench`](crate::wrench) (the same wrench, and the depth rates of
    /// [`wrench_and_stiffness`](crate::wrench_and_stiffness)) and applies the rule of
    /// [`Passivity`](super::Passivity)'s module.
    ///
    /// # Errors
    /// [`ConfigError::Passivity`] for a damping or period that is not finite and > 0; the
    /// guard is then unchanged.
    pub fn set_passivity(&mut self, passivity: Option<Passivity>) -> Result<(), ConfigError> {
        if let Some(p) = &passivity {
            p.validate()?;
        }
        self.passivity = passivity;
        self.guard.reset();
        Ok(())
    }

    /// The passivity guard's configuration (`None`: off).
    #[inline]
    #[must_use]
    pub const fn passivity(&self) -> Option<&Passivity> {
        self.passivity.as_ref()
    }

    /// Renders a whole insertion with `Some` (a needle path through a tissue stack:
    /// [`Insertion`], in its current state) instead of the block surrogate
    /// [`wrench`](crate::wrench), or the block surrogate again with `None` (takes effect
    /// at the next tick).
    ///
    /// With an insertion, each tick with a valid pose steps it once
    /// ([`Insertion::step`], or [`Insertion::step_with_stiffness`] with the passivity
    /// guard on: the guard then limits the elastic part of the force, of the deflected
    /// boundary's stiffness `|dF/dδ|` (times the viscoelastic filter's `rho`, whose part
    /// of the force the guard then renders with its own filter of the guarded
    /// deflection), and passes friction and cutting as they are:
    /// [`Passivity`]'s module). A stale or missing pose
    /// does not step it (its velocity filter then sees the whole motion since the last
    /// valid pose in one tick, smoothed by its time constant). A tick that punctures a
    /// boundary clears the guard's offset: the force drops to what the track renders and
    /// no offset stored while deflecting the boundary is given back to the hand.
    /// The insertion's configuration period should equal the loop's.
    pub fn set_insertion(&mut self, insertion: Option<Insertion>) {
        self.insertion = insertion;
        self.insertion_last = None;
        self.guard.reset();
    }

    /// The insertion the loop renders, in its state after the last tick (`None`: the
    /// block surrogate).
    #[inline]
    #[must_use]
    pub const fn insertion(&self) -> Option<&Insertion> {
        self.insertion.as_ref()
    }

    /// The insertion's result of the last tick that stepped it: the phase, the punctures
    /// and the filtered velocity beside the wrench (`None` before the first, or
    /// without an insertion).
    #[inline]
    #[must_use]
    pub const fn insertion_evaluation(&self) -> Option<&InsertionEvaluation> {
        self.insertion_last.as_ref()
    }

    /// Sets what happens above the force limit (takes effect at the next tick).
    #[inline]
    pub fn set_over_limit(&mut self, over_limit: OverLimit) {
        self.config.over_limit = over_limit;
    }

    /// One tick of the control law on `reading` (the pose source's answer):
    ///
    /// 1. the tick count goes up by one (wrapping);
    /// 2. a stale or missing pose is a fault (`POSE_STALE` / `POSE_MISSING`), the model is
    ///    not evaluated; otherwise `wrench(pose)` (or the insertion's tick:
    ///    [`set_insertion`](Self::set_insertion)), and an `ERROR` status is a fault
    ///    (`EVAL_ERROR`); a pose the insertion rejects as a glitch is a fault
    ///    (`POSE_GLITCH`) that keeps the passivity guard's state (the insertion integrated
    ///    nothing: the next accepted tick goes on from the last);
    /// 3. with the passivity guard on ([`set_passivity`](Self::set_passivity)), `F` is the
    ///    guarded force (`STIFFNESS_LIMITED` when the model's stiffness was above the
    ///    guard's), else the model's `(fx, fy, fz)`; then with `F`: if `fx² + fy² + fz² > limit²` (`OVER_LIMIT`),
    ///    [`OverLimit::Saturate`] commands `F * (limit / |F|)` (`FORCE_SATURATED`) and
    ///    [`OverLimit::RampToZero`] makes it a fault; else the command is `F`;
    /// 4. on a fault each component of the previous command moves towards zero by at
    ///    most `ramp_step_n` (`RAMPING`), and when all three are zero the outputs are
    ///    disabled (`DISABLED`).
    ///
    /// A tick without a fault follows the model again at once. Never panics, constant
    /// work except one square root when the force is above the limit.
    pub fn step(&mut self, reading: Result<Pose, PoseFault>) -> Sample {
        let tick = self.last.tick.wrapping_add(1);
        let mut s = Sample { tick, pose: self.last.pose, ..Sample::default() };
        let fault = match reading {
            Err(PoseFault::Stale) => Some(LoopFlags::POSE_STALE),
            Err(PoseFault::Missing) => Some(LoopFlags::POSE_MISSING),
            Ok(pose) => {
                s.pose = pose;
                let (wrench, status, stiffness) = self.evaluate(&pose);
                s.model = status;
                let glitch = self.insertion.is_some() && self.insertion_last.is_some_and(|e| e.flags.is_glitch());
                if glitch {
                    Some(LoopFlags::POSE_GLITCH)
                } else if status.is_error() {
                    Some(LoopFlags::EVAL_ERROR)
                } else {
                    s.wrench = wrench;
                    let f = [wrench.fx_n, wrench.fy_n, wrench.fz_n];
                    let f = match stiffness {
                        Some((p, terms)) => {
                            let filter = self.insertion.as_ref().and_then(Insertion::guard_filter);
                            #[cfg(feature = "shaft-presliding")]
                            let (guarded, limited) = self.guard.apply_held(&p, f, &terms, filter);
                            #[cfg(not(feature = "shaft-presliding"))]
                            let (guarded, limited) = self.guard.apply(&p, f, &terms, filter);
                            if limited {
                                s.flags |= LoopFlags::STIFFNESS_LIMITED;
                            }
                            guarded
                        }
                        None => f,
                    };
                    self.limit(f, &mut s)
                }
            }
        };
        if let Some(f) = fault {
            if f != LoopFlags::POSE_GLITCH {
                self.guard.reset();
            }
            s.flags |= f | LoopFlags::RAMPING;
            s.force_cmd_n = ramp(self.last.force_cmd_n, self.config.ramp_step_n);
            if s.force_cmd_n == [0.0; 3] {
                s.flags |= LoopFlags::DISABLED;
            }
        }
        let (commands, clipped) = channel_commands(&self.config, s.force_cmd_n);
        if clipped {
            s.flags |= LoopFlags::DUTY_CLIPPED;
        }
        self.commands = commands;
        self.last = s;
        s
    }

    /// The channel commands of the last tick (all zero fraction, direction of `+0.0`,
    /// before the first tick).
    #[inline]
    #[must_use]
    pub const fn commands(&self) -> &[ChannelCommand; N] {
        &self.commands
    }

    /// Whether the enable pin should be high after the last tick (`DISABLED` not set).
    #[inline]
    #[must_use]
    pub const fn enabled(&self) -> bool {
        !self.last.flags.contains(LoopFlags::DISABLED)
    }

    /// Adds `flags` to the last tick's sample (the hardware layer reports
    /// `OUTPUT_ERROR` this way).
    #[inline]
    pub fn add_flags(&mut self, flags: LoopFlags) {
        self.last.flags |= flags;
    }

    /// The model at `pose` (the insertion's tick when one is set): the wrench, its status
    /// and, with the passivity guard on, the guard's configuration with the stiffness
    /// along the insertion `|dF/d depth|` (N/mm) and the force the guard leaves alone
    /// (the insertion's friction and cutting; zero for the block surrogate).
    fn evaluate(&mut self, pose: &Pose) -> (Wrench, Status, Option<(Passivity, GuardTerms)>) {
        if let Some(ins) = self.insertion.as_mut() {
            let (e, guarded) = match self.passivity {
                Some(p) => {
                    let (e, terms) = ins.step_with_stiffness(pose);
                    (e, Some((p, terms)))
                }
                None => (ins.step(pose), None),
            };
            self.insertion_last = Some(e);
            if e.punctures > 0 {
                // nothing the guard stored while the boundary deflected is given back
                self.guard.punctured();
            }
            return (e.wrench, e.status, guarded);
        }
        match self.passivity {
            Some(p) => {
                // the rates by depth of `wrench_and_stiffness`, bit for bit, without the
                // rates by x and z the guard does not use
                let (e, [dfx, dfy, dfz]) = crate::wrench_and_depth_rate(pose);
                let k2 = dfx * dfx + dfy * dfy + dfz * dfz;
                (e.wrench, e.status, Some((p, GuardTerms { stiffness_n_per_mm: needle_fpu::sqrtf(k2), ..GuardTerms::NONE })))
            }
            None => {
                let e = crate::wrench(pose);
                (e.wrench, e.status, None)
            }
        }
    }

    /// Step 3 of [`step`](Self::step): the command for a valid force `f` (N), or the fault.
    fn limit(&self, f: [f32; 3], s: &mut Sample) -> Option<LoopFlags> {
        let [fx, fy, fz] = f;
        let limit = self.config.force_limit_n;
        let norm2 = fx * fx + fy * fy + fz * fz;
        if norm2 <= limit * limit {
            s.force_cmd_n = f;
            return None;
        }
        s.flags |= LoopFlags::OVER_LIMIT;
        match self.config.over_limit {
            OverLimit::RampToZero => Some(LoopFlags::OVER_LIMIT),
            OverLimit::Saturate => {
                let scale = limit / needle_fpu::sqrtf(norm2);
                s.force_cmd_n = f.map(|c| c * scale);
                s.flags |= LoopFlags::FORCE_SATURATED;
                None
            }
        }
    }
}

/// Each component of `cmd_n` moved towards zero by at most `step_n` (never past it).
fn ramp(cmd_n: [f32; 3], step_n: f32) -> [f32; 3] {
    cmd_n.map(|c| {
        if c > step_n {
            c - step_n
        } else if c < -step_n {
            c + step_n
        } else {
            0.0
        }
    })
}

/// The channel commands of the force `f_n` through the linear map, and whether one was
/// clipped to full scale.
fn channel_commands<const N: usize>(config: &LoopConfig<N>, f_n: [f32; 3]) -> ([ChannelCommand; N], bool) {
    let [fx, fy, fz] = f_n;
    let mut clipped = false;
    let commands = config.channels.map(|ch| {
        let [gx, gy, gz] = ch.gains_per_n;
        let c = (gx * fx + gy * fy) + gz * fz;
        let a = if c < 0.0 { -c } else { c };
        let fraction = if a > 1.0 {
            clipped = true;
            1.0
        } else {
            a
        };
        ChannelCommand { fraction, direction_high: (c >= 0.0) != ch.direction_inverted }
    });
    (commands, clipped)
}
