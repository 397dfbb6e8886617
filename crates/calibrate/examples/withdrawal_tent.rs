//! A study, not the product: how much of the rig's withdrawal a tissue "tent" in series
//! with the shaft would explain (issue 65's withdrawal misses; `docs/insertion.md`,
//! "Repeats"). The library's friction per mm of shaft pulls hardest just after its
//! turn-over and falls with the shaft's length; the rig's pull turns over over
//! millimetres and grows while the needle leaves.
//!
//! The law tried here, applied to the library's force at the hold's end `F0` (N, along
//! the axis, positive resisting a deeper needle) along the measured withdrawal: the
//! tissue around the shaft is a spring of stiffness `k` (N/mm) to the ground in series
//! with the shaft's friction, which slips at `c` N per mm of shaft in the tissue; the
//! tissue lifted by `u = |F| / k` adds `u` to that length, so the slipping pull is
//! `c L / (1 - c / k)`, `L` the depth of the tip below the contact plus a release height
//! `h` (mm: the tip lets go `h` above the contact's stage position). The force:
//! `max(F0 - k travel, -c L / (1 - c / k))` while `L > 0`, else 0.
//!
//! For every group of the rig (one sample at one speed) and every pair of its trials:
//! the stack calibrated on the pair (`needle calibrate --trials`), replayed along every
//! trial of the group (as `needle replay`); `k`, `c`, `h` by least squares over the
//! pair's withdrawals (a grid); each other trial's withdrawal RMS (% of the group's
//! mean peak force) with the library's force and with the law. Usage:
//! `cargo run --release -p needle-calibrate --example withdrawal_tent [DIR] [SET]`.
use needle_calibrate::events::EventRule;
use needle_calibrate::runtime_stack::OwnedStack;
use needle_calibrate::whole::{calibrate_trials, trials, TrialsOptions};
use needle_haptics::{insertion, Pose};
use std::path::{Path, PathBuf};

/// The rig does not state its needle's gauge: the shipped liver's 1.27 mm, as the tests.
const NEEDLE_MM: f64 = 1.27;

/// Per layer: a tent for the top layer's tissue and one for the layers below it around its part of the shaft (`k`, `c` per
/// layer, the top layer's `h`), each letting go when the tip leaves its layer; the force
/// at the hold's end on the deepest layer the tip is in.
#[derive(Clone, Copy)]
struct Tents {
    k: [f64; 2],
    c: [f64; 2],
    h: f64,
}

impl Tents {
    fn force(self, top_mm: f64, start_deep: bool, start_n: f64, travel_mm: f64, depth_mm: f64) -> f64 {
        let lengths = [depth_mm.min(top_mm) + self.h, depth_mm - top_mm];
        let mut f = 0.0;
        for (j, ((k, c), l)) in self.k.into_iter().zip(self.c).zip(lengths).enumerate() {
            let start = if (j == 1) == start_deep { start_n } else { 0.0 };
            f += Tent { k, c, h: 0.0 }.force(start, travel_mm, l);
        }
        f
    }
}

/// One trial's withdrawal: stage travel back from the hold's end (mm), the tip's depth
/// below the contact (mm), the measured and the library's force (N); and the library's
/// force at the hold's end (N).
struct Withdrawal {
    rows: Vec<[f64; 4]>,
    start_n: f64,
}

/// The law's parameters: `k` N/mm, `c` N/mm, `h` mm.
#[derive(Clone, Copy)]
struct Tent {
    k: f64,
    c: f64,
    h: f64,
}

impl Tent {
    fn force(self, start_n: f64, travel_mm: f64, depth_mm: f64) -> f64 {
        let l = depth_mm + self.h;
        if l <= 0.0 {
            return 0.0;
        }
        let slipping = if self.c < self.k { self.c * l / (1.0 - self.c / self.k) } else { f64::INFINITY };
        (start_n - self.k * travel_mm).max(-slipping)
    }
}

fn rms(pairs: impl Iterator<Item = (f64, f64)>) -> f64 {
    let (mut s, mut n) = (0.0, 0.0);
    for (a, b) in pairs {
        s += (a - b) * (a - b);
        n += 1.0;
    }
    if n > 0.0 {
        (s / n).sqrt()
    } else {
        f64::NAN
    }
}

