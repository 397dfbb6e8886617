//! Puts memory.x on the linker's search path and links with cortex-m-rt's link.x and
//! defmt's defmt.x (a build script, not config rustflags: a RUSTFLAGS variable would
//! replace those).
use std::path::PathBuf;

fn main() {
    let out = PathBuf::from(std::env::var_os("OUT_DIR").unwrap_or_default());
    let manifest = PathBuf::from(std::env::var_os("CARGO_MANIFEST_DIR").unwrap_or_default());
    if let Err(e) = std::fs::copy(manifest.join("memory.x"), out.join("memory.x")) {
        println!("cargo::error=cannot copy memory.x to {}: {e}", out.display());
        return;
    }
    println!("cargo::rustc-link-search={}", out.display());
    println!("cargo::rerun-if-changed=memory.x");
    println!("cargo::rustc-link-arg-bins=-Tlink.x");
    println!("cargo::rustc-link-arg-bins=-Tdefmt.x");
}
