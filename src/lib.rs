//! needle-haptics: no_std needle-tissue reaction wrench models (in progress).
#![no_std]
#![forbid(unsafe_code)]
