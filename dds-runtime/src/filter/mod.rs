//! Content filters and queries: the SQL subset of DDS 1.4 Annex B.
//!
//! - **Predicates:** `field <op> value` with `=`, `<>` (also `!=`), `<`, `<=`, `>`, `>=`;
//!   `field [NOT] BETWEEN a AND b`; `field [NOT] LIKE 'pattern'` (`%` any run, `_` one character).
//! - **Conditions:** `AND`, `OR`, `NOT` and parentheses; `AND` binds tighter than `OR`.
//! - **Operands:** member paths (`x`, `inner.y`, `points[2].x`, a union branch by name), literals (integers,
//!   also `0x1F` and signed; floats; `'strings'` and `'c'` characters, which may open with a backquote;
//!   enumerators as `'NAME'`; `TRUE`/`FALSE`) and parameters `%0`..`%99`.
//! - **Queries** (`QueryCondition`) may also end with `ORDER BY field, field...` and may have no condition.
//! - Keywords are case-insensitive. An enumerator compares with a string by name and with a number by value;
//!   integers, floats and enumerator values compare numerically; a char compares with a one-character string.
//! - A missing member, an absent optional, an inactive union branch or values of kinds that do not compare make
//!   the predicate false.
//!
//! Not supported: `MATCH` (an RTI extension, not in Annex B) and arithmetic.
//!
//! Samples are read through [`FilterFields`], which `#[derive(DdsType)]` implements. Evaluation allocates
//! nothing. This module needs no feature: the derive refers to it.
//!
//! ```
//! use dds_runtime::{filter::ContentFilter, DdsType};
//!
//! #[derive(DdsType, Clone, Copy)]
//! enum Color { Red, Green }
//! #[derive(DdsType)]
//! struct Point { x: i32, y: i32 }
//! #[derive(DdsType)]
//! struct Shape { color: Color, center: Point, size: u32 }
//!
//! let s = Shape { color: Color::Green, center: Point { x: 5, y: 7 }, size: 30 };
//! let f = ContentFilter::new("color = 'Green' AND center.x BETWEEN %0 AND 10", &["0"])?;
//! assert!(f.matches(&s));
//! # Ok::<(), dds_runtime::filter::FilterError>(())
//! ```

mod error;
mod eval;
mod lexer;
mod parser;
mod value;

use std::cmp::Ordering;

pub use error::FilterError;
pub use value::{FieldValue, FilterFields, PathSegment};

use lexer::Literal;
use parser::Parsed;

/// The most parameters an expression can be given (`%0`..`%99`).
pub const MAX_PARAMETERS: usize = 100;

/// A compiled filter or query expression with its current parameters.
#[derive(Debug, Clone, PartialEq)]
pub struct ContentFilter {
    expression: String,
    parsed: Parsed,
    params: Vec<Literal>,
    raw_params: Vec<String>,
}

impl ContentFilter {
    /// A filter expression (a condition; no ORDER BY). `%N` refers to `params[N]`; a parameter's text is read
    /// as a literal (`'RED'`, `42`, `TRUE`) or else taken as a string (`RED`).
    pub fn new<S: AsRef<str>>(expression: &str, params: &[S]) -> Result<Self, FilterError> {
        Self::build(expression, params, false)
    }

    /// A query expression: an optional condition, then optionally `ORDER BY field, ...`.
    pub fn query<S: AsRef<str>>(expression: &str, params: &[S]) -> Result<Self, FilterError> {
        Self::build(expression, params, true)
    }

    fn build<S: AsRef<str>>(
        expression: &str,
        params: &[S],
        query: bool,
    ) -> Result<Self, FilterError> {
        let mut f = ContentFilter {
            expression: expression.to_string(),
            parsed: parser::parse(expression, query)?,
            params: Vec::new(),
            raw_params: Vec::new(),
        };
        f.set_parameters(params)?;
        Ok(f)
    }

    /// The expression text.
    pub fn expression(&self) -> &str {
        &self.expression
    }

    /// The parameters as given.
    pub fn parameters(&self) -> &[String] {
        &self.raw_params
    }

    /// Replaces the parameters. Refused (and the old ones kept) when the expression uses a parameter beyond
    /// the new list, or when more than [`MAX_PARAMETERS`] are given.
    pub fn set_parameters<S: AsRef<str>>(&mut self, params: &[S]) -> Result<(), FilterError> {
        if params.len() > MAX_PARAMETERS {
            return Err(FilterError::TooManyParameters {
                given: params.len(),
            });
        }
        if self.parsed.params_needed > params.len() {
            return Err(FilterError::MissingParameter {
                index: self.parsed.params_needed - 1,
                given: params.len(),
            });
        }
        self.raw_params = params.iter().map(|p| p.as_ref().to_string()).collect();
        self.params = params
            .iter()
            .map(|p| lexer::parameter_value(p.as_ref()))
            .collect();
        Ok(())
    }

    /// Whether the sample passes (always, for a query without a condition).
    pub fn matches<T: FilterFields + ?Sized>(&self, sample: &T) -> bool {
        self.parsed
            .condition
            .as_ref()
            .is_none_or(|c| eval::eval(c, sample, &self.params))
    }

    /// Whether the expression has an ORDER BY clause.
    pub fn has_order_by(&self) -> bool {
        !self.parsed.order_by.is_empty()
    }

    /// Orders two samples by the ORDER BY fields (equal when there are none).
    pub fn compare<T: FilterFields + ?Sized>(&self, a: &T, b: &T) -> Ordering {
        eval::order(&self.parsed.order_by, a, b)
    }
}

#[cfg(test)]
mod tests;
