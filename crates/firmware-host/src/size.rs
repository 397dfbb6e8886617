//! Flash and RAM of the model on each core, from binutils on the `no_panic` example ELF
//! (f32 evaluator) and the `no_panic_fixed` one (fixed-point evaluator).
//!
//! `no_panic` is the smallest firmware holding the model: cortex-m-rt's vector table and
//! startup, a `main` that calls [`needle_haptics::wrench`] through a function pointer
//! (so the evaluator is one out-of-line function) on one pose, no formatting, no
//! constant data of its own. So in its ELF:
//!
//! - *evaluator code*: the text symbols of `needle_haptics::` (`wrench`);
//! - *tables*: the whole `.rodata` section (the coefficient tables and the `ODD` flags,
//!   anonymous constants: named `.Lanon.*` on some targets, unnamed on others);
//! - *compiler runtime*: the `compiler_builtins` / `__aeabi_*` functions the evaluator
//!   calls (the soft-float add, multiply and compare on the M3 and M0; none on the M4F);
//! - *startup*: everything else (vector table, `Reset`, handlers, `main`);
//! - *static RAM*: `.data` + `.bss` of the whole image.
//!
//! Model flash = evaluator code + tables + compiler runtime.
use super::{build, build::Features, qemu::find_on_path, Core};
use anyhow::{bail, Context};
use std::path::{Path, PathBuf};
use std::process::Command;

/// A binutils program: `arm-none-eabi-<name>`, else the host's `<name>` (Debian's
/// binutils read ARM ELF).
///
/// # Errors
/// Neither is on `PATH`.
pub fn binutil(name: &str) -> anyhow::Result<PathBuf> {
    find_on_path(&format!("arm-none-eabi-{name}"))
        .or_else(|| find_on_path(name))
        .ok_or_else(|| anyhow::anyhow!("neither arm-none-eabi-{name} nor {name} is on PATH: `apt-get install binutils-arm-none-eabi`"))
}

fn output(program: &Path, args: &[&str], elf: &Path) -> anyhow::Result<String> {
    let out = Command::new(program).args(args).arg(elf).output().with_context(|| format!("cannot run {}", program.display()))?;
    if !out.status.success() {
        bail!("{} {} {}: {}", program.display(), args.join(" "), elf.display(), String::from_utf8_lossy(&out.stderr));
    }
    Ok(String::from_utf8_lossy(&out.stdout).into_owned())
}

/// One sized symbol of the ELF.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Symbol {
    /// Address.
    pub addr: u64,
    /// Size in bytes.
    pub size: u64,
    /// nm's type letter (`t`/`T` code, `r`/`R` read-only data, `d`/`b` RAM).
    pub kind: char,
    /// Demangled name.
    pub name: String,
}

/// Flash and RAM of the model in one core's `no_panic` (or `no_panic_fixed`) ELF.
#[derive(Debug, Clone)]
pub struct SizeReport {
    /// The core.
    pub core: Core,
    /// Which evaluator the ELF holds: `f32` (`no_panic`) or `fixed` (`no_panic_fixed`).
    pub evaluator: &'static str,
    /// The ELF measured.
    pub elf: PathBuf,
    /// Berkeley `size`: text (code and read-only data, flash), data (flash and RAM), bss (RAM).
    pub text: u64,
    /// See [`SizeReport::text`].
    pub data: u64,
    /// See [`SizeReport::text`].
    pub bss: u64,
    /// Bytes of the `.rodata` section (the model's tables).
    pub tables: u64,
    /// The library's code symbols (`wrench`).
    pub evaluator_code: Vec<Symbol>,
    /// The compiler runtime functions in the image (soft float).
    pub runtime: Vec<Symbol>,
    /// Named read-only data symbols inside `.rodata` (may be none).
    pub table_symbols: Vec<Symbol>,
}

impl SizeReport {
    /// Bytes of the evaluator's code.
    #[must_use]
    pub fn evaluator_bytes(&self) -> u64 {
        self.evaluator_code.iter().map(|s| s.size).sum()
    }

