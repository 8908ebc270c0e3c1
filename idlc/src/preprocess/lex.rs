//! Preprocessing tokens: just enough lexing to find identifiers, literals and punctuation.

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Kind {
    Ident,
    Number,
    Str,
    Char,
    Punct,
    Ws,
}

#[derive(Clone, Debug, PartialEq, Eq)]
pub(crate) struct Tok {
    pub kind: Kind,
    pub text: String,
}

impl Tok {
    pub(crate) fn new(kind: Kind, text: impl Into<String>) -> Self {
        Tok {
            kind,
            text: text.into(),
        }
    }
    pub(crate) fn is(&self, s: &str) -> bool {
        self.kind != Kind::Ws && self.text == s
    }
}

pub(crate) fn is_ident_start(b: u8) -> bool {
    b.is_ascii_alphabetic() || b == b'_'
}
pub(crate) fn is_ident_char(b: u8) -> bool {
    b.is_ascii_alphanumeric() || b == b'_'
}

/// Length of the literal starting with the quote at `s[0]`; `None` when it does not end on this line.
pub(crate) fn literal_len(s: &[u8]) -> Option<usize> {
    let q = s[0];
    let mut i = 1;
    while i < s.len() {
        match s[i] {
            b'\\' => i += 2,
            b'\n' => return None,
            c if c == q => return Some(i + 1),
            _ => i += 1,
        }
    }
    None
}

/// Length of a pp-number starting at `s[0]` (a digit, or '.' followed by a digit).
pub(crate) fn number_len(s: &[u8]) -> usize {
    let mut i = 1;
    while i < s.len() {
        let c = s[i];
        let exponent_sign = (c == b'+' || c == b'-')
            && matches!(s[i - 1], b'e' | b'E')
            && !s[..i].starts_with(b"0x");
        if exponent_sign || is_ident_char(c) || c == b'.' {
            i += 1;
        } else {
            break;
        }
    }
    i
}

/// Splits text (comments already removed) into tokens. Unterminated literals become punctuation.
pub(crate) fn lex(text: &str) -> Vec<Tok> {
    let b = text.as_bytes();
    let mut out = Vec::new();
    let mut i = 0;
    while i < b.len() {
        let c = b[i];
        let (kind, len) = if c.is_ascii_whitespace() {
            let mut j = i;
            while j < b.len() && b[j].is_ascii_whitespace() {
                j += 1;
            }
            (Kind::Ws, j - i)
        } else if is_ident_start(c) {
            let mut j = i + 1;
            while j < b.len() && is_ident_char(b[j]) {
                j += 1;
            }
            (Kind::Ident, j - i)
        } else if c.is_ascii_digit()
            || (c == b'.' && b.get(i + 1).is_some_and(|d| d.is_ascii_digit()))
        {
            (Kind::Number, number_len(&b[i..]))
        } else if c == b'"' || c == b'\'' {
            match literal_len(&b[i..]) {
                Some(n) => (if c == b'"' { Kind::Str } else { Kind::Char }, n),
                None => (Kind::Punct, 1),
            }
        } else {
            let two = &b[i..(i + 2).min(b.len())];
            let n = if matches!(
                two,
                b"##" | b"&&" | b"||" | b"==" | b"!=" | b"<=" | b">=" | b"<<" | b">>"
            ) {
                2
            } else {
                1
            };
            // keep UTF-8 sequences whole
            let mut n = n;
            while i + n < b.len() && !text.is_char_boundary(i + n) {
                n += 1;
            }
            (Kind::Punct, n)
        };
        out.push(Tok::new(kind, &text[i..i + len]));
        i += len;
    }
    out
}

/// Removes comments from one logical directive line (a `/*` that does not close ends the line).
pub(crate) fn strip_comments(s: &str) -> String {
    let b = s.as_bytes();
    let mut out = String::with_capacity(s.len());
    let mut i = 0;
    let mut from = 0;
    while i < b.len() {
        match b[i] {
            b'"' | b'\'' => i += literal_len(&b[i..]).unwrap_or(b.len() - i),
            b'/' if b.get(i + 1) == Some(&b'/') => {
                out.push_str(&s[from..i]);
                return out;
            }
            b'/' if b.get(i + 1) == Some(&b'*') => {
                out.push_str(&s[from..i]);
                out.push(' ');
                match s[i + 2..].find("*/") {
                    Some(p) => {
                        i = i + 2 + p + 2;
                        from = i;
                    }
                    None => return out,
                }
            }
            _ => i += 1,
        }
    }
    out.push_str(&s[from..]);
    out
}
