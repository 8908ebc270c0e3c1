//! Evaluation of a parsed expression on a sample, and the ORDER BY comparison. Nothing here allocates:
//! values borrow from the sample and from the parameters.

use std::cmp::Ordering;

use super::lexer::{Literal, RelOp};
use super::parser::{Expr, Operand};
use super::value::{FieldValue, FilterFields, PathSegment};

impl Literal {
    pub(crate) fn as_value(&self) -> FieldValue<'_> {
        match self {
            Literal::Int(i) => FieldValue::Int(*i),
            Literal::UInt(u) => FieldValue::UInt(*u),
            Literal::Float(f) => FieldValue::Float(*f),
            Literal::Bool(b) => FieldValue::Bool(*b),
            Literal::Str(s) => FieldValue::Str(s),
        }
    }
}

/// Evaluates `e` on `sample` with `params`. A missing member, an absent parameter or values that do not
/// compare make the predicate false (as SQL's unknown, which `NOT` keeps false is simplified to false).
pub(crate) fn eval<T: FilterFields + ?Sized>(e: &Expr, sample: &T, params: &[Literal]) -> bool {
    let value = |o| operand(o, sample, params);
    match e {
        Expr::And(terms) => terms.iter().all(|t| eval(t, sample, params)),
        Expr::Or(terms) => terms.iter().any(|t| eval(t, sample, params)),
        Expr::Not(inner) => !eval(inner, sample, params),
        Expr::Cmp(a, op, b) => {
            let (Some(x), Some(y)) = (value(a), value(b)) else {
                return false;
            };
            x.compare(&y).is_some_and(|o| holds(*op, o))
        }
        Expr::Between(a, lo, hi) => {
            let (Some(x), Some(l), Some(h)) = (value(a), value(lo), value(hi)) else {
                return false;
            };
            x.compare(&l).is_some_and(|o| o != Ordering::Less)
                && x.compare(&h).is_some_and(|o| o != Ordering::Greater)
        }
        Expr::Like(a, p) => {
            let (Some(x), Some(p)) = (value(a), value(p)) else {
                return false;
            };
            p.with_text(|p| x.with_text(|x| like(p.as_bytes(), x.as_bytes())))
                .flatten()
                .unwrap_or(false)
        }
    }
}

fn operand<'s, T: FilterFields + ?Sized>(
    o: &'s Operand,
    sample: &'s T,
    params: &'s [Literal],
) -> Option<FieldValue<'s>> {
    match o {
        Operand::Field(p) => sample.field_value(p),
        Operand::Lit(l) => Some(l.as_value()),
        Operand::Param(n) => params.get(*n).map(Literal::as_value),
    }
}

fn holds(op: RelOp, o: Ordering) -> bool {
    match op {
        RelOp::Eq => o == Ordering::Equal,
        RelOp::Ne => o != Ordering::Equal,
        RelOp::Lt => o == Ordering::Less,
        RelOp::Le => o != Ordering::Greater,
        RelOp::Gt => o == Ordering::Greater,
        RelOp::Ge => o != Ordering::Less,
    }
}

/// Orders two samples by the ORDER BY fields in turn; a missing or incomparable value sorts first.
pub(crate) fn order<T: FilterFields + ?Sized>(keys: &[Vec<PathSegment>], a: &T, b: &T) -> Ordering {
    for k in keys {
        let o = match (a.field_value(k), b.field_value(k)) {
            (Some(x), Some(y)) => x.compare(&y).unwrap_or(Ordering::Equal),
            (None, Some(_)) => Ordering::Less,
            (Some(_), None) => Ordering::Greater,
            (None, None) => Ordering::Equal,
        };
        if o != Ordering::Equal {
            return o;
        }
    }
    Ordering::Equal
}

/// The length of the UTF-8 character starting with byte `b`.
fn char_len(b: u8) -> usize {
    match b {
        0xF0..=0xFF => 4,
        0xE0..=0xEF => 3,
        0xC0..=0xDF => 2,
        _ => 1,
    }
}

/// SQL `LIKE`: `%` matches any run of characters, `_` exactly one. Greedy with one backtrack point, so linear
/// in practice and never recursive.
pub(crate) fn like(p: &[u8], s: &[u8]) -> bool {
    let (mut pi, mut si) = (0, 0);
    let mut star: Option<(usize, usize)> = None;
    while si < s.len() {
        if pi < p.len() && p[pi] == b'%' {
            star = Some((pi + 1, si));
            pi += 1;
        } else if pi < p.len() && p[pi] == b'_' {
            pi += 1;
            si += char_len(s[si]).min(s.len() - si);
        } else if pi < p.len() && p[pi] == s[si] {
            pi += 1;
            si += 1;
        } else if let Some((sp, ss)) = star {
            let next = ss + char_len(s[ss]).min(s.len() - ss);
            star = Some((sp, next));
            pi = sp;
            si = next;
        } else {
            return false;
        }
    }
    p[pi..].iter().all(|&c| c == b'%')
}
