//! Content filters: the SQL subset of DDS 1.4 Annex B used by content-filtered topics.
//!
//! Supported: comparisons `= <> != < <= > >=` between fields, literals (integers, floats, `'strings'`,
//! `TRUE`/`FALSE`) and parameters `%0`..`%99`; `BETWEEN a AND b`, `NOT BETWEEN`; `LIKE` with `%` and `_`;
//! `AND`, `OR`, `NOT` and parentheses. Keywords are case-insensitive. Fields are read through
//! [`FilterFields`] (dotted paths for nested members). Not supported: `MATCH`, enumerator names as bare
//! identifiers (compare them as strings instead), arithmetic.

use std::cmp::Ordering;

use super::error::DdsError;

/// A value a filter compares.
#[derive(Debug, Clone, PartialEq)]
pub enum FieldValue {
    /// Signed integer.
    Int(i64),
    /// Unsigned integer.
    UInt(u64),
    /// Floating point.
    Float(f64),
    /// String, char or enumerator name.
    Str(String),
    /// Boolean.
    Bool(bool),
}

impl FieldValue {
    fn as_f64(&self) -> Option<f64> {
        match *self {
            FieldValue::Int(i) => Some(i as f64),
            FieldValue::UInt(u) => Some(u as f64),
            FieldValue::Float(f) => Some(f),
            _ => None,
        }
    }

    fn compare(&self, other: &FieldValue) -> Option<Ordering> {
        use FieldValue::*;
        match (self, other) {
            (Int(a), Int(b)) => Some(a.cmp(b)),
            (UInt(a), UInt(b)) => Some(a.cmp(b)),
            (Int(a), UInt(b)) => Some(if *a < 0 {
                Ordering::Less
            } else {
                (*a as u64).cmp(b)
            }),
            (UInt(a), Int(b)) => Some(if *b < 0 {
                Ordering::Greater
            } else {
                a.cmp(&(*b as u64))
            }),
            (Str(a), Str(b)) => Some(a.cmp(b)),
            (Bool(a), Bool(b)) => Some(a.cmp(b)),
            _ => self.as_f64()?.partial_cmp(&other.as_f64()?),
        }
    }
}

macro_rules! from_int {
    ($variant:ident, $as:ty, $($t:ty),*) => {$(
        impl From<$t> for FieldValue {
            fn from(v: $t) -> Self { FieldValue::$variant(v as $as) }
        }
    )*};
}
from_int!(Int, i64, i8, i16, i32, i64);
from_int!(UInt, u64, u8, u16, u32, u64);
impl From<f32> for FieldValue {
    fn from(v: f32) -> Self {
        FieldValue::Float(f64::from(v))
    }
}
impl From<f64> for FieldValue {
    fn from(v: f64) -> Self {
        FieldValue::Float(v)
    }
}
impl From<bool> for FieldValue {
    fn from(v: bool) -> Self {
        FieldValue::Bool(v)
    }
}
impl From<&str> for FieldValue {
    fn from(v: &str) -> Self {
        FieldValue::Str(v.to_string())
    }
}
impl From<String> for FieldValue {
    fn from(v: String) -> Self {
        FieldValue::Str(v)
    }
}
impl From<char> for FieldValue {
    fn from(v: char) -> Self {
        FieldValue::Str(v.to_string())
    }
}

/// Gives a content filter access to a sample's members by name. Implement it by hand (or let generated code
/// do it) for types used with content-filtered topics.
pub trait FilterFields {
    /// The value of the member at `path` (`x`, `inner.y`), or `None` if there is no such member.
    fn field(&self, path: &str) -> Option<FieldValue>;
}

