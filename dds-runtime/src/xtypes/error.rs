//! Why a type has no type information.

use thiserror::Error;

/// Why a type has no type information.
#[derive(Debug, Clone, PartialEq, Eq, Error)]
#[non_exhaustive]
pub enum BuildError {
    /// A topic type must be a named struct or union.
    #[error("a topic type must be a named struct or union")]
    NotNamed,
    /// The type uses something XTypes 1.3 cannot describe.
    #[error("{0}")]
    Unsupported(&'static str),
    /// A type reaches itself outside a strongly connected component (recursive types are built as components;
    /// this is not expected).
    #[error("recursive type {0} outside a strongly connected component")]
    Recursive(String),
    /// Two different types of one name reached from a topic type (type objects name each type once).
    #[error("two different types are named {0}")]
    Conflict(String),
    /// Encoding a type object failed (a name with a NUL, ...).
    #[error("encoding a type object: {0}")]
    Encode(#[from] crate::cdr::EncodeError),
}
