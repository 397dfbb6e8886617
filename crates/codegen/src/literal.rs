//! Number literals of the generated code.

/// An f32 as a decimal literal that parses back to the same bits (Rust's shortest
/// round-trip form, `1.0`, `-0.25`, `1e-7`).
pub fn f32_literal(v: f32) -> String {
    format!("{v:?}")
}