#[derive(Debug, Clone, PartialEq)]
enum Tok {
    Ident(String),
    Num(FieldValue),
    Str(String),
    Param(usize),
    Op(&'static str),
    LParen,
    RParen,
}

fn tokenize(s: &str) -> Result<Vec<Tok>, String> {
    let b = s.as_bytes();
    let mut i = 0;
    let mut out = Vec::new();
    while i < b.len() {
        let c = b[i];
        match c {
            b' ' | b'\t' | b'\n' | b'\r' => i += 1,
            b'(' => {
                out.push(Tok::LParen);
                i += 1
            }
            b')' => {
                out.push(Tok::RParen);
                i += 1
            }
            b'=' => {
                out.push(Tok::Op("="));
                i += 1
            }
            b'<' | b'>' | b'!' => {
                let two = b.get(i + 1).copied();
                let op = match (c, two) {
                    (b'<', Some(b'=')) => "<=",
                    (b'<', Some(b'>')) => "<>",
                    (b'>', Some(b'=')) => ">=",
                    (b'!', Some(b'=')) => "<>",
                    (b'<', _) => "<",
                    (b'>', _) => ">",
                    _ => return Err(format!("unexpected '!' at {i}")),
                };
                i += op.len().max(if c == b'!' { 2 } else { 0 });
                out.push(Tok::Op(op));
            }
            b'\'' | b'`' => {
                // 'string'; also `string' as some tools write it
                let close = b'\'';
                let start = i + 1;
                let end = b[start..]
                    .iter()
                    .position(|&x| x == close)
                    .ok_or_else(|| "unterminated string".to_string())?;
                out.push(Tok::Str(s[start..start + end].to_string()));
                i = start + end + 1;
            }
            b'%' => {
                let start = i + 1;
                let mut j = start;
                while j < b.len() && b[j].is_ascii_digit() {
                    j += 1;
                }
                let n: usize = s[start..j]
                    .parse()
                    .map_err(|_| format!("bad parameter at {i}"))?;
                if n > 99 {
                    return Err("parameter index above 99".into());
                }
                out.push(Tok::Param(n));
                i = j;
            }
            b'0'..=b'9' | b'-' | b'+' | b'.' => {
                let start = i;
                i += 1;
                while i < b.len()
                    && (b[i].is_ascii_alphanumeric()
                        || b[i] == b'.'
                        || ((b[i] == b'-' || b[i] == b'+') && (b[i - 1] | 0x20) == b'e'))
                {
                    i += 1;
                }
                out.push(Tok::Num(
                    parse_number(&s[start..i])
                        .ok_or_else(|| format!("bad number {:?}", &s[start..i]))?,
                ));
            }
            c if c.is_ascii_alphabetic() || c == b'_' => {
                let start = i;
                while i < b.len()
                    && (b[i].is_ascii_alphanumeric()
                        || b[i] == b'_'
                        || b[i] == b'.'
                        || b[i] == b'['
                        || b[i] == b']')
                {
                    i += 1;
                }
                out.push(Tok::Ident(s[start..i].to_string()));
            }
            _ => return Err(format!("unexpected character {:?} at {i}", c as char)),
        }
    }
    Ok(out)
}

fn parse_number(s: &str) -> Option<FieldValue> {
    if let Some(h) = s.strip_prefix("0x").or_else(|| s.strip_prefix("0X")) {
        return i64::from_str_radix(h, 16).ok().map(FieldValue::Int);
    }
    if let Ok(i) = s.parse::<i64>() {
        return Some(FieldValue::Int(i));
    }
    s.parse::<f64>().ok().map(FieldValue::Float)
}

/// A parameter value: a quoted string, a number, or else the raw text as a string.
fn parse_param(p: &str) -> FieldValue {
    let t = p.trim();
    if t.len() >= 2 && t.starts_with('\'') && t.ends_with('\'') {
        return FieldValue::Str(t[1..t.len() - 1].to_string());
    }
    parse_number(t).unwrap_or_else(|| FieldValue::Str(t.to_string()))
}

#[derive(Debug, Clone, PartialEq)]
enum Operand {
    Field(String),
    Lit(FieldValue),
    Param(usize),
}

#[derive(Debug, Clone, PartialEq)]
enum Expr {
    And(Box<Expr>, Box<Expr>),
    Or(Box<Expr>, Box<Expr>),
    Not(Box<Expr>),
    Cmp(Operand, &'static str, Operand),
    Between(Operand, Operand, Operand),
    Like(Operand, Operand),
}

struct Parser {
    toks: Vec<Tok>,
    pos: usize,
}

impl Parser {
    fn peek(&self) -> Option<&Tok> {
        self.toks.get(self.pos)
    }
    fn keyword(&self, kw: &str) -> bool {
        matches!(self.peek(), Some(Tok::Ident(s)) if s.eq_ignore_ascii_case(kw))
    }
    fn or(&mut self, depth: u32) -> Result<Expr, String> {
        if depth > 64 {
            return Err("expression nests too deeply".into());
        }
        let mut l = self.and(depth)?;
        while self.keyword("OR") {
            self.pos += 1;
            l = Expr::Or(Box::new(l), Box::new(self.and(depth)?));
        }
        Ok(l)
    }
    fn and(&mut self, depth: u32) -> Result<Expr, String> {
        let mut l = self.not(depth)?;
        while self.keyword("AND") {
            self.pos += 1;
            l = Expr::And(Box::new(l), Box::new(self.not(depth)?));
        }
        Ok(l)
    }
    fn not(&mut self, depth: u32) -> Result<Expr, String> {
        if self.keyword("NOT") {
            self.pos += 1;
            return Ok(Expr::Not(Box::new(self.not(depth + 1)?)));
        }
        if self.peek() == Some(&Tok::LParen) {
            self.pos += 1;
            let e = self.or(depth + 1)?;
            if self.peek() != Some(&Tok::RParen) {
                return Err("expected ')'".into());
            }
            self.pos += 1;
            return Ok(e);
        }
        let a = self.operand()?;
        if self.keyword("BETWEEN") || self.keyword("NOT") {
            let negate = self.keyword("NOT");
            self.pos += 1;
            if negate {
                if !self.keyword("BETWEEN") {
                    return Err("expected BETWEEN after NOT".into());
                }
                self.pos += 1;
            }
            let lo = self.operand()?;
            if !self.keyword("AND") {
                return Err("expected AND in BETWEEN".into());
            }
            self.pos += 1;
            let hi = self.operand()?;
            let e = Expr::Between(a, lo, hi);
            return Ok(if negate { Expr::Not(Box::new(e)) } else { e });
        }
        if self.keyword("LIKE") {
            self.pos += 1;
            return Ok(Expr::Like(a, self.operand()?));
        }
        match self.peek() {
            Some(Tok::Op(op)) => {
                let op = *op;
                self.pos += 1;
                Ok(Expr::Cmp(a, op, self.operand()?))
            }
            other => Err(format!("expected a comparison operator, found {other:?}")),
        }
    }
    fn operand(&mut self) -> Result<Operand, String> {
        let t = self.peek().cloned().ok_or("unexpected end of expression")?;
        self.pos += 1;
        Ok(match t {
            Tok::Ident(s) if s.eq_ignore_ascii_case("TRUE") => Operand::Lit(FieldValue::Bool(true)),
            Tok::Ident(s) if s.eq_ignore_ascii_case("FALSE") => {
                Operand::Lit(FieldValue::Bool(false))
            }
            Tok::Ident(s) => Operand::Field(s),
            Tok::Num(n) => Operand::Lit(n),
            Tok::Str(s) => Operand::Lit(FieldValue::Str(s)),
            Tok::Param(n) => Operand::Param(n),
            other => return Err(format!("expected an operand, found {other:?}")),
        })
    }
}

/// A parsed filter expression with its parameters.
#[derive(Debug, Clone, PartialEq)]
pub struct ContentFilter {
    expression: String,
    expr: Expr,
    params: Vec<FieldValue>,
    raw_params: Vec<String>,
}

impl ContentFilter {
    /// Parses `expression`; `%N` refers to `params[N]`.
    pub fn new(expression: &str, params: &[String]) -> Result<Self, DdsError> {
        let toks = tokenize(expression).map_err(DdsError::BadParameter)?;
        let mut p = Parser { toks, pos: 0 };
        let expr = p.or(0).map_err(DdsError::BadParameter)?;
        if p.pos != p.toks.len() {
            return Err(DdsError::BadParameter(format!(
                "unexpected trailing input in filter {expression:?}"
            )));
        }
        let f = ContentFilter {
            expression: expression.to_string(),
            expr,
            params: params.iter().map(|s| parse_param(s)).collect(),
            raw_params: params.to_vec(),
        };
        f.check_params(&f.expr)?;
        Ok(f)
    }

