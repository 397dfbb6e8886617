//! The JSON of `needle eval --json`: the pose, the wrench with its f32 bits, the status
//! flags, the compiled-in model's form and stated accuracy.
use needle_haptics::{model_info, Evaluation, Pose, Status};

/// Names of the flags set in `status` (empty for OK).
pub fn status_names(status: Status) -> Vec<&'static str> {
    Status::FLAGS.iter().filter(|(f, _)| status.contains(*f)).map(|(_, n)| *n).collect()
}

/// Each component's name and unit, in the contract's order.
pub fn names() -> impl Iterator<Item = (&'static str, &'static str)> {
    needle_contract::COMPONENTS.into_iter().zip(needle_contract::UNITS)
}

/// The compiled-in model's form: `paper` or `coupled`.
pub fn form_name() -> &'static str {
    if model_info::COUPLED {
        "coupled"
    } else {
        "paper"
    }
}

/// The stated accuracy of the compiled-in model (`[coupled]` of its model.toml): the
/// cross-validated RMS error per component, in % and in N or N*mm; `null` for the paper
/// form, whose model.toml records none.
pub fn accuracy_json() -> serde_json::Value {
    if !model_info::COUPLED {
        return serde_json::Value::Null;
    }
    let mut pct = serde_json::Map::new();
    let mut abs = serde_json::Map::new();
    for (((name, _), p), scale) in names().zip(model_info::CV_RMS_PCT).zip(model_info::CV_SCALE) {
        pct.insert((*name).to_string(), serde_json::json!(p));
        abs.insert((*name).to_string(), serde_json::json!(p * scale / 100.0));
    }
    serde_json::json!({
        "method": format!("{}-fold cross-validation over the sweep runs and {} training runs (role train)", needle_fit::coupled::FOLDS, model_info::TRAINING_RUNS),
        "rms_pct_of_scale": pct,
        "rms": abs,
        "scale": "peak |Fy| of the training runs (N) for the forces, times the hub lever arm (N*mm) for the moments",
    })
}

/// The JSON form of `needle eval --poses FILE --json`: an array of [`eval_json`] objects.
pub fn to_json(poses: &[Pose], evals: &[Evaluation]) -> serde_json::Value {
    serde_json::Value::Array(poses.iter().zip(evals).map(|(p, e)| eval_json(p, e)).collect())
}

/// The JSON object `needle eval --json` prints.
pub fn eval_json(pose: &Pose, e: &Evaluation) -> serde_json::Value {
    let mut wrench = serde_json::Map::new();
    let mut bits = serde_json::Map::new();
    for ((name, _), v) in names().zip(e.wrench.to_array()) {
        wrench.insert((*name).to_string(), serde_json::json!(v));
        bits.insert((*name).to_string(), serde_json::json!(format!("{:#010x}", v.to_bits())));
    }
    let pose_bits = [pose.x_mm, pose.z_mm, pose.theta_x_deg, pose.theta_z_deg, pose.depth_mm].map(|v| format!("{:#010x}", v.to_bits()));
    serde_json::json!({
        "set": model_info::SET,
        "fe_sha256": model_info::FE_SHA256,
        "form": form_name(),
        "accuracy": accuracy_json(),
        "pose": {
            "x_mm": pose.x_mm, "z_mm": pose.z_mm, "theta_x_deg": pose.theta_x_deg,
            "theta_z_deg": pose.theta_z_deg, "depth_mm": pose.depth_mm,
        },
        "pose_bits": pose_bits,
        "wrench": wrench,
        "wrench_bits": bits,
        "reference_point": "needle hub (on the axis, needle.reference_from_tip_mm from the tip)",
        "status": {
            "bits": format!("{:#04x}", e.status.bits()),
            "flags": status_names(e.status),
            "ok": e.status.is_ok(),
            "saturated": e.status.saturated(),
            "fe_unsolved": e.status.fe_unsolved(),
            "error": e.status.is_error(),
        },
    })
}