    /// Bytes of the compiler runtime functions.
    #[must_use]
    pub fn runtime_bytes(&self) -> u64 {
        self.runtime.iter().map(|s| s.size).sum()
    }

    /// Flash of the model: evaluator code, tables and compiler runtime.
    #[must_use]
    pub fn model_flash(&self) -> u64 {
        self.evaluator_bytes() + self.tables + self.runtime_bytes()
    }

    /// Static RAM of the whole image (`.data` + `.bss`).
    #[must_use]
    pub fn static_ram(&self) -> u64 {
        self.data + self.bss
    }
}

/// Parses `size -B` output: (text, data, bss) of its one file.
///
/// # Errors
/// Not the expected format.
pub fn parse_berkeley(text: &str) -> anyhow::Result<(u64, u64, u64)> {
    let line = text.lines().nth(1).context("size printed no line for the file")?;
    let v: Vec<u64> = line.split_whitespace().take(3).filter_map(|w| w.parse().ok()).collect();
    match v[..] {
        [t, d, b] => Ok((t, d, b)),
        _ => bail!("unexpected size output line {line:?}"),
    }
}

/// (text, data, bss) of `elf` from `size -B`: flash holds text + data, RAM data + bss.
///
/// # Errors
/// binutils missing or their output unexpected.
pub fn berkeley(elf: &Path) -> anyhow::Result<(u64, u64, u64)> {
    parse_berkeley(&output(&binutil("size")?, &["-B"], elf)?)
}

/// The size of `section` in `size -A` output (0 when absent).
#[must_use]
pub fn section_size(sysv: &str, section: &str) -> u64 {
    sysv.lines()
        .find_map(|l| {
            let mut w = l.split_whitespace();
            (w.next() == Some(section)).then(|| w.next().and_then(|s| s.parse().ok())).flatten()
        })
        .unwrap_or(0)
}

/// Parses `nm -S -C` output (symbols with a size only), one entry per address.
#[must_use]
pub fn parse_nm(text: &str) -> Vec<Symbol> {
    let mut out: Vec<Symbol> = Vec::new();
    for line in text.lines() {
        let mut parts = line.splitn(4, ' ');
        let (Some(a), Some(s), Some(k), Some(name)) = (parts.next(), parts.next(), parts.next(), parts.next()) else {
            continue;
        };
        let (Ok(addr), Ok(size)) = (u64::from_str_radix(a, 16), u64::from_str_radix(s, 16)) else {
            continue;
        };
        let Some(kind) = k.chars().next() else { continue };
        if size == 0 || out.iter().any(|o| o.addr == addr && o.kind.eq_ignore_ascii_case(&kind)) {
            continue;
        }
        out.push(Symbol { addr, size, kind, name: name.to_string() });
    }
    out
}

fn is_runtime(name: &str) -> bool {
    name.starts_with("compiler_builtins::") || name.starts_with("__aeabi") || name.ends_with("sf3") || name.ends_with("si2")
}

/// Measures the `no_panic` ELF at `elf` for `core`.
///
/// # Errors
/// binutils missing or their output unexpected.
pub fn measure(core: &Core, elf: &Path, evaluator: &'static str) -> anyhow::Result<SizeReport> {
    let size = binutil("size")?;
    let nm = binutil("nm")?;
    let (text, data, bss) = parse_berkeley(&output(&size, &["-B"], elf)?)?;
    let sysv = output(&size, &["-A"], elf)?;
    let tables = section_size(&sysv, ".rodata");
    let symbols = parse_nm(&output(&nm, &["-S", "-C"], elf)?);
    let code = |s: &&Symbol| matches!(s.kind, 't' | 'T' | 'W' | 'w');
    let evaluator_code = symbols.iter().filter(code).filter(|s| s.name.starts_with("needle_haptics::")).cloned().collect();
    let which = evaluator;
    let runtime = symbols.iter().filter(code).filter(|s| is_runtime(&s.name)).cloned().collect();
    let rodata_start = symbols.iter().find(|s| s.name == "__srodata").map(|s| s.addr);
    let table_symbols = symbols
        .iter()
        .filter(|s| matches!(s.kind, 'r' | 'R') && !s.name.starts_with("__") && rodata_start.is_none_or(|r| s.addr >= r))
        .cloned()
        .collect();
    Ok(SizeReport {
        core: *core,
        evaluator: which,
        elf: elf.to_path_buf(),
        text,
        data,
        bss,
        tables,
        evaluator_code,
        runtime,
        table_symbols,
    })
}