    fn check_params(&self, e: &Expr) -> Result<(), DdsError> {
        let ok = |o: &Operand| match o {
            Operand::Param(n) if *n >= self.params.len() => Err(DdsError::BadParameter(format!(
                "filter uses %{n} but only {} parameters were given",
                self.params.len()
            ))),
            _ => Ok(()),
        };
        match e {
            Expr::And(a, b) | Expr::Or(a, b) => {
                self.check_params(a)?;
                self.check_params(b)
            }
            Expr::Not(a) => self.check_params(a),
            Expr::Cmp(a, _, b) | Expr::Like(a, b) => {
                ok(a)?;
                ok(b)
            }
            Expr::Between(a, b, c) => {
                ok(a)?;
                ok(b)?;
                ok(c)
            }
        }
    }

    /// The expression text.
    pub fn expression(&self) -> &str {
        &self.expression
    }
    /// The parameters as given.
    pub fn parameters(&self) -> &[String] {
        &self.raw_params
    }

    /// Replaces the parameters (same count rules as [`ContentFilter::new`]).
    pub fn set_parameters(&mut self, params: &[String]) -> Result<(), DdsError> {
        let f = ContentFilter::new(&self.expression, params)?;
        *self = f;
        Ok(())
    }

    /// Evaluates the filter on a sample. A missing field or incomparable values make the comparison false.
    pub fn matches<T: FilterFields + ?Sized>(&self, sample: &T) -> bool {
        self.eval(&self.expr, sample)
    }

