//! Back ends: Rust source (askama templates, formatted with prettyplease) and the JSON type model.
pub mod json;
pub mod rust;
