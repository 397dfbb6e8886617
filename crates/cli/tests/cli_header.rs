//! `needle header --out DIR` writes both C headers a C user needs: needle_coeffs.h (the
//! model's tables, from the build) and needle.h (the C API, from needle-capi).

mod common;
use common::needle;

#[test]
fn header_writes_the_tables_and_the_api_header() {
    let d = tempfile::tempdir().expect("tempdir");
    let out_dir = d.path().join("include");
    let out = needle(&["header".as_ref(), "--out".as_ref(), out_dir.as_os_str()]);
    assert!(out.status.success(), "needle header failed: {}", String::from_utf8_lossy(&out.stderr));
    let coeffs = std::fs::read_to_string(out_dir.join("needle_coeffs.h")).expect("needle_coeffs.h written");
    assert_eq!(coeffs, needle_haptics::model_info::C_HEADER);
    let api = std::fs::read_to_string(out_dir.join("needle.h")).expect("needle.h written");
    assert_eq!(api, needle_capi::HEADER);
    for item in
        ["needle_wrench(", "needle_strerror(", "needle_status_name(", "#define NEEDLE_STATUS_SAT_X 1", "#define NEEDLE_LOOP_DISABLED 256"]
    {
        assert!(api.contains(item), "needle.h lacks {item}");
    }
}

/// Issue 38: on a failure between the two headers (a full disk, a refused path) the
/// first was already replaced, leaving a new needle_coeffs.h beside an old needle.h.
/// Now both are written or neither.
#[test]
fn header_writes_both_or_neither() {
    let d = tempfile::tempdir().expect("tempdir");
    let out_dir = d.path().join("include");
    std::fs::create_dir_all(out_dir.join("needle.h")).expect("a folder where needle.h goes");
    std::fs::write(out_dir.join("needle_coeffs.h"), "old\n").expect("old header");
    let out = needle(&["header".as_ref(), "--out".as_ref(), out_dir.as_os_str()]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(err.contains("needle.h: is a folder"), "{err}");
    assert_eq!(std::fs::read_to_string(out_dir.join("needle_coeffs.h")).expect("kept"), "old\n", "the old header is kept");
    let names: Vec<String> =
        std::fs::read_dir(&out_dir).expect("dir").map(|e| e.expect("entry").file_name().to_string_lossy().into_owned()).collect();
    assert_eq!(names.len(), 2, "no temporary left: {names:?}");
}
