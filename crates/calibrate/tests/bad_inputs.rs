//! Issue 66: the inputs that made `needle calibrate` panic, abort, grow without bound or
//! scan forever, and the curves whose refusal named the wrong cause, each refused before
//! any work with the real cause (the range and its unit, the line).
use needle_calibrate::events::EventRule;
use needle_calibrate::{calibrate, calibrate_points, limits, measured, Options};
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

fn liver() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../coeffs/default/measured/okamura2004-bovine-liver/position_force.csv")
}

fn options(curve: &Path) -> Options<'_> {
    Options {
        curve,
        name: "liver".into(),
        needle_diameter_mm: 1.27,
        speed_mm_per_s: 3.0,
        rule: EventRule::default(),
        fe_shear_modulus_n_per_mm2: 0.0012,
    }
}

/// The liver's points with positions and forces scaled.
fn scaled(position: f64, force: f64) -> Vec<measured::Point> {
    measured::read_curve(&liver())
        .expect("the shipped curve")
        .into_iter()
        .map(|p| measured::Point { position_mm: p.position_mm * position, force_n: p.force_n * force, line: p.line })
        .collect()
}

fn refused<T>(r: anyhow::Result<T>, what: &str) -> String {
    match r {
        Ok(_) => panic!("{what}: accepted"),
        Err(e) => format!("{e:#}"),
    }
}

fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).expect("temp file");
    p
}

#[test]
fn issue66_3_a_needle_diameter_of_1e20_mm_is_refused_with_its_range() {
    let path = liver();
    for d in [1e20, 0.0, -1.0, f64::NAN, 0.01, 50.0] {
        let e = refused(calibrate(&Options { needle_diameter_mm: d, ..options(&path) }), "needle diameter");
        assert!(e.contains("--needle-diameter-mm") && e.contains("from 0.1 to 10 mm"), "{d}: {e}");
    }
}

#[test]
fn issue66_4_a_speed_of_1e_5_mm_per_s_is_refused_before_any_allocation() {
    let path = liver();
    let e = refused(calibrate(&Options { speed_mm_per_s: 1e-5, ..options(&path) }), "speed 1e-5");
    assert!(e.contains("--speed-mm-per-s") && e.contains("mm/s"), "{e}");
    let start = Instant::now();
    let e = refused(calibrate(&Options { speed_mm_per_s: 0.001, ..options(&path) }), "speed 1e-3");
    assert!(e.contains("from 0.01 to 1000 mm/s"), "{e}");
    // in the range, but the replay of the liver's 96 mm (positions doubled) at 0.01 mm/s
    // is 9.6e6 ticks, more than the limit
    let e = refused(calibrate_points(&Options { speed_mm_per_s: 0.01, ..options(&path) }, scaled(2.0, 1.0)), "speed 0.01");
    assert!(e.contains("ticks") && e.contains("--speed-mm-per-s 0.01"), "{e}");
    assert!(start.elapsed() < Duration::from_secs(5), "refused before the fit: {:?}", start.elapsed());
}

#[cfg(unix)]
#[test]
fn issue66_5_dev_zero_as_the_curve_is_refused_after_the_byte_limit() {
    let start = Instant::now();
    let e = refused(measured::read_curve(Path::new("/dev/zero")), "/dev/zero");
    assert!(e.contains(&format!("at most {} bytes", limits::MAX_CURVE_BYTES)), "{e}");
    assert!(start.elapsed() < Duration::from_secs(10), "{:?}", start.elapsed());
}

#[test]
fn issue66_6_positions_in_micrometres_or_larger_are_refused_as_a_unit_problem() {
    let path = liver();
    for factor in [1e3, 1e6, 1e30] {
        let start = Instant::now();
        let e = refused(calibrate_points(&options(&path), scaled(factor, 1.0)), "scaled positions");
        assert!(e.contains("positions span") && e.contains("micrometres"), "x{factor}: {e}");
        assert!(start.elapsed() < Duration::from_secs(2), "x{factor}: {:?}", start.elapsed());
    }
    // and in metres
    let e = refused(calibrate_points(&options(&path), scaled(1e-3, 1.0)), "positions in metres");
    assert!(e.contains("less than 1 mm") && e.contains("metres"), "{e}");
    // forces in mN
    let e = refused(calibrate_points(&options(&path), scaled(1.0, 1e3)), "forces in mN");
    assert!(e.contains("forces in mN"), "{e}");
}

