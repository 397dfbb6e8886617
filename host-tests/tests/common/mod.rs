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

fn bits(field: &str, line: usize) -> u32 {
    needle_codegen::parse_bits(field).unwrap_or_else(|| panic!("golden-f32.csv:{line}: bad field {field:?}"))
}

/// Every row of `<set>/golden-f32.csv` (fails, never skips, when the file is missing).
pub fn golden_rows() -> Vec<GoldenRow> {
    let path = Path::new(model_info::SET_DIR).join("golden-f32.csv");
    let text = std::fs::read_to_string(&path)
        .unwrap_or_else(|e| panic!("{}: {e}: run `needle fit --set {}`", path.display(), model_info::SET_DIR));
    text.lines()
        .enumerate()
        .skip(1)
        .map(|(i, l)| {
            let line = i + 1;
            let f: Vec<&str> = l.split(',').collect();
            assert_eq!(f.len(), 12, "golden-f32.csv:{line}");
            let v: Vec<f32> = f.iter().enumerate().filter(|(k, _)| *k != 5).map(|(_, s)| f32::from_bits(bits(s, line))).collect();
            let status = u8::from_str_radix(f[5].trim_start_matches("0x"), 16).expect("status");
            GoldenRow {
                line,
                pose: Pose::new(v[0], v[1], v[2], v[3], v[4]),
                status: Status::from_bits(status),
                wrench: Wrench::from_array([v[5], v[6], v[7], v[8], v[9], v[10]]),
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
