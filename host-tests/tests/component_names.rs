//! The wrench types name their fields after the contract's components: `Wrench` and
//! `WrenchRate` (f32 and fixed point) and the C API's structs, in Rust and in the
//! generated header, spell exactly `needle_contract::COMPONENTS` / `FIXED_COMPONENTS` in
//! the contract's order, so the named fields are a view of the one list, not a second one.
use needle_capi::{needle_fixed_wrench_t, needle_wrench_t, HEADER};
use needle_contract::{COMPONENTS, FIXED_COMPONENTS};

/// The field names of a struct from its derived `Debug` text, in declaration order.
fn debug_fields(text: &str) -> Vec<String> {
    let Some((_, body)) = text.split_once('{') else { return Vec::new() };
    body.trim_end_matches('}').split(',').filter_map(|f| f.split_once(':').map(|(name, _)| name.trim().to_string())).collect()
}

/// The field names of `typedef struct { ... } <name>;` in C `text`, in order (comment
/// lines skipped); empty when the typedef is missing.
fn header_fields(text: &str, name: &str) -> Vec<String> {
    let Some(end) = text.find(&format!("}} {name};")) else { return Vec::new() };
    let Some(start) = text.get(..end).and_then(|t| t.rfind("typedef struct {")) else { return Vec::new() };
    text.get(start..end)
        .unwrap_or_default()
        .lines()
        .skip(1)
        .map(str::trim)
        .filter(|l| l.ends_with(';') && !l.starts_with('*') && !l.starts_with("/*"))
        .filter_map(|l| l.trim_end_matches(';').split_whitespace().last().map(str::to_string))
        .collect()
}

fn rates_of(names: &[&str]) -> Vec<String> {
    names.iter().map(|c| format!("d{c}_per_mm")).collect()
}

#[test]
fn f32_wrench_and_rate_fields_are_the_contract_components_in_order() {
    assert_eq!(debug_fields(&format!("{:?}", needle_haptics::Wrench::ZERO)), COMPONENTS);
    assert_eq!(debug_fields(&format!("{:?}", needle_haptics::WrenchRate::ZERO)), rates_of(&COMPONENTS));
}

#[test]
fn fixed_wrench_and_rate_fields_are_the_contract_fixed_components_in_order() {
    assert_eq!(debug_fields(&format!("{:?}", needle_haptics::fixed::Wrench::default())), FIXED_COMPONENTS);
    assert_eq!(debug_fields(&format!("{:?}", needle_haptics::fixed::WrenchRate::default())), rates_of(&FIXED_COMPONENTS));
}

#[test]
fn the_parser_sees_a_reordered_struct() {
    // the check can fail: two fields swapped are not the contract's order
    let swapped = "Wrench { fy_n: 0.0, fx_n: 0.0, fz_n: 0.0, mx_nmm: 0.0, my_nmm: 0.0, mz_nmm: 0.0 }";
    assert_ne!(debug_fields(swapped), COMPONENTS);
    assert_eq!(debug_fields(&swapped.replace("fy_n: 0.0, fx_n", "fx_n: 0.0, fy_n")), COMPONENTS);
}

#[test]
fn c_wrench_structs_are_the_contract_components_in_order() {
    assert_eq!(debug_fields(&format!("{:?}", needle_wrench_t::default())), COMPONENTS);
    assert_eq!(debug_fields(&format!("{:?}", needle_fixed_wrench_t::default())), FIXED_COMPONENTS);
    assert_eq!(header_fields(HEADER, "needle_wrench_t"), COMPONENTS);
    assert_eq!(header_fields(HEADER, "needle_fixed_wrench_t"), FIXED_COMPONENTS);
}

#[test]
fn the_header_parser_sees_a_reordered_struct() {
    let c = "typedef struct {\n  /**\n   * Force along y.\n   */\n  float fy_n;\n  float fx_n;\n} needle_wrench_t;\n";
    assert_eq!(header_fields(c, "needle_wrench_t"), ["fy_n", "fx_n"]);
    assert_ne!(header_fields(c, "needle_wrench_t"), COMPONENTS);
    assert!(header_fields(c, "needle_pose_t").is_empty());
}

/// The string items of the first `[...]` after `marker` in `text` (JavaScript source):
/// every `"..."` literal up to the closing bracket of that array.
fn js_strings_after(text: &str, marker: &str) -> Vec<String> {
    let Some(start) = text.find(marker) else { return Vec::new() };
    let rest = text.get(start + marker.len()..).unwrap_or_default();
    let body = rest.split_once("];").map_or("", |(b, _)| b);
    body.split('"').skip(1).step_by(2).map(str::to_string).collect()
}

const WASM_GLUE: &str = include_str!("../../crates/explore/src/page/needle-wasm.mjs");

#[test]
fn the_explorer_page_lists_the_contract_components_and_status_flags() {
    assert_eq!(js_strings_after(WASM_GLUE, "export const COMPONENTS = ["), COMPONENTS);
    // STATUS_FLAGS: [bit, "NAME"] pairs, every named bit but OK (0)
    let flags = js_strings_after(WASM_GLUE, "export const STATUS_FLAGS = [");
    let want: Vec<&str> = needle_contract::status::NAMES.iter().filter(|(_, bit)| *bit != 0).map(|(n, _)| *n).collect();
    assert_eq!(flags, want);
    for (name, bit) in needle_contract::status::NAMES.iter().filter(|(_, bit)| *bit != 0) {
        assert!(WASM_GLUE.contains(&format!("[0x{bit:02x}, \"{name}\"]")), "STATUS_FLAGS: {name} = 0x{bit:02x}");
    }
    // the reader sees a list that differs
    assert_ne!(js_strings_after("export const COMPONENTS = [\"fy_n\", \"fx_n\"];", "export const COMPONENTS = ["), COMPONENTS);
}
