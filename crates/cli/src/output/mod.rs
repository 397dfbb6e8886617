//! Text the commands write, shared by them: [`float_text`], an f32 laid out as `{:?}`
//! writes it (the CLI's CSV contract); [`terminal`], where the library crates' text goes.
pub mod float_text;
pub mod terminal;
