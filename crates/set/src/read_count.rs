//! How many campaign specs and manifests this process has read ([`spec::load`],
//! [`read_manifest`]), so that a test can hold a command to one read of each
//! ([`crate::set_folder::SetFolder`] opens a set once).
//!
//! [`spec::load`]: crate::spec::load
//! [`read_manifest`]: crate::manifest::read_manifest

use std::sync::atomic::{AtomicUsize, Ordering};

static READS: AtomicUsize = AtomicUsize::new(0);

/// Campaign specs and manifests read by this process so far.
pub fn spec_and_manifest_reads() -> usize {
    READS.load(Ordering::Relaxed)
}

/// Counts one read.
pub(crate) fn count_read() {
    READS.fetch_add(1, Ordering::Relaxed);
}
