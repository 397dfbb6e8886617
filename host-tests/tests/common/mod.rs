//! Shared by the control-loop tests: the golden vectors of the compiled-in set and a
//! scripted pose source.
#![allow(dead_code)]
use needle_haptics::control::{PoseFault, PoseSource};
use needle_haptics::{model_info, Pose, Status, Wrench};
use std::collections::VecDeque;
use std::path::Path;

/// One golden row: pose, status and wrench as the fitter's independent implementation
/// computed them.
#[derive(Clone, Copy, Debug)]
pub struct GoldenRow {
    pub line: usize,
    pub pose: Pose,
    pub status: Status,
    pub wrench: Wrench,
}

/// Every row of `<set>/golden-f32.csv` (fails, never skips, when the file is missing),
/// read by the fitter's golden-file reader.
pub fn golden_rows() -> Vec<GoldenRow> {
    let path = Path::new(model_info::SET_DIR).join("golden-f32.csv");
    let text = std::fs::read_to_string(&path)
        .unwrap_or_else(|e| panic!("{}: {e}: run `needle fit --set {}`", path.display(), model_info::SET_DIR));
    let rows = needle_fit::golden::float32::parse_csv(&text, &path).unwrap_or_else(|e| panic!("{e:#}"));
    rows.into_iter()
        .enumerate()
        .map(|(i, r)| {
            let [x, z, tx, tz, d] = r.pose;
            GoldenRow {
                line: i + 2,
                pose: Pose::new(x, z, tx, tz, d),
                status: Status::from_bits(r.status),
                wrench: Wrench::from_array(r.wrench),
            }
        })
        .collect()
}

/// `count` golden rows inside the domain (status OK) with a non-zero force, spread over
/// the file.
pub fn golden_in_domain(count: usize) -> Vec<GoldenRow> {
    let ok: Vec<GoldenRow> = golden_rows().into_iter().filter(|r| r.status.is_ok() && r.wrench.fy_n.abs() > 1e-3).collect();
    assert!(ok.len() >= count, "only {} in-domain golden rows with |fy| > 1 mN", ok.len());
    let stride = ok.len() / count;
    ok.into_iter().step_by(stride).take(count).collect()
}

/// A pose source that replays a script, then reports `Missing`.
#[derive(Debug, Default)]
pub struct Script(pub VecDeque<Result<Pose, PoseFault>>);

impl Script {
    pub fn new(items: impl IntoIterator<Item = Result<Pose, PoseFault>>) -> Self {
        Self(items.into_iter().collect())
    }
}

impl PoseSource for Script {
    fn read_pose(&mut self) -> Result<Pose, PoseFault> {
        self.0.pop_front().unwrap_or(Err(PoseFault::Missing))
    }
}

/// The documented linear map of one channel, in the documented f32 order: the signed
/// channel command `c`.
pub fn channel_c(gains: [f32; 3], f: [f32; 3]) -> f32 {
    (gains[0] * f[0] + gains[1] * f[1]) + gains[2] * f[2]
}

/// The documented duty of a signed command `c` on a PWM of full scale `max`.
pub fn duty_of(c: f32, max: u16) -> u16 {
    let a = c.abs().min(1.0);
    (a * f32::from(max) + 0.5) as u16
}