fn withdrawal(stack: &OwnedStack, t: &trials::Trial) -> anyhow::Result<(Withdrawal, f64)> {
    let r = needle_calibrate::trial_replay::replay(&stack.as_stack(), t.onset_mm(), &t.samples).map_err(anyhow::Error::msg)?;
    let w = t.phases.withdrawal.clone();
    let first = w.start;
    let start = t.samples.get(first).ok_or_else(|| anyhow::anyhow!("{}: no withdrawal", t.name()))?;
    let rows = w
        .filter_map(|i| Some((t.samples.get(i)?, r.rows.get(i)?)))
        .map(|(s, m)| [start.position_mm - s.position_mm, s.position_mm - t.onset_mm(), s.force_n, m.force_n])
        .collect();
    let start_n = r.rows.get(first).map_or(0.0, |m| m.force_n);
    let peak = t.samples.iter().map(|s| s.force_n).fold(f64::NEG_INFINITY, f64::max);
    Ok((Withdrawal { rows, start_n }, peak))
}

fn law_rms(w: &Withdrawal, tent: Tent) -> f64 {
    rms(w.rows.iter().map(|r| (r[2], tent.force(w.start_n, r[0], r[1]))))
}

fn layers_rms(w: &Withdrawal, top_mm: f64, t: Tents) -> f64 {
    let deep = w.rows.first().is_some_and(|r| r[1] > top_mm);
    rms(w.rows.iter().map(|r| (r[2], t.force(top_mm, deep, w.start_n, r[0], r[1]))))
}

/// Coordinate descent over each parameter's grid, from one tent for both layers.
fn fit_layers(ws: &[&Withdrawal], top_mm: f64, one: Tent) -> Tents {
    let cost = |t: Tents| ws.iter().map(|w| layers_rms(w, top_mm, t).powi(2)).sum::<f64>();
    let mut t = Tents { k: [one.k; 2], c: [one.c; 2], h: one.h };
    let ks: Vec<f64> = (0..25).map(|i| 0.03 * 1.25f64.powi(i)).collect();
    let cs: Vec<f64> = (0..25).map(|j| 0.01 * 1.2f64.powi(j)).collect();
    for _ in 0..4 {
        for p in 0..5 {
            let grid: &[f64] = match p {
                0 | 1 => &ks,
                2 | 3 => &cs,
                _ => &[0.0, 0.5, 1.0, 1.5, 2.0, 3.0],
            };
            let mut best = (cost(t), t);
            for &v in grid {
                let mut n = t;
                match p {
                    0 | 1 => n.k[p] = v,
                    2 | 3 => n.c[p - 2] = v,
                    _ => n.h = v,
                }
                let e = cost(n);
                if e < best.0 {
                    best = (e, n);
                }
            }
            t = best.1;
        }
    }
    t
}

fn fit(ws: &[&Withdrawal]) -> Tent {
    let mut best = (f64::INFINITY, Tent { k: 1.0, c: 0.0, h: 0.0 });
    for i in 0..25 {
        for j in 0..25 {
            for h in [0.0, 0.5, 1.0, 1.5, 2.0, 3.0] {
                let tent = Tent { k: 0.03 * 1.25f64.powi(i), c: 0.01 * 1.2f64.powi(j), h };
                let e: f64 = ws.iter().map(|w| law_rms(w, tent).powi(2)).sum();
                if e < best.0 {
                    best = (e, tent);
                }
            }
        }
    }
    best.1
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v.get(v.len() / 2).copied().unwrap_or(f64::NAN)
}

