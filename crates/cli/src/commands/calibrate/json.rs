//! `needle calibrate --json` (`--curve` and `--trials`) and `needle replay --json`: the
//! results as JSON for machines (a non-finite number is `null`).
use needle_calibrate::edges::EdgeWarning;
use needle_calibrate::replay::Check;
use needle_calibrate::trial::Sample;
use needle_calibrate::trial_replay::TrialReplay;
use needle_calibrate::whole::TrialsCalibration;
use serde_json::{json, Value};

fn num(x: f64) -> Value {
    if x.is_finite() {
        json!(x)
    } else {
        Value::Null
    }
}

/// The checks, each with its numbers and whether it is met.
#[must_use]
pub fn checks(cs: &[Check]) -> Value {
    cs.iter()
        .map(|c| json!({"what": c.what, "measured": num(c.measured), "model": num(c.model), "error": num(c.error), "goal": c.goal, "unit": c.unit, "met": c.met()}))
        .collect()
}

/// One trial's rows: time, position, measured and model force, the model's phase code
/// (`needle_haptics::insertion::Phase::code`), and the model's punctures.
#[must_use]
pub fn rows(s: &[Sample], r: &TrialReplay) -> Value {
    let rows: Vec<Value> =
        s.iter().zip(&r.rows).map(|(x, m)| json!([x.time_s, x.position_mm, x.force_n, num(m.force_n), m.phase.code()])).collect();
    let punctures: Vec<Value> =
        r.punctures.iter().map(|p| json!({"time_s": p.time_s, "position_mm": p.position_mm, "force_n": num(p.force_n)})).collect();
    json!({"columns": ["time_s", "position_mm", "force_n", "model_force_n", "model_phase"], "rows": rows, "model_punctures": punctures})
}

/// The fitted values on their range's edge, each with its numbers and its sentence.
#[must_use]
pub fn edges(es: &[EdgeWarning]) -> Value {
    es.iter()
        .map(|e| {
            json!({
                "key": e.key, "parameter": e.parameter, "value": num(e.value), "range": [num(e.range[0]), num(e.range[1])],
                "unit": e.unit, "grid_step": num(e.step), "edge": e.edge.word(),
                "trials_on_edge": e.trials_on_edge.map(|(k, n)| json!({"trials": k, "of": n})), "text": e.to_string(),
            })
        })
        .collect()
}

/// One layer of a tissue file: its values (the file's keys) and its shape.
#[must_use]
pub fn layer(l: &needle_codegen::tissue::Layer) -> Value {
    let range = |r: Option<[f64; 2]>| r.map(|[lo, hi]| json!([num(lo), num(hi)]));
    json!({
        "name": l.name, "thickness_mm": l.thickness_mm, "stiffness_scale": l.stiffness_scale,
        "puncture_force_n": l.puncture_force_n, "cutting_force_n": l.cutting_force_n,
        "friction_static_n_per_mm": l.friction_static_n_per_mm, "friction_coulomb_n_per_mm": l.friction_coulomb_n_per_mm,
        "friction_viscous_n_s_per_mm2": l.friction_viscous_n_s_per_mm2, "stick_band_mm_per_s": l.stick_band_mm_per_s,
        "prony": l.prony.iter().map(|t| json!({"g": t.g, "tau_s": t.tau_s})).collect::<Vec<_>>(),
        "family_weight": l.family_weight, "family_weight_range": range(l.family_weight_range),
        "softening_fraction": l.softening_fraction, "softening_onset_ratio": l.softening_onset_ratio,
        "softening_fraction_range": range(l.softening_fraction_range),
        "presliding_mm": l.presliding_mm, "relaxation_slip_mm": l.relaxation_slip_mm, "tent_n_per_mm": l.tent_n_per_mm,
        "shaft_prony": l.shaft_prony.iter().map(|t| json!({"g": t.g, "tau_s": t.tau_s})).collect::<Vec<_>>(),
    })
}

/// A single-curve calibration (`needle calibrate --curve --json`): the layers, the
/// values on their range's edge, the checks, and per measured point the model's force
/// (the state the model is in when the stage reaches the point).
#[must_use]
pub fn curve_calibration(c: &needle_calibrate::Calibration) -> Value {
    let rows: Vec<Value> = c.points.iter().map(|p| json!([p.position_mm, p.force_n, num(c.replay.before(p.position_mm))])).collect();
    let measured: Vec<Value> =
        c.events.iter().filter_map(|e| c.points.get(e.peak)).map(|p| json!({"position_mm": p.position_mm, "force_n": p.force_n})).collect();
    let model: Vec<Value> = c.replay.punctures.iter().map(|&(p, f)| json!({"position_mm": p, "force_n": num(f)})).collect();
    json!({
        "name": c.stack.name, "warnings": edges(&c.fit.edges), "similarity": c.similarity, "contact_mm": c.fit.onset_mm,
        "layers": c.stack.layers.iter().map(layer).collect::<Vec<_>>(), "checks": checks(&c.checks),
        "measured_punctures": measured,
        "model": {"columns": ["position_mm", "force_n", "model_force_n"], "rows": rows, "model_punctures": model},
    })
}

/// The whole calibration.
#[must_use]
pub fn calibration(c: &TrialsCalibration) -> Value {
    let layers: Vec<Value> = c
        .fitted
        .stack
        .layers
        .iter()
        .zip(&c.fitted.uncertainty)
        .map(|(l, u)| {
            let uncertainty: serde_json::Map<String, Value> = u.iter().map(|(k, n)| ((*k).to_string(), json!(n))).collect();
            let mut v = layer(l);
            v["uncertainty"] = Value::Object(uncertainty);
            v
        })
        .collect();
    let trials: Vec<Value> = c
        .trials
        .iter()
        .zip(&c.replays)
        .zip(&c.checks)
        .map(|((t, r), cs)| {
            let p = &t.phases;
            json!({
                "file": t.name(), "contact_mm": t.onset_mm(),
                "insertion_speed_mm_per_s": p.insertion_speed_mm_per_s, "withdrawal_speed_mm_per_s": p.withdrawal_speed_mm_per_s,
                "hold_s": p.hold_s, "checks": checks(cs), "model": rows(&t.samples, r),
            })
        })
        .collect();
    json!({"name": c.fitted.stack.name, "notes": c.notes, "warnings": edges(&c.edges), "similarity": c.similarity, "layers": layers, "trials": trials})
}
