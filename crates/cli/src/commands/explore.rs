//! `needle explore`: serve the model explorer page for a set.

use anyhow::{Context, Result};
use clap::Args;
use needle_explore::{self as explore, server::Content, server::Explorer};
use std::net::{IpAddr, Ipv4Addr, SocketAddr};
use std::path::PathBuf;
use std::process::ExitCode;

/// Arguments of `needle explore`.
#[derive(Args, Debug)]
#[command(after_help = "What it builds: the page (HTML, CSS, JavaScript) is inside this binary; the evaluator \
(crates/wasm, the library compiled for wasm32-unknown-unknown with the set's tables) is built by running \
`cargo build --release -p needle-wasm --target wasm32-unknown-unknown` with NEEDLE_COEFFS=<set> in the source \
tree this binary was built from, into its target/firmware/ folder: that needs the source tree, cargo and the \
wasm32 target. Without them, give a prebuilt evaluator with --wasm FILE (the needle_wasm.wasm of that build, \
for the same set); then nothing is built and only the set folder is read.")]
// The fields' doc comments are the --help text, written for the terminal: <set> is a
// placeholder there, not HTML.
#[allow(rustdoc::invalid_html_tags)]
pub struct ExploreArgs {
    /// Set folder holding campaign.toml, fe/ and model.toml, e.g. coeffs/default.
    #[arg(long, value_name = "DIR")]
    pub set: PathBuf,
    /// TCP port; 0 picks a free one (the URL printed says which).
    #[arg(long, default_value_t = 8080)]
    pub port: u16,
    /// Address to listen on; the default serves this machine only.
    #[arg(long, default_value_t = IpAddr::V4(Ipv4Addr::LOCALHOST))]
    pub host: IpAddr,
    /// A prebuilt evaluator (needle_wasm.wasm, built with NEEDLE_COEFFS=<set>) to serve
    /// instead of building one with cargo (see below).
    #[arg(long, value_name = "FILE")]
    pub wasm: Option<PathBuf>,
    /// A tissue file to play in the insertion player besides the compiled-in stacks
    /// (repeatable). With its spread beside it (<name>.spread.csv, written by `needle
    /// calibrate --trials`), the page also offers tissues drawn within that spread.
    #[arg(long, value_name = "FILE")]
    pub stack: Vec<PathBuf>,
    /// Tissues drawn per --stack with a spread: seeds 1 to N, each the tissue `needle
    /// stack sample --seed K` writes.
    #[arg(long, value_name = "N", default_value_t = 5)]
    pub draws: u64,
}

/// Run `needle explore`: build the set's wasm evaluator (or take `--wasm`), print the
/// URL, serve until interrupted. Opens no browser.
///
/// # Errors
/// The set cannot be read, the wasm build fails (or `--wasm` is not a wasm module), or
/// the port cannot be bound.
pub fn run(a: ExploreArgs) -> Result<ExitCode> {
    let set = std::path::absolute(&a.set).with_context(|| format!("{}: not a usable path", a.set.display()))?;
    let set_json = explore::set_json::set_json(&needle_set::set_folder::SetFolder::open(&a.set)?)?;
    let runs = set_json["runs"].as_array().map_or(0, Vec::len);
    let stacks_json = explore::stacks_json::stacks_json(&a.stack, a.draws)?;
    for s in stacks_json.as_array().into_iter().flatten() {
        let drawn = s["drawn"].as_array().map_or(0, Vec::len);
        println!(
            "needle explore: tissue file {} ({} layers), {drawn} tissue(s) drawn within its spread",
            s["file"],
            s["stack"]["words"].as_array().map_or(0, Vec::len)
        );
    }
    let wasm_path = match &a.wasm {
        Some(prebuilt) => prebuilt.clone(),
        None => {
            eprintln!(
                "needle explore: building the wasm evaluator of {} with cargo in {} (--wasm FILE serves a prebuilt one) ...",
                a.set.display(),
                needle_stdx::workspace_root().display()
            );
            explore::wasm::build(&set)?
        }
    };
    let wasm = std::fs::read(&wasm_path).with_context(|| format!("--wasm {}: cannot read", wasm_path.display()))?;
    if !wasm.starts_with(b"\0asm") {
        anyhow::bail!("--wasm {}: not a WebAssembly module (it does not start with \\0asm)", wasm_path.display());
    }
    let explorer = Explorer::bind(
        SocketAddr::new(a.host, a.port),
        Content { wasm, set_json: set_json.to_string(), stacks_json: stacks_json.to_string() },
    )?;
    println!(
        "needle explore: set {} ({runs} FE runs), evaluator {} ({} bytes)",
        a.set.display(),
        wasm_path.display(),
        std::fs::metadata(&wasm_path).map_or(0, |m| m.len())
    );
    println!("open {}   (Ctrl-C stops)", explorer.url());
    explorer.serve();
    Ok(ExitCode::SUCCESS)
}
