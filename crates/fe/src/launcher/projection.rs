//! A campaign's wall time on N cluster nodes, projected from measured runs: each pose
//! takes its measured wall time (from the manifest), the poses go longest first to the
//! slot that frees up first (LPT list scheduling, as a job array's tasks start on the
//! slots that free up), and the projection is the time the last slot finishes. It counts
//! neither queue waiting nor the slower cores a cluster may have.

use crate::campaign::Plan;
use crate::mesh::summary as mesh_summary;
use std::collections::BTreeMap;
use std::fmt::Write as _;

/// The time the last of `slots` parallel slots finishes `walls_s` (s), longest first to
/// the earliest free slot. 0 slots count as 1.
pub fn makespan_s(walls_s: &[f64], slots: usize) -> f64 {
    let mut w: Vec<f64> = walls_s.iter().copied().filter(|v| v.is_finite() && *v > 0.0).collect();
    w.sort_by(|a, b| b.total_cmp(a));
    let mut free = vec![0.0_f64; slots.max(1)];
    for t in w {
        if let Some(slot) = free.iter_mut().min_by(|a, b| a.total_cmp(b)) {
            *slot += t;
        }
    }
    free.into_iter().fold(0.0, f64::max)
}

/// One line of the projection table.
#[derive(Debug, Clone, PartialEq)]
pub struct Projected {
    /// Nodes.
    pub nodes: usize,
    /// Parallel tasks: nodes x tasks per node.
    pub slots: usize,
    /// Projected wall time of the campaign, s.
    pub wall_s: f64,
    /// Speed-up over one slot.
    pub speedup: f64,
}

/// The projection for each count of `nodes`, with `tasks_per_node` tasks on each.
pub fn project(walls_s: &[f64], nodes: &[usize], tasks_per_node: usize) -> Vec<Projected> {
    let one = makespan_s(walls_s, 1);
    nodes
        .iter()
        .map(|&n| {
            let slots = n.max(1) * tasks_per_node.max(1);
            let wall_s = makespan_s(walls_s, slots);
            Projected { nodes: n, slots, wall_s, speedup: if wall_s > 0.0 { one / wall_s } else { 1.0 } }
        })
        .collect()
}

/// `1 h 05 min`, `12 min`, `40 s`.
pub fn human(s: f64) -> String {
    let s = s.max(0.0).round() as u64;
    match s {
        0..=119 => format!("{s} s"),
        120..=3599 => format!("{} min", (s + 30) / 60),
        _ => format!("{} h {:02} min", s / 3600, (s % 3600 + 30) / 60),
    }
}

/// The projection table of the poses `plan` selects (`needle fe status --project-nodes`):
/// each pose's measured wall time on this engine, mesh and step count from the manifest,
/// or the median of the measured runs of its model kind (quarter, half, full block) when
/// it has none.
pub fn table(plan: &Plan, nodes: &[usize], tasks_per_node: usize) -> String {
    let engine = plan.campaign.solver.engine.name();
    let measured =
        |e: &&crate::manifest::ManifestEntry| e.engine == engine && e.mesh == plan.mesh_name && e.steps == plan.steps && e.wall_s > 0.0;
    let by_kind = plan.manifest.wall_times_s(engine, &plan.mesh_name, plan.steps);
    let median = |v: &Vec<f64>| {
        let mut v = v.clone();
        v.sort_by(f64::total_cmp);
        v.get(v.len() / 2).copied()
    };
    let kind_median: BTreeMap<&String, f64> = by_kind.iter().filter_map(|(k, v)| median(v).map(|m| (k, m))).collect();
    let (mut walls, mut own, mut estimated, mut unknown) = (Vec::new(), 0, 0, Vec::new());
    for p in &plan.selected {
        if let Some(e) = plan.manifest.pose.get(&p.name).filter(measured) {
            walls.push(e.wall_s);
            own += 1;
        } else if let Some(&m) = kind_median.get(&mesh_summary::model_name(p.symmetry()).to_string()) {
            walls.push(m);
            estimated += 1;
        } else {
            unknown.push(p.name.clone());
        }
    }
    let mut s = String::new();
    let total: f64 = walls.iter().sum();
    let _ = writeln!(
        s,
        "projection ({engine}, mesh {}, {} steps): {} runs, {own} measured, {estimated} at their model kind's median, total {} of solver time",
        plan.mesh_name,
        plan.steps,
        walls.len(),
        human(total)
    );
    if !unknown.is_empty() {
        let _ = writeln!(s, "  left out (no measured run of their model kind): {}", unknown.join(", "));
    }
    let _ = writeln!(s, "{:>6}  {:>6}  {:>14}  {:>8}", "nodes", "tasks", "wall", "speed-up");
    for r in project(&walls, nodes, tasks_per_node) {
        let _ = writeln!(s, "{:>6}  {:>6}  {:>14}  {:>7.1}x", r.nodes, r.slots, human(r.wall_s), r.speedup);
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn longest_first_to_the_earliest_free_slot() {
        // one slot: the sum
        assert_eq!(makespan_s(&[3.0, 1.0, 2.0], 1), 6.0);
        // two slots: 5 | 3, then 2 joins the 3 (5 | 5), then 1 joins either: 6
        assert_eq!(makespan_s(&[5.0, 3.0, 2.0, 1.0], 2), 6.0);
        // more slots than runs: the longest run
        assert_eq!(makespan_s(&[5.0, 3.0], 8), 5.0);
        // the longest run bounds it from below, the mean load too
        let w: Vec<f64> = (1..=40).map(f64::from).collect();
        let m = makespan_s(&w, 4);
        assert!((820.0 / 4.0..=820.0 / 4.0 + 40.0).contains(&m), "{m}");
        let p = project(&w, &[1, 2], 2);
        assert_eq!((p[0].slots, p[1].slots), (2, 4));
        assert!(p[1].speedup > p[0].speedup);
    }

    #[test]
    fn human_times() {
        assert_eq!(human(40.0), "40 s");
        assert_eq!(human(720.0), "12 min");
        assert_eq!(human(3900.0), "1 h 05 min");
    }
}
