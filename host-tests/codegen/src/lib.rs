//! Build-time code generation for `needle-haptics` (filled in by the model issue).
#![forbid(unsafe_code)]
