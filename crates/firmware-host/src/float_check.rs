//! Is a firmware function integer-only? From `objdump -d -C` of the ELF: the calls the
//! function makes (to soft-float helpers such as `__aeabi_fadd`, `__aeabi_fmul`,
//! `__aeabi_f2iz`) and its FPU instructions (`v...` mnemonics: `vmul.f32`, `vldr`).
use super::size::binutil;
use anyhow::{bail, Context};
use std::path::Path;
use std::process::Command;

/// Whether `name` is a floating-point runtime function (ARM EABI or libgcc names, or
/// Rust's `compiler_builtins::float`).
#[must_use]
pub fn is_float_helper(name: &str) -> bool {
    let aeabi_float = name.starts_with("__aeabi_f")
        || name.starts_with("__aeabi_d")
        || (name.starts_with("__aeabi_") && (name.ends_with("2f") || name.ends_with("2d")));
    let libgcc = ["sf3", "df3", "sf2", "df2"].iter().any(|s| name.ends_with(s)) && name.starts_with("__")
        || name.starts_with("__float")
        || name.starts_with("__fix");
    aeabi_float || libgcc || name.contains("compiler_builtins::float")
}

/// What one function of an ELF does with floating point.
#[derive(Debug, Clone, Default)]
pub struct FloatUse {
    /// The function's name as objdump printed it.
    pub function: String,
    /// Instructions in its body.
    pub instructions: usize,
    /// Every function it calls (`bl`/`blx` targets), once each.
    pub calls: Vec<String>,
    /// Those that are floating-point helpers.
    pub float_calls: Vec<String>,
    /// Its FPU instructions (mnemonics starting with `v`), as printed.
    pub fpu_instructions: Vec<String>,
}

/// Analyses the body of the first function whose demangled name starts with
/// `name_prefix` in the disassembly `text` (`objdump -d -C --no-show-raw-insn`).
///
/// # Errors
/// No such function.
pub fn analyse(text: &str, name_prefix: &str) -> anyhow::Result<FloatUse> {
    let mut lines = text.lines();
    let header = lines
        .by_ref()
        .find(|l| l.split_once(" <").is_some_and(|(_, n)| n.starts_with(name_prefix) && l.ends_with(">:")))
        .with_context(|| format!("no function {name_prefix}... in the disassembly"))?;
    let mut use_ = FloatUse { function: header.to_string(), ..FloatUse::default() };
    for line in lines.take_while(|l| !l.trim().is_empty()) {
        // "  800012a:\tbl\t8000400 <__aeabi_fmul>" (fields split by tabs)
        let mut fields = line.split('\t').skip(1);
        let Some(mnemonic) = fields.next().map(str::trim) else { continue };
        use_.instructions += 1;
        if mnemonic.starts_with('v') {
            use_.fpu_instructions.push(line.trim().to_string());
        }
        if mnemonic == "bl" || mnemonic == "blx" {
            if let Some(target) = line.rsplit_once('<').and_then(|(_, t)| t.strip_suffix('>')) {
                let target = target.split('+').next().unwrap_or(target).to_string();
                if !use_.calls.contains(&target) {
                    if is_float_helper(&target) {
                        use_.float_calls.push(target.clone());
                    }
                    use_.calls.push(target);
                }
            }
        }
    }
    Ok(use_)
}

/// Disassembles `elf` and analyses its function `name_prefix`.
///
/// # Errors
/// objdump missing or failing; no such function.
pub fn analyse_elf(elf: &Path, name_prefix: &str) -> anyhow::Result<FloatUse> {
    let objdump = binutil("objdump")?;
    let out = Command::new(&objdump)
        .args(["-d", "-C", "--no-show-raw-insn"])
        .arg(elf)
        .output()
        .with_context(|| format!("cannot run {}", objdump.display()))?;
    if !out.status.success() {
        bail!("{} -d {}: {}", objdump.display(), elf.display(), String::from_utf8_lossy(&out.stderr));
    }
    analyse(&String::from_utf8_lossy(&out.stdout), name_prefix)
}
