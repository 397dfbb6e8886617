//! `needle_insertion_init_file` (issue 65): a tissue file loaded at run time through the C
//! API steps bit for bit as the library does with the same file
//! (`needle_calibrate::runtime_stack`), and a refused file says why with `FILE:LINE`,
//! leaving the state untouched.
use needle_calibrate::runtime_stack::OwnedStack;
use needle_capi::*;
use needle_haptics::insertion::{Insertion, InsertionConfig};
use needle_haptics::Pose;
use std::ffi::{c_char, CStr, CString};
use std::path::PathBuf;

/// A stack calibrated by `needle calibrate --trials` on a rig trial: a family member, a
/// softening and Prony terms (coeffs/README.md, "calibrated/").
fn calibrated() -> PathBuf {
    needle_stdx::workspace_root().join("coeffs/default/calibrated/rig_skin_2mmps_t1.toml")
}

fn empty_state() -> needle_insertion_t {
    needle_insertion_t { storage: [0; NEEDLE_INSERTION_STORAGE_WORDS], magic: 0 }
}

fn init(state: &mut needle_insertion_t, path: &std::path::Path) -> (i32, String) {
    let c_path = CString::new(path.to_string_lossy().as_bytes()).expect("no NUL in the path");
    let mut message = [0 as c_char; 512];
    // SAFETY: valid pointers; `message` has its length's bytes.
    let rc = unsafe { needle_insertion_init_file(state, c_path.as_ptr(), 0.001, 0.005, message.as_mut_ptr(), message.len()) };
    // SAFETY: the function NUL-terminates within the buffer.
    (rc, unsafe { CStr::from_ptr(message.as_ptr()) }.to_string_lossy().into_owned())
}

#[test]
fn a_tissue_file_steps_as_the_library_steps_it() {
    let mut state = empty_state();
    let (rc, message) = init(&mut state, &calibrated());
    assert_eq!((rc, message.as_str()), (NEEDLE_OK, ""));
    let stack = OwnedStack::load(&calibrated()).expect("the calibrated stack");
    let mut model = Insertion::new(&stack.as_stack(), InsertionConfig::DEFAULT_1KHZ).expect("the library takes it");
    let (mut punctures, mut ticks) = (0u32, 0u32);
    // down to 40 mm in 20 s, back out to above the surface in 20 s (1 kHz)
    for k in 0..40_000u32 {
        let t = k as f32 * 0.001;
        let depth_mm = if t < 20.0 { -1.0 + 2.05 * t } else { 40.0 - 2.05 * (t - 20.0) };
        let pose = needle_pose_t { x_mm: 0.5, z_mm: -0.25, theta_x_deg: 1.0, theta_z_deg: 0.0, depth_mm };
        let mut out = needle_insertion_result_t::default();
        // SAFETY: valid pointers; the state was set up above.
        assert_eq!(unsafe { needle_insertion_step(&mut state, &pose, &mut out) }, NEEDLE_OK);
        let want = model.step(&Pose { x_mm: 0.5, z_mm: -0.25, theta_x_deg: 1.0, theta_z_deg: 0.0, depth_mm });
        let w = out.wrench;
        let got = [w.fx_n, w.fy_n, w.fz_n, w.mx_nmm, w.my_nmm, w.mz_nmm].map(f32::to_bits);
        assert_eq!(got, want.wrench.to_array().map(f32::to_bits), "tick {k}");
        assert_eq!(
            (out.status, out.phase, out.punctures, out.flags),
            (want.status.bits(), want.phase.code(), want.punctures, want.flags.bits())
        );
        punctures += u32::from(out.punctures);
        ticks += 1;
    }
    assert_eq!(ticks, 40_000);
    assert!(punctures >= 1, "the path punctures the calibrated skin");
}

#[test]
fn a_refused_file_names_its_line_and_leaves_the_state_as_it_was() {
    let text = std::fs::read_to_string(calibrated()).expect("the calibrated stack");
    let line = text.lines().position(|l| l.starts_with("stiffness_scale = ")).expect("a scale") + 1;
    let dir = std::env::temp_dir().join(format!("needle-capi-file-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("a scratch folder");
    let bad = dir.join("bad.toml");
    std::fs::write(&bad, text.replacen("stiffness_scale = ", "stiffness_scale = -", 1)).expect("write");
    let mut state = empty_state();
    let (rc, message) = init(&mut state, &bad);
    assert_eq!(rc, NEEDLE_E_ARG, "{message}");
    assert!(message.contains(&format!("bad.toml:{line}:")) && message.contains("stiffness_scale"), "{message}");
    assert_eq!(state.magic, 0, "the state is untouched");
    let (rc, message) = init(&mut state, &dir.join("missing.toml"));
    assert_eq!(rc, NEEDLE_E_ARG);
    assert!(message.contains("missing.toml"), "{message}");
    // a short buffer gets a cut, NUL-terminated message; NULL pointers are refused
    let c_path = CString::new(bad.to_string_lossy().as_bytes()).expect("path");
    let mut short = [1 as c_char; 8];
    // SAFETY: valid pointers, `short` has 8 bytes.
    let rc = unsafe { needle_insertion_init_file(&mut state, c_path.as_ptr(), 0.001, 0.005, short.as_mut_ptr(), short.len()) };
    assert_eq!((rc, short[7]), (NEEDLE_E_ARG, 0));
    // SAFETY: NULL is allowed and refused.
    let rc = unsafe { needle_insertion_init_file(&mut state, std::ptr::null(), 0.001, 0.005, std::ptr::null_mut(), 0) };
    assert_eq!(rc, NEEDLE_E_NULL);
    let _ = std::fs::remove_dir_all(&dir);
}