#[test]
fn issue66_7_a_curve_of_more_than_max_points_rows_is_refused_while_reading() {
    let dir = tempfile::tempdir().expect("temp dir");
    let mut text = String::from("position_mm,force_n\n");
    for i in 0..=limits::MAX_POINTS {
        text.push_str(&format!("{},1\n", i as f64 * 1e-4));
    }
    let path = write(dir.path(), "dense.csv", &text);
    let e = refused(measured::read_curve(&path), "too many rows");
    assert!(e.contains(&format!("more than {} points", limits::MAX_POINTS)) && e.contains("resample"), "{e}");
    assert!(e.contains(&format!(":{}:", limits::MAX_POINTS + 2)), "names the line: {e}");
}

#[test]
fn issue66_10_a_drop_fraction_outside_0_to_1_or_nan_is_refused_with_its_range() {
    let path = liver();
    for f in [-0.1, 0.0, 1.0, 1.5, f64::NAN] {
        let rule = EventRule { drop_fraction: f, ..EventRule::default() };
        let e = refused(calibrate(&Options { rule, ..options(&path) }), "drop fraction");
        assert!(e.starts_with(&format!("--drop-fraction {f}: must be a number from")), "{f}: {e}");
        assert!(!e.contains("no drop of"), "the real cause, not a missing puncture: {e}");
    }
}

#[test]
fn message_all_positions_equal_says_so_not_a_zero_stiffness() {
    let path = liver();
    let points: Vec<measured::Point> = scaled(1.0, 1.0).into_iter().map(|p| measured::Point { position_mm: 5.0, ..p }).collect();
    let e = refused(calibrate_points(&options(&path), points), "all positions equal");
    assert!(e.contains("every position is 5 mm"), "{e}");
    assert!(!e.contains("stiffness_scale"), "{e}");
}

#[test]
fn message_shuffled_rows_say_the_order_not_the_drop_fraction() {
    let dir = tempfile::tempdir().expect("temp dir");
    let text = std::fs::read_to_string(liver()).expect("curve");
    let mut lines: Vec<&str> = text.lines().skip(1).collect();
    // a fixed permutation: every 7th row first, then the rest
    let mut shuffled: Vec<&str> = lines.iter().step_by(7).copied().collect();
    lines = lines.iter().enumerate().filter(|(i, _)| i % 7 != 0).map(|(_, l)| *l).collect();
    shuffled.extend(lines);
    let path = write(dir.path(), "shuffled.csv", &format!("position_mm,force_n\n{}\n", shuffled.join("\n")));
    let e = refused(calibrate(&options(&path)), "shuffled rows");
    assert!(e.contains("in the order of the insertion") && e.contains("shuffled.csv:"), "{e}");
    assert!(!e.contains("--drop-fraction"), "{e}");
}

#[test]
fn message_one_spike_of_1e6_n_names_its_line_not_a_missing_puncture() {
    let dir = tempfile::tempdir().expect("temp dir");
    let text = std::fs::read_to_string(liver()).expect("curve");
    let mut lines: Vec<String> = text.lines().map(String::from).collect();
    let (p, _) = lines[100].split_once(',').expect("a row");
    lines[100] = format!("{p},1e6");
    let path = write(dir.path(), "spike.csv", &(lines.join("\n") + "\n"));
    let e = refused(calibrate(&options(&path)), "a spike");
    assert!(e.contains("spike.csv:101") && e.contains("1000000 N is beyond"), "{e}");
    assert!(!e.contains("no puncture found"), "{e}");
}