    fn value<T: FilterFields + ?Sized>(&self, o: &Operand, s: &T) -> Option<FieldValue> {
        match o {
            Operand::Field(f) => s.field(f),
            Operand::Lit(v) => Some(v.clone()),
            Operand::Param(n) => self.params.get(*n).cloned(),
        }
    }

    fn eval<T: FilterFields + ?Sized>(&self, e: &Expr, s: &T) -> bool {
        match e {
            Expr::And(a, b) => self.eval(a, s) && self.eval(b, s),
            Expr::Or(a, b) => self.eval(a, s) || self.eval(b, s),
            Expr::Not(a) => !self.eval(a, s),
            Expr::Cmp(a, op, b) => {
                let (Some(x), Some(y)) = (self.value(a, s), self.value(b, s)) else {
                    return false;
                };
                let Some(o) = x.compare(&y) else { return false };
                match *op {
                    "=" => o == Ordering::Equal,
                    "<>" => o != Ordering::Equal,
                    "<" => o == Ordering::Less,
                    "<=" => o != Ordering::Greater,
                    ">" => o == Ordering::Greater,
                    ">=" => o != Ordering::Less,
                    _ => false,
                }
            }
            Expr::Between(a, lo, hi) => {
                let (Some(x), Some(l), Some(h)) =
                    (self.value(a, s), self.value(lo, s), self.value(hi, s))
                else {
                    return false;
                };
                matches!(x.compare(&l), Some(Ordering::Greater | Ordering::Equal))
                    && matches!(x.compare(&h), Some(Ordering::Less | Ordering::Equal))
            }
            Expr::Like(a, p) => match (self.value(a, s), self.value(p, s)) {
                (Some(FieldValue::Str(x)), Some(FieldValue::Str(p))) => {
                    like(p.as_bytes(), x.as_bytes())
                }
                _ => false,
            },
        }
    }
}

/// SQL LIKE: `%` any run, `_` any one character. Iterative, no recursion blow-up.
fn like(p: &[u8], s: &[u8]) -> bool {
    let (mut pi, mut si) = (0, 0);
    let (mut star, mut mark) = (None, 0);
    while si < s.len() {
        if pi < p.len() && (p[pi] == b'_' || p[pi] == s[si]) {
            pi += 1;
            si += 1;
        } else if pi < p.len() && p[pi] == b'%' {
            star = Some(pi);
            mark = si;
            pi += 1;
        } else if let Some(st) = star {
            pi = st + 1;
            mark += 1;
            si = mark;
        } else {
            return false;
        }
    }
    while pi < p.len() && p[pi] == b'%' {
        pi += 1;
    }
    pi == p.len()
}

#[cfg(test)]
mod tests {
    use super::*;

    struct Shape {
        color: &'static str,
        x: i32,
        y: i32,
    }
    impl FilterFields for Shape {
        fn field(&self, path: &str) -> Option<FieldValue> {
            match path {
                "color" => Some(self.color.into()),
                "x" => Some(self.x.into()),
                "y" => Some(self.y.into()),
                _ => None,
            }
        }
    }

    fn f(e: &str, p: &[&str]) -> ContentFilter {
        ContentFilter::new(e, &p.iter().map(|s| s.to_string()).collect::<Vec<_>>()).unwrap()
    }

    #[test]
    fn evaluates_the_shape_filters() {
        let s = Shape {
            color: "RED",
            x: 50,
            y: 200,
        };
        assert!(f("x > %0 AND color = 'RED'", &["10"]).matches(&s));
        assert!(!f("x > %0 AND color = 'RED'", &["60"]).matches(&s));
        assert!(f("color = %0", &["'RED'"]).matches(&s));
        assert!(f("color = %0", &["RED"]).matches(&s));
        assert!(f("x BETWEEN 0 AND 100 and not (y < 100)", &[]).matches(&s));
        assert!(f("(x < 10 OR y >= 200) AND color <> 'BLUE'", &[]).matches(&s));
        assert!(f("color LIKE 'R%'", &[]).matches(&s));
        assert!(!f("color LIKE 'B_UE'", &[]).matches(&s));
        assert!(f("x NOT BETWEEN 60 AND 70", &[]).matches(&s));
        assert!(!f("missing = 1", &[]).matches(&s));
        assert!(f("x >= 49.5", &[]).matches(&s));
    }

    #[test]
    fn rejects_bad_filters() {
        for bad in [
            "x >",
            "x > %3",
            "(x > 1",
            "x ! 1",
            "x > 1 y",
            "'unterminated = 1",
            "",
        ] {
            assert!(
                ContentFilter::new(bad, &["1".to_string()]).is_err(),
                "{bad}"
            );
        }
        let deep = format!("{}x = 1{}", "(".repeat(200), ")".repeat(200));
        assert!(ContentFilter::new(&deep, &[]).is_err());
    }
}
