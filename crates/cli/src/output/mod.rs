//! Text the commands write, shared by them: [`float_text`], an f32 laid out as `{:?}`
//! writes it (the CLI's CSV contract).
pub mod float_text;
