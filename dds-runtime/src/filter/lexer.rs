//! Tokens of the DDS 1.4 Annex B language: keywords (case-insensitive), member paths, literals (integers
//! with an optional sign or in hex, floats, `'strings'` that may also open with a backquote, `TRUE`/`FALSE`),
//! parameters `%0`..`%99`, relational operators and parentheses.

use super::error::FilterError;
use super::value::PathSegment;

/// A literal value of the expression or of a parameter.
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum Literal {
    Int(i64),
    UInt(u64),
    Float(f64),
    Bool(bool),
    Str(Box<str>),
}

/// A relational operator.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum RelOp {
    Eq,
    Ne,
    Lt,
    Le,
    Gt,
    Ge,
}

#[derive(Debug, Clone, PartialEq)]
pub(crate) enum Tok {
    /// A member path (or a keyword, recognised by the parser).
    Path(Vec<PathSegment>, Box<str>),
    Lit(Literal),
    Param(usize),
    Op(RelOp),
    LParen,
    RParen,
    Comma,
}

impl Tok {
    /// Whether this is the keyword `kw` (given in upper case).
    pub(crate) fn is_keyword(&self, kw: &str) -> bool {
        matches!(self, Tok::Path(_, text) if text.eq_ignore_ascii_case(kw))
    }

    /// A short description for error messages.
    pub(crate) fn describe(&self) -> String {
        match self {
            Tok::Path(_, t) => format!("{t:?}"),
            Tok::Lit(l) => format!("literal {l:?}"),
            Tok::Param(n) => format!("%{n}"),
            Tok::Op(o) => format!("operator {o:?}"),
            Tok::LParen => "'('".into(),
            Tok::RParen => "')'".into(),
            Tok::Comma => "','".into(),
        }
    }
}

/// Splits `s` into `(byte offset, token)` pairs.
pub(crate) fn tokenize(s: &str) -> Result<Vec<(usize, Tok)>, FilterError> {
    let b = s.as_bytes();
    let mut out = Vec::new();
    let mut i = 0;
    while i < b.len() {
        let c = b[i];
        let start = i;
        let tok = match c {
            b' ' | b'\t' | b'\n' | b'\r' => {
                i += 1;
                continue;
            }
            b'(' | b')' | b',' | b'=' => {
                i += 1;
                match c {
                    b'(' => Tok::LParen,
                    b')' => Tok::RParen,
                    b',' => Tok::Comma,
                    _ => Tok::Op(RelOp::Eq),
                }
            }
            b'<' | b'>' | b'!' => {
                let (op, len) = match (c, b.get(i + 1)) {
                    (b'<', Some(b'=')) => (RelOp::Le, 2),
                    (b'<', Some(b'>')) | (b'!', Some(b'=')) => (RelOp::Ne, 2),
                    (b'>', Some(b'=')) => (RelOp::Ge, 2),
                    (b'<', _) => (RelOp::Lt, 1),
                    (b'>', _) => (RelOp::Gt, 1),
                    _ => return Err(FilterError::UnexpectedChar { pos: i, ch: '!' }),
                };
                i += len;
                Tok::Op(op)
            }
            b'\'' | b'`' => {
                let body = i + 1;
                let len = b[body..]
                    .iter()
                    .position(|&x| x == b'\'')
                    .ok_or(FilterError::UnterminatedString { pos: i })?;
                i = body + len + 1;
                Tok::Lit(Literal::Str(s[body..body + len].into()))
            }
            b'%' => {
                let digits = b[i + 1..].iter().take_while(|d| d.is_ascii_digit()).count();
                let n = s[i + 1..i + 1 + digits]
                    .parse::<usize>()
                    .ok()
                    .filter(|&n| n <= 99 && digits <= 2)
                    .ok_or(FilterError::BadParameterRef { pos: i })?;
                i += 1 + digits;
                Tok::Param(n)
            }
            b'0'..=b'9' | b'-' | b'+' => {
                i = number_end(b, i);
                let text = &s[start..i];
                Tok::Lit(parse_number(text).ok_or_else(|| FilterError::BadNumber {
                    pos: start,
                    text: text.into(),
                })?)
            }
            c if c.is_ascii_alphabetic() || c == b'_' => {
                while i < b.len() && is_path_byte(b[i]) {
                    i += 1;
                }
                let text = &s[start..i];
                match text.to_ascii_uppercase().as_str() {
                    "TRUE" => Tok::Lit(Literal::Bool(true)),
                    "FALSE" => Tok::Lit(Literal::Bool(false)),
                    _ => Tok::Path(path(text, start)?, text.into()),
                }
            }
            _ => {
                let ch = s[i..].chars().next().unwrap_or('?');
                return Err(FilterError::UnexpectedChar { pos: i, ch });
            }
        };
        out.push((start, tok));
    }
    Ok(out)
}

