//! `--emit json`: the resolved type model, for tooling and debugging.
use crate::model::Model;

/// The model as pretty-printed JSON.
pub fn emit(model: &Model) -> String {
    // The model holds only plain data: serialisation cannot fail.
    serde_json::to_string_pretty(model).unwrap_or_else(|e| format!("{{\"error\": \"{e}\"}}"))
}
