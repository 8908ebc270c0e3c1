//! The typed error of the filter language.

/// Why an expression or a parameter was refused. Positions are byte offsets into the expression.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum FilterError {
    /// The expression is empty where a condition is required.
    #[error("empty filter expression")]
    Empty,
    /// A character that starts no token.
    #[error("unexpected character {ch:?} at {pos}")]
    UnexpectedChar {
        /// Where.
        pos: usize,
        /// The character.
        ch: char,
    },
    /// A string literal without its closing quote.
    #[error("unterminated string starting at {pos}")]
    UnterminatedString {
        /// Where the string starts.
        pos: usize,
    },
    /// A malformed or out-of-range number.
    #[error("bad number {text:?} at {pos}")]
    BadNumber {
        /// Where.
        pos: usize,
        /// The text.
        text: String,
    },
    /// `%` not followed by a parameter index 0..=99.
    #[error("bad parameter reference at {pos} (expected %0 to %99)")]
    BadParameterRef {
        /// Where.
        pos: usize,
    },
    /// A malformed member path (`a..b`, `a[x]`, `a[`).
    #[error("bad member path {text:?} at {pos}")]
    BadPath {
        /// Where.
        pos: usize,
        /// The text.
        text: String,
    },
    /// The grammar expected something else.
    #[error("expected {expected} at {pos}, found {found}")]
    Unexpected {
        /// Where.
        pos: usize,
        /// What the grammar allows there.
        expected: &'static str,
        /// What was there.
        found: String,
    },
    /// `MATCH` and other operators that DDS 1.4 Annex B does not define.
    #[error("operator {op} at {pos} is not part of the DDS SQL subset")]
    UnsupportedOperator {
        /// Where.
        pos: usize,
        /// The operator.
        op: String,
    },
    /// `ORDER BY` in a content filter (only queries sort).
    #[error("ORDER BY is allowed in query expressions only")]
    OrderByInFilter,
    /// Parentheses or `NOT` nest deeper than the parser allows.
    #[error("expression nests deeper than {limit} levels")]
    TooDeep {
        /// The limit.
        limit: usize,
    },
    /// The expression is longer than the parser accepts.
    #[error("expression longer than {limit} bytes")]
    TooLong {
        /// The limit.
        limit: usize,
    },
    /// The expression refers to `%index` but fewer parameters were given.
    #[error("expression uses %{index} but only {given} parameters were given")]
    MissingParameter {
        /// The parameter referred to.
        index: usize,
        /// How many were given.
        given: usize,
    },
    /// More than 100 parameters.
    #[error("{given} parameters given; at most 100 are allowed")]
    TooManyParameters {
        /// How many were given.
        given: usize,
    },
}
