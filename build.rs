//! Code generation from coeffs/ (in progress).
fn main() {}
