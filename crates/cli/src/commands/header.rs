//! `needle header`: write the C headers of the library's compiled-in model.
use anyhow::Context;
use clap::Args;
use needle_haptics::model_info;
use std::path::PathBuf;
use std::process::ExitCode;

/// Arguments of `needle header`.
#[derive(Args, Debug)]
pub struct HeaderArgs {
    /// Folder to write needle_coeffs.h (the model's tables) and needle.h (the C API) into
    /// (created if missing).
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
}

/// `needle header`: writes the C headers to `DIR`: `needle_coeffs.h` (generated with the
/// compiled-in tables) and `needle.h` (the C API's header, from `needle-capi`).
///
/// # Errors
/// The folder cannot be created or the file cannot be written.
pub fn run(a: HeaderArgs) -> anyhow::Result<ExitCode> {
    std::fs::create_dir_all(&a.out).with_context(|| format!("creating {}", a.out.display()))?;
    let path = a.out.join(needle_codegen::C_HEADER_FILE);
    // the C API's own header (functions, types, NEEDLE_STATUS_* / NEEDLE_LOOP_* constants)
    let api = a.out.join("needle.h");
    // both or neither: a failure leaves the old pair as it was
    needle_stdx::fs::write_all_atomic(&[(&path, model_info::C_HEADER.as_bytes()), (&api, needle_capi::HEADER.as_bytes())])?;
    println!("wrote {} (the C API: link libneedle_capi.a from `cargo build --release -p needle-capi`)", api.display());
    if model_info::FITTED {
        println!("wrote {} (set {}, fe_sha256 {})", path.display(), model_info::SET, model_info::FE_SHA256);
    } else {
        eprintln!(
            "warning: this build has no fitted model ({} had no model.toml): the header's tables are all zero (NEEDLE_COEFFS_FITTED 0)",
            model_info::SET_DIR
        );
        println!("wrote {}", path.display());
    }
    Ok(ExitCode::SUCCESS)
}
