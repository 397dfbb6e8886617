//! Which [`Backend`] solves a run: the one place that knows every engine.

use crate::backend::Backend;
use crate::ccx::CcxBackend;
use crate::febio::FebioBackend;
use crate::spec::Engine;

/// The backend of `engine`, its jobs each on `threads` solver threads (ccx always runs
/// on one: its SPOOLES factorisation is serial in Debian's build).
pub fn backend_for(engine: Engine, threads: usize) -> Box<dyn Backend> {
    match engine {
        Engine::Ccx => Box::new(CcxBackend::default()),
        Engine::Febio => Box::new(FebioBackend::new(threads)),
    }
}