fn group(files: &[PathBuf], set: &Path) -> anyhow::Result<Vec<[f64; 6]>> {
    let mu0 = needle_codegen::tissue::read_fe_shear_modulus(set)?.unwrap_or(f64::NAN);
    let lambda = (NEEDLE_MM / f64::from(insertion::FE_NEEDLE_DIAMETER_MM)) as f32;
    let u = move |d: f64| f64::from(insertion::deflection(&Pose::default(), d as f32, 1.0, lambda).wrench.fy_n);
    let prepared: Vec<trials::Trial> =
        files.iter().map(|f| trials::prepare(f, EventRule::default(), &u, f64::from(lambda), false)).collect::<anyhow::Result<_>>()?;
    let mut out = Vec::new();
    for a in 0..files.len() {
        for b in a + 1..files.len() {
            let pair = [files[a].clone(), files[b].clone()];
            let opts = TrialsOptions {
                trials: &pair,
                name: "rig".into(),
                needle_diameter_mm: &[NEEDLE_MM],
                rule: EventRule::default(),
                fe_shear_modulus_n_per_mm2: mu0,
            };
            let c = calibrate_trials(&opts)?;
            let layers = c.fitted.stack.layers.iter().map(needle_calibrate::to_layer).collect();
            let stack = OwnedStack { name: "rig".into(), needle_diameter_mm: NEEDLE_MM as f32, layers };
            let all: Vec<(Withdrawal, f64)> = prepared.iter().map(|t| withdrawal(&stack, t)).collect::<anyhow::Result<_>>()?;
            let peak = all.iter().map(|x| x.1).sum::<f64>() / all.len() as f64;
            let tent = fit(&[&all[a].0, &all[b].0]);
            let top = stack.layers.first().filter(|_| stack.layers.len() >= 2).map(|l| f64::from(l.thickness_mm));
            let tents = top.map(|top| (top, fit_layers(&[&all[a].0, &all[b].0], top, tent)));
            for (_, (w, _)) in all.iter().enumerate().filter(|(i, _)| *i != a && *i != b) {
                let today = rms(w.rows.iter().map(|r| (r[2], r[3])));
                let per_layer = tents.map_or(f64::NAN, |(top, t)| layers_rms(w, top, t));
                out.push([100.0 * today / peak, 100.0 * law_rms(w, tent) / peak, tent.k, tent.c, tent.h, 100.0 * per_layer / peak]);
            }
        }
    }
    Ok(out)
}

fn main() -> anyhow::Result<()> {
    let args: Vec<String> = std::env::args().collect();
    let dir = PathBuf::from(args.get(1).cloned().unwrap_or_else(|| "../shared/data/stokes-needle-rig".into()));
    let set = PathBuf::from(args.get(2).cloned().unwrap_or_else(|| "coeffs/default".into()));
    let mut files: Vec<PathBuf> =
        std::fs::read_dir(&dir)?.filter_map(|e| e.ok().map(|e| e.path())).filter(|p| p.extension().is_some_and(|x| x == "csv")).collect();
    files.sort();
    let key = |p: &Path| p.file_name().and_then(|n| n.to_str()).and_then(|n| n.rsplit_once("_trial")).map(|(k, _)| k.to_string());
    let mut keys: Vec<String> = files.iter().filter_map(|p| key(p)).collect();
    keys.dedup();
    println!("withdrawal RMS, % of the group's mean peak force: the library's friction -> the tent law (k, c, h: medians of the pairs' fits); a tent for the top layer and one below (stacks of two layers or more)");
    for k in keys {
        let g: Vec<PathBuf> = files.iter().filter(|p| key(p).as_deref() == Some(k.as_str())).cloned().collect();
        if g.len() < 3 {
            continue;
        }
        let r = group(&g, &set)?;
        let col = |j: usize| r.iter().map(|x| x[j]).filter(|x| x.is_finite()).collect::<Vec<_>>();
        let worst = |j: usize| col(j).into_iter().fold(f64::NEG_INFINITY, f64::max);
        println!(
            "{k:<34} {:>3} predictions: median {:>5.2} worst {:>5.2} -> median {:>5.2} worst {:>5.2}   k {:.3} N/mm, c {:.3} N/mm, h {:.1} mm; per layer: median {:>5.2} worst {:>5.2}",
            r.len(),
            median(col(0)),
            worst(0),
            median(col(1)),
            worst(1),
            median(col(2)),
            median(col(3)),
            median(col(4)),
            median(col(5)),
            worst(5),
        );
    }
    Ok(())
}
