//! `needle explore`: serve the model explorer page for a set.

use anyhow::{Context, Result};
use clap::Args;
use needle_explore::{self as explore, server::Content, server::Explorer};
use std::net::{IpAddr, Ipv4Addr, SocketAddr};
use std::path::PathBuf;
use std::process::ExitCode;

/// Arguments of `needle explore`.
#[derive(Args, Debug)]
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
}

/// Run `needle explore`: build the set's wasm evaluator, print the URL, serve until
/// interrupted. Opens no browser.
///
/// # Errors
/// The set cannot be read, the wasm build fails, or the port cannot be bound.
pub fn run(a: ExploreArgs) -> Result<ExitCode> {
    let set = std::path::absolute(&a.set).with_context(|| format!("{}: not a usable path", a.set.display()))?;
    let set_json = explore::set_json::set_json(&needle_set::set_folder::SetFolder::open(&a.set)?)?;
    let runs = set_json["runs"].as_array().map_or(0, Vec::len);
    eprintln!("needle explore: building the wasm evaluator of {} ...", a.set.display());
    let wasm_path = explore::wasm::build(&set)?;
    let wasm = std::fs::read(&wasm_path).with_context(|| format!("{}: cannot read", wasm_path.display()))?;
    let explorer = Explorer::bind(SocketAddr::new(a.host, a.port), Content { wasm, set_json: set_json.to_string() })?;
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
