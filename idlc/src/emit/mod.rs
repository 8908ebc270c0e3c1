//! Back ends: Rust source (written directly, laid out as rustfmt would) and the JSON type model.
pub mod json;
pub mod rust;