/// The evaluators, the firmware example that holds each alone and the library features
/// it is built with (`insertion`: the f32 model, its depth extension, the insertion model
/// with the guard's stiffness, every compiled-in tissue stack and a control loop rendering
/// it; `fixed-insertion` the same in integers; `+qlv`: the same image with the
/// viscoelastic filter, [`Features::Viscoelastic`]).
pub const EVALUATORS: [(&str, &str, Features); 6] = [
    ("f32", "no_panic", Features::Viscoelastic),
    ("fixed", "no_panic_fixed", Features::Viscoelastic),
    ("insertion", "no_panic_insertion", Features::Elastic),
    ("fixed-insertion", "no_panic_fixed_insertion", Features::Elastic),
    ("insertion+qlv", "no_panic_insertion", Features::Viscoelastic),
    ("fixed-insertion+qlv", "no_panic_fixed_insertion", Features::Viscoelastic),
];

/// Builds the [`EVALUATORS`]' examples for `core` with the set `set` and measures each
/// (in that order).
///
/// # Errors
/// Build failed or binutils missing.
pub fn run(core: &Core, set: &Path) -> anyhow::Result<Vec<SizeReport>> {
    let mut out = Vec::with_capacity(EVALUATORS.len());
    for features in [Features::Viscoelastic, Features::Elastic] {
        let chosen: Vec<_> = EVALUATORS.iter().filter(|(_, _, f)| *f == features).collect();
        let names: Vec<&str> = chosen.iter().map(|(_, e, _)| *e).collect();
        let elfs = build::build_examples_with(core, &names, set, features)?;
        for ((which, _, _), elf) in chosen.iter().zip(&elfs) {
            out.push(measure(core, elf, which)?);
        }
    }
    let order = |r: &SizeReport| EVALUATORS.iter().position(|(w, _, _)| *w == r.evaluator);
    out.sort_by_key(order);
    Ok(out)
}

/// `1234 B (1.21 KiB)`.
#[must_use]
pub fn bytes(n: u64) -> String {
    if n >= 1024 {
        format!("{n} B ({:.2} KiB)", n as f64 / 1024.0)
    } else {
        format!("{n} B")
    }
}

/// The reports as text: a summary table, then the symbols of each core.
#[must_use]
pub fn table(reports: &[SizeReport]) -> String {
    let mut s = format!(
        "{:<11} {:<22} {:<6} {:>8} {:>6} {:>6} | {:>9} {:>8} {:>10} | {:>20} {:>11}\n",
        "core", "target", "eval", "text", "data", "bss", "evaluator", "tables", "runtime", "model flash", "static RAM"
    );
    for r in reports {
        s.push_str(&format!(
            "{:<11} {:<22} {:<6} {:>8} {:>6} {:>6} | {:>9} {:>8} {:>10} | {:>20} {:>11}\n",
            r.core.core,
            r.core.target,
            r.evaluator,
            format!("{} B", r.text),
            format!("{} B", r.data),
            format!("{} B", r.bss),
            format!("{} B", r.evaluator_bytes()),
            format!("{} B", r.tables),
            format!("{} B", r.runtime_bytes()),
            bytes(r.model_flash()),
            format!("{} B", r.static_ram()),
        ));
    }
    for r in reports {
        s.push_str(&format!("\n{} ({}), {} evaluator, {}:\n", r.core.core, r.core.target, r.evaluator, r.elf.display()));
        for sym in r.evaluator_code.iter().chain(&r.table_symbols).chain(&r.runtime) {
            s.push_str(&format!("  {:>6} B  {}  {}\n", sym.size, sym.kind, sym.name));
        }
        s.push_str(&format!("  {:>6} B  .rodata section (tables, whole)\n", r.tables));
    }
    s
}
