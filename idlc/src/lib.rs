//! IDL 4.2 compiler: preprocess → parse → resolve → validate → emit.
//!
//! Each stage is its own module and reports into one [`diag::Diagnostics`] sink, so a run shows every error.
pub mod ast;
pub mod builder;
pub mod diag;
pub mod driver;
pub mod emit;
pub mod model;
pub mod parse;
pub mod preprocess;
pub mod resolve;
pub mod source;
pub mod validate;

pub use builder::{Builder, Error};
