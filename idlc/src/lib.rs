//! IDL 4.2 compiler: preprocess → parse → resolve → validate → emit.
//!
//! Each stage is its own module and reports into one [`diag::Diagnostics`] sink, so a run shows every error.
pub mod ast;
pub mod diag;
pub mod parse;
pub mod preprocess;
pub mod source;
pub mod model;
pub mod resolve;
pub mod validate;
pub mod emit;
pub mod driver;
pub mod builder;

pub use builder::{Builder, Error};
