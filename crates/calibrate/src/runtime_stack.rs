//! A tissue stack loaded at run time on the host (issue 65): the file checked by the one
//! reader of the format ([`needle_codegen::tissue::parse_stack`], the build's own checks and
//! messages, `FILE:LINE`), converted to the library's layers as the build compiles them
//! ([`crate::to_layer`]) and accepted by the library's insertion
//! ([`Insertion::new`](needle_haptics::insertion::Insertion::new)). The library is
//! unchanged: its [`Stack`] borrows the layers this type owns. The firmware keeps its
//! stacks compiled in.
use anyhow::{bail, Result};
use needle_haptics::insertion::{self, Insertion, InsertionConfig, Layer, Stack};
use std::path::Path;

/// A stack with its layers owned.
#[derive(Debug, Clone, PartialEq)]
pub struct OwnedStack {
    /// The stack's name.
    pub name: String,
    /// Its needle's diameter, mm.
    pub needle_diameter_mm: f32,
    /// Its layers, from the surface down.
    pub layers: Vec<Layer>,
}

impl OwnedStack {
    /// The stack of the tissue file `path`.
    ///
    /// # Errors
    /// The format's refusal (`FILE:LINE: ...`, as the build says it), or the library's.
    pub fn load(path: &Path) -> Result<Self> {
        let file = needle_codegen::tissue::parse_stack(path)?;
        Self::from_file(&file).map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))
    }

    /// The stack of a tissue file's values already read (a stack drawn within a
    /// spread, `crate::sample`), converted as the build compiles them.
    ///
    /// # Errors
    /// The library's refusal ([`Insertion::new`]).
    pub fn from_file(file: &needle_codegen::tissue::Stack) -> Result<Self> {
        let out = Self {
            name: file.name.clone(),
            needle_diameter_mm: file.needle_diameter_mm as f32,
            layers: file.layers.iter().map(crate::to_layer).collect(),
        };
        if let Err(e) = Insertion::new(&out.as_stack(), InsertionConfig::DEFAULT_1KHZ) {
            bail!("{e}");
        }
        Ok(out)
    }

    /// The compiled-in stack `name`, owned.
    #[must_use]
    pub fn compiled(name: &str) -> Option<Self> {
        insertion::stacks::by_name(name).map(|s| Self {
            name: s.name.to_string(),
            needle_diameter_mm: s.needle_diameter_mm,
            layers: s.layers.to_vec(),
        })
    }

    /// `what` as `option` gave it: a tissue file (a path that exists, or one ending in
    /// `.toml`) or the name of a compiled-in stack.
    ///
    /// # Errors
    /// As [`OwnedStack::load`]; no compiled-in stack of that name (they are listed).
    pub fn resolve(option: &str, what: &str) -> Result<Self> {
        let path = Path::new(what);
        if path.exists() || what.ends_with(".toml") {
            return Self::load(path);
        }
        Self::compiled(what).ok_or_else(|| {
            let names: Vec<&str> = insertion::stacks::ALL.iter().map(|s| s.name).collect();
            anyhow::anyhow!("{option} {what:?}: no such tissue file, nor a stack of the compiled-in set (it has: {})", names.join(", "))
        })
    }

    /// The library's view of it.
    #[must_use]
    pub fn as_stack(&self) -> Stack<'_> {
        Stack { name: &self.name, needle_diameter_mm: self.needle_diameter_mm, layers: &self.layers }
    }
}
