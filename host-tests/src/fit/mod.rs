//! The fitter: FE sweeps -> model.toml (filled in by the model issue).
