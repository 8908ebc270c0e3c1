//! Errors of dynamic types and data.

use thiserror::Error;

/// What went wrong building a dynamic type or handling dynamic data.
#[derive(Debug, Clone, PartialEq, Eq, Error)]
#[non_exhaustive]
pub enum DynamicError {
    /// The type description is inconsistent.
    #[error("invalid type: {0}")]
    Invalid(String),
    /// A type object, or one it depends on, is not available or not supported.
    #[error("cannot resolve type: {0}")]
    Unresolved(String),
    /// No member of that name or id.
    #[error("no member {0}")]
    NoMember(String),
    /// A value does not fit its type.
    #[error("{path}: expected {expected}, found {found}")]
    Mismatch {
        /// Where in the sample (`a.b[3]`).
        path: String,
        /// What the type wants.
        expected: String,
        /// What was given.
        found: String,
    },
}

impl DynamicError {
    pub(super) fn mismatch(
        path: &str,
        expected: impl Into<String>,
        found: impl Into<String>,
    ) -> Self {
        DynamicError::Mismatch {
            path: if path.is_empty() {
                "sample".into()
            } else {
                path.to_string()
            },
            expected: expected.into(),
            found: found.into(),
        }
    }
}
