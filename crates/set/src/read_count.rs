//! How many campaign specs and manifests this process has read ([`spec::load`],
//! [`read_manifest`]), so that a test can hold a command to one read of each
//! ([`crate::set_folder::SetFolder`] opens a set once).
//!
//! [`spec::load`]: crate::spec::load
//! [`read_manifest`]: crate::manifest::read_manifest

use std::sync::atomic::{AtomicUsize, Ordering};

static SPECS: AtomicUsize = AtomicUsize::new(0);
static MANIFESTS: AtomicUsize = AtomicUsize::new(0);

/// Campaign specs and manifests read by this process so far.
pub fn spec_and_manifest_reads() -> usize {
    spec_reads() + MANIFESTS.load(Ordering::Relaxed)
}

/// Campaign specs read by this process so far. The FE commands read one set's spec once
/// (the campaign's manifests are read again where the campaign writes them: another
/// process may have written them since, see docs/architecture.md).
pub fn spec_reads() -> usize {
    SPECS.load(Ordering::Relaxed)
}

/// Counts one read of a spec.
pub(crate) fn count_spec_read() {
    SPECS.fetch_add(1, Ordering::Relaxed);
}

/// Counts one read of a manifest.
pub(crate) fn count_manifest_read() {
    MANIFESTS.fetch_add(1, Ordering::Relaxed);
}
