//! The block's two mirrors hold bit for bit in the library (coeffs/README.md, "Mirror
//! symmetries and `odd`"): under x -> -x ((x, theta_z) -> (-x, -theta_z)) and under
//! z -> -z ((z, theta_x) -> (-z, -theta_x)), every component odd under that mirror is
//! exactly the negation and every even one is unchanged, in f32 (`wrench`, compared as
//! floats, so +0.0 == -0.0) and in fixed point (`fixed::wrench`, integers), on a grid of
//! poses that includes the mirror planes themselves: an odd component is exactly 0 there.
use needle_contract::{COMPONENTS, ODD};
use needle_haptics::{fixed, model_info, wrench, Pose};

const OFFSETS: [f32; 7] = [0.0, 0.5, -0.5, 3.0, -3.0, 11.9, -11.9];
const TILTS: [f32; 5] = [0.0, 2.0, -2.0, 14.0, -14.0];
const DEPTHS: [f32; 4] = [0.5, 2.0, 4.0, 6.0];

/// The mirrors: name, the sweep whose parities (`ODD[k]`) it flips, and the pose map.
const MIRRORS: [(&str, usize); 2] = [("x -> -x", 0), ("z -> -z", 1)];

fn mirror(k: usize, p: [f32; 5]) -> [f32; 5] {
    let [x, z, tx, tz, d] = p;
    if k == 0 {
        [-x, z, tx, -tz, d]
    } else {
        [x, -z, -tx, tz, d]
    }
}

fn grid() -> Vec<[f32; 5]> {
    let mut poses = Vec::new();
    for &x in &OFFSETS {
        for &z in &OFFSETS {
            for &tx in &TILTS {
                for &tz in &TILTS {
                    for &d in &DEPTHS {
                        poses.push([x, z, tx, tz, d]);
                    }
                }
            }
        }
    }
    poses
}

fn q16(v: f32) -> i32 {
    // Every grid value times 65536 is an integer well inside i32.
    (f64::from(v) * 65536.0) as i32
}

/// The components of `a` and `b` that break the mirror's parities, as text.
fn broken<T: Copy + PartialEq + std::fmt::Debug + std::ops::Neg<Output = T>>(k: usize, a: [T; 6], b: [T; 6]) -> Vec<String> {
    (0..6)
        .filter(|&c| if ODD[k][c] { a[c] != -b[c] } else { a[c] != b[c] })
        .map(|c| format!("{} {:?} vs {:?}", COMPONENTS[c], a[c], b[c]))
        .collect()
}

#[test]
fn odd_components_flip_and_even_ones_stay_bit_for_bit() {
    if !model_info::FITTED {
        panic!("the library was built without a fitted model ({}): run `needle fit`", model_info::SET_DIR);
    }
    let poses = grid();
    let mut failures = Vec::new();
    let (mut bad_f32, mut bad_fixed) = (0usize, 0usize);
    for (name, k) in MIRRORS {
        for &p in &poses {
            let m = mirror(k, p);
            let [x, z, tx, tz, d] = p;
            let [mx, mz, mtx, mtz, md] = m;
            let a = wrench(&Pose::new(x, z, tx, tz, d));
            let b = wrench(&Pose::new(mx, mz, mtx, mtz, md));
            let e = broken(k, a.wrench.to_array(), b.wrench.to_array());
            if !e.is_empty() || a.status != b.status {
                bad_f32 += 1;
                failures.push(format!("f32 {name} at {p:?}: {}", e.join(", ")));
            }
            let fa = fixed::wrench(&fixed::Pose::new(q16(x), q16(z), q16(tx), q16(tz), q16(d)));
            let fb = fixed::wrench(&fixed::Pose::new(q16(mx), q16(mz), q16(mtx), q16(mtz), q16(md)));
            let e = broken(k, fa.wrench.to_array(), fb.wrench.to_array());
            if !e.is_empty() || fa.status.bits() != fb.status.bits() {
                bad_fixed += 1;
                failures.push(format!("fixed {name} at {p:?}: {}", e.join(", ")));
            }
        }
    }
    let centre = wrench(&Pose::new(0.0, 0.0, 0.0, 0.0, 3.0)).wrench.to_array();
    println!(
        "{} poses x 2 mirrors: {bad_f32} f32 and {bad_fixed} fixed-point pairs break a parity; fz at the centre (3 mm) {:e} N",
        poses.len(),
        centre[2]
    );
    assert!(
        failures.is_empty(),
        "{} of {} mirrored pairs break a parity (f32 {bad_f32}, fixed {bad_fixed}); first ones:\n{}",
        failures.len(),
        2 * 2 * poses.len(),
        failures.iter().take(12).cloned().collect::<Vec<_>>().join("\n")
    );
}