fn is_path_byte(c: u8) -> bool {
    c.is_ascii_alphanumeric() || matches!(c, b'_' | b'.' | b'[' | b']')
}

/// The end of the number starting at `i`: sign, digits, `.`, exponent with its sign, hex digits.
fn number_end(b: &[u8], mut i: usize) -> usize {
    i += 1;
    while i < b.len()
        && (b[i].is_ascii_alphanumeric()
            || b[i] == b'.'
            || (matches!(b[i], b'-' | b'+') && matches!(b[i - 1], b'e' | b'E')))
    {
        i += 1;
    }
    i
}

/// An integer (decimal or `0x` hex, with an optional sign) or a float.
pub(crate) fn parse_number(text: &str) -> Option<Literal> {
    let (neg, digits) = match text.as_bytes().first()? {
        b'-' => (true, &text[1..]),
        b'+' => (false, &text[1..]),
        _ => (false, text),
    };
    let hex = digits
        .strip_prefix("0x")
        .or_else(|| digits.strip_prefix("0X"));
    let unsigned = match hex {
        Some(h) if !h.is_empty() => u64::from_str_radix(h, 16).ok(),
        Some(_) => return None,
        None if digits.bytes().all(|d| d.is_ascii_digit()) && !digits.is_empty() => {
            digits.parse::<u64>().ok()
        }
        None => {
            let valid = digits.bytes().next().is_some_and(|d| d.is_ascii_digit())
                && !digits
                    .bytes()
                    .any(|d| d.is_ascii_alphabetic() && d != b'e' && d != b'E');
            return valid.then(|| text.parse::<f64>().ok().map(Literal::Float))?;
        }
    }?;
    Some(match (neg, i64::try_from(unsigned)) {
        (false, Ok(v)) => Literal::Int(v),
        (false, Err(_)) => Literal::UInt(unsigned),
        (true, _) => Literal::Int(0i64.checked_sub_unsigned(unsigned)?),
    })
}

/// `a.b[2].c` as segments; `pos` is where the text starts, for errors.
pub(crate) fn path(text: &str, pos: usize) -> Result<Vec<PathSegment>, FilterError> {
    let bad = || FilterError::BadPath {
        pos,
        text: text.into(),
    };
    let mut segs = Vec::new();
    for part in text.split('.') {
        let (name, mut rest) = part.split_at(part.find('[').unwrap_or(part.len()));
        let ident_ok = name
            .bytes()
            .next()
            .is_some_and(|c| c.is_ascii_alphabetic() || c == b'_')
            && name.bytes().all(|c| c.is_ascii_alphanumeric() || c == b'_');
        if !ident_ok {
            return Err(bad());
        }
        segs.push(PathSegment::Member(name.into()));
        while !rest.is_empty() {
            let inner = rest.strip_prefix('[').ok_or_else(bad)?;
            let close = inner.find(']').ok_or_else(bad)?;
            let index = inner[..close].parse::<usize>().map_err(|_| bad())?;
            segs.push(PathSegment::Index(index));
            rest = &inner[close + 1..];
        }
    }
    Ok(segs)
}

/// A parameter's text as a value: a literal token if it is one (`'RED'`, `42`, `TRUE`), else the text itself
/// as a string (`RED`, an enumerator name).
pub(crate) fn parameter_value(text: &str) -> Literal {
    let t = text.trim();
    match tokenize(t).as_deref() {
        Ok([(_, Tok::Lit(l))]) => l.clone(),
        _ => Literal::Str(t.into()),
    }
}
