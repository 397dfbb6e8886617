//! The `needle` command line: [`commands`] has one module per command, named as the
//! command (`needle calibrate-published` is [`commands::calibrate_published`]); the
//! helpers several commands share are [`compiled_set`], [`output`] and [`planned_outputs`].
#![forbid(unsafe_code)]

pub mod commands;
pub mod compiled_set;
pub mod output;
pub mod planned_outputs;
