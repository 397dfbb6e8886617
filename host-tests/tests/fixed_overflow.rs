//! No intermediate of the fixed-point evaluation overflows, checked with checked
//! arithmetic: the fitter's independent implementation (`fit::eval::fixed`, i64 with checked
//! operations, every intermediate held to the contract's |v| <= 2^30) runs on a dense grid
//! and on proptest-random poses over all of i32, and the library (wrapping i32, which
//! would give a different result had anything wrapped) must give the same integers.
//!
//! Also: the fitter's choice of formats equals the tables compiled into the library, and
//! the checker does catch an overflow when the formats are one bit too ambitious.
use needle_contract::{COMPONENT_COUNT, TERMS};
use needle_fit::eval::fixed::eval;
use needle_fit::fixed_formats::TablesFixed;
use needle_fit::model_file;
use needle_haptics::fixed::{self, tables};
use needle_haptics::model_info;
use proptest::prelude::*;
use std::path::Path;
use std::sync::OnceLock;

fn fitter_tables() -> &'static TablesFixed {
    static T: OnceLock<TablesFixed> = OnceLock::new();
    T.get_or_init(|| {
        if !model_info::FITTED {
            panic!("no fitted model compiled in: run `needle fit`");
        }
        let model = model_file::read(&Path::new(model_info::SET_DIR).join("model.toml")).unwrap_or_else(|e| panic!("{e:#}"));
        // the set's unsolved region too: the library flags FE_UNSOLVED in the status
        let region = needle_fit::unsolved::region(
            &needle_set::set_folder::SetFolder::open(Path::new(model_info::SET_DIR)).unwrap_or_else(|e| panic!("{e:#}")),
        )
        .unwrap_or_else(|e| panic!("{e:#}"));
        TablesFixed::from_model(&model).unwrap_or_else(|e| panic!("{e:#}")).with_unsolved(region.entries())
    })
}

fn check_pose(t: &TablesFixed, p: [i32; 5]) {
    let (want, status) = eval(t, p).unwrap_or_else(|e| panic!("pose {p:?}: {e}"));
    let got = fixed::wrench(&fixed::Pose::new(p[0], p[1], p[2], p[3], p[4]));
    assert_eq!((got.wrench.to_array(), got.status.bits()), (want, status), "pose {p:?}");
}

#[test]
fn fitter_formats_equal_the_generated_tables() {
    let t = fitter_tables();
    for c in 0..needle_contract::COMPONENT_COUNT {
        assert_eq!(t.acc_frac[c], tables::FRAC_BITS[c], "G of component {c}");
        assert_eq!(t.baseline[c].map(|v| v as i32), tables::BASELINE[c], "baseline {c}");
        for k in 0..4 {
            for i in 0..5 {
                assert_eq!(t.rows[k][c][i].map(|v| v as i32), tables::ROWS[c][k][i], "row k={k} c={c} i={i}");
                assert_eq!(t.row_frac[k][c][i] - t.acc_frac[c], tables::SHIFTS[c][k][i], "shift k={k} c={c} i={i}");
            }
        }
    }
}

/// 13 points per input over the domain plus one unit beyond each end: 15^5 = 759,375 poses.
#[test]
fn no_overflow_on_a_dense_grid() {
    let t = fitter_tables();
    let max = [12i64 << 16, 12 << 16, 15 << 16, 15 << 16, 6 << 16];
    let axis: Vec<Vec<i32>> = (0..5)
        .map(|i| {
            let lo = if i < 4 { -max[i] } else { 0 };
            let mut a: Vec<i32> = (0..13).map(|m| (lo + (max[i] - lo) * m / 12) as i32).collect();
            a.push((lo - 1) as i32);
            a.push((max[i] + 1) as i32);
            a
        })
        .collect();
    let mut n = 0usize;
    for &x in &axis[0] {
        for &z in &axis[1] {
            for &tx in &axis[2] {
                for &tz in &axis[3] {
                    for &d in &axis[4] {
                        check_pose(t, [x, z, tx, tz, d]);
                        n += 1;
                    }
                }
            }
        }
    }
    println!("{n} grid poses: no intermediate beyond 2^30, library equal");
}

/// Any i32 input, and inputs inside the domain (where saturation does not hide them).
fn input(max: i32) -> impl Strategy<Value = i32> {
    prop_oneof![any::<i32>(), -max - 1..=max + 1]
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(20_000))]
    #[test]
    fn no_overflow_on_random_poses(
        x in input(12 << 16), z in input(12 << 16), tx in input(15 << 16), tz in input(15 << 16), d in input(6 << 16),
    ) {
        check_pose(fitter_tables(), [x, z, tx, tz, d]);
    }
}

/// The checker is not vacuous: made-up tables whose Horner in u reaches 2^30 + 1 at full
/// depth (u = +1) are reported there, and not at half depth (u = 0).
#[test]
fn an_intermediate_beyond_two_to_the_thirty_is_caught() {
    let mut t = fitter_tables().clone();
    for k in 0..4 {
        for c in 0..COMPONENT_COUNT {
            t.rows[k][c] = [[0; TERMS]; TERMS];
            t.row_frac[k][c] = [0; TERMS];
        }
    }
    t.acc_frac = [0; COMPONENT_COUNT];
    t.baseline = [[0; TERMS]; COMPONENT_COUNT];
    // B(u) = 2^29 + (2^29 + 1) u: 2^30 + 1 at u = +1
    t.baseline[1] = [0; TERMS];
    t.baseline[1][0] = 1 << 29;
    t.baseline[1][1] = (1 << 29) + 1;
    let full = eval(&t, [0, 0, 0, 0, 6 << 16]);
    assert!(full.is_err(), "2^30 + 1 at u = +1 not caught: {full:?}");
    assert!(format!("{}", full.unwrap_err()).contains("component 1"));
    let half = eval(&t, [0, 0, 0, 0, 3 << 16]).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(half.0[1], 1 << 29);
}
