//! `#if` expressions: integer arithmetic on i64 with C's operators. `defined` is handled before this runs;
//! identifiers that remain are 0, as in C.
use super::lex::{Kind, Tok};

pub(crate) fn eval(toks: &[Tok]) -> Result<i64, String> {
    let toks: Vec<&Tok> = toks.iter().filter(|t| t.kind != Kind::Ws).collect();
    let mut p = Parser {
        toks,
        pos: 0,
        depth: 0,
    };
    let v = p.ternary()?;
    match p.toks.get(p.pos) {
        None => Ok(v),
        Some(t) => Err(format!("unexpected `{}` in #if expression", t.text)),
    }
}

struct Parser<'a> {
    toks: Vec<&'a Tok>,
    pos: usize,
    depth: usize,
}

const BINARY: &[&[&str]] = &[
    &["||"],
    &["&&"],
    &["|"],
    &["^"],
    &["&"],
    &["==", "!="],
    &["<", ">", "<=", ">="],
    &["<<", ">>"],
    &["+", "-"],
    &["*", "/", "%"],
];

impl Parser<'_> {
    fn peek(&self) -> Option<&str> {
        self.toks.get(self.pos).map(|t| t.text.as_str())
    }
    fn eat(&mut self, s: &str) -> bool {
        if self.peek() == Some(s) {
            self.pos += 1;
            true
        } else {
            false
        }
    }
    fn ternary(&mut self) -> Result<i64, String> {
        let c = self.binary(0)?;
        if self.eat("?") {
            let a = self.ternary()?;
            if !self.eat(":") {
                return Err("expected `:` in conditional expression".into());
            }
            let b = self.ternary()?;
            return Ok(if c != 0 { a } else { b });
        }
        Ok(c)
    }
    fn binary(&mut self, level: usize) -> Result<i64, String> {
        if level == BINARY.len() {
            return self.unary();
        }
        let mut l = self.binary(level + 1)?;
        while let Some(op) = self
            .peek()
            .filter(|p| BINARY[level].contains(p))
            .map(str::to_owned)
        {
            self.pos += 1;
            let r = self.binary(level + 1)?;
            l = match op.as_str() {
                "||" => ((l != 0) || (r != 0)) as i64,
                "&&" => ((l != 0) && (r != 0)) as i64,
                "|" => l | r,
                "^" => l ^ r,
                "&" => l & r,
                "==" => (l == r) as i64,
                "!=" => (l != r) as i64,
                "<" => (l < r) as i64,
                ">" => (l > r) as i64,
                "<=" => (l <= r) as i64,
                ">=" => (l >= r) as i64,
                "<<" => l.checked_shl(r as u32).ok_or("shift count out of range")?,
                ">>" => l.checked_shr(r as u32).ok_or("shift count out of range")?,
                "+" => l.wrapping_add(r),
                "-" => l.wrapping_sub(r),
                "*" => l.wrapping_mul(r),
                "/" => l.checked_div(r).ok_or("division by zero in #if")?,
                _ => l.checked_rem(r).ok_or("division by zero in #if")?,
            };
        }
        Ok(l)
    }
    fn unary(&mut self) -> Result<i64, String> {
        self.depth += 1;
        if self.depth > 200 {
            return Err("#if expression nested too deeply".into());
        }
        let r = if self.eat("!") {
            self.unary().map(|v| (v == 0) as i64)
        } else if self.eat("~") {
            self.unary().map(|v| !v)
        } else if self.eat("-") {
            self.unary().map(|v| v.wrapping_neg())
        } else if self.eat("+") {
            self.unary()
        } else if self.eat("(") {
            let v = self.ternary()?;
            if !self.eat(")") {
                return Err("expected `)` in #if expression".into());
            }
            Ok(v)
        } else {
            match self.toks.get(self.pos) {
                None => Err("#if expression ends too early".into()),
                Some(t) => {
                    self.pos += 1;
                    match t.kind {
                        Kind::Number => parse_int(&t.text),
                        Kind::Char => parse_char(&t.text),
                        Kind::Ident => Ok(if t.text == "true" { 1 } else { 0 }),
                        _ => Err(format!("unexpected `{}` in #if expression", t.text)),
                    }
                }
            }
        };
        self.depth -= 1;
        r
    }
}

fn parse_int(s: &str) -> Result<i64, String> {
    let t = s.trim_end_matches(['u', 'U', 'l', 'L']);
    let r = if let Some(h) = t.strip_prefix("0x").or_else(|| t.strip_prefix("0X")) {
        u64::from_str_radix(h, 16)
    } else if t.len() > 1 && t.starts_with('0') {
        u64::from_str_radix(&t[1..], 8)
    } else {
        t.parse::<u64>()
    };
    r.map(|v| v as i64)
        .map_err(|_| format!("invalid integer `{s}` in #if expression"))
}

fn parse_char(s: &str) -> Result<i64, String> {
    let inner = &s[1..s.len() - 1];
    let mut chars = inner.chars();
    match (chars.next(), chars.next()) {
        (Some('\\'), Some(c)) => Ok(match c {
            'n' => 10,
            't' => 9,
            'r' => 13,
            '0' => 0,
            c => c as i64,
        }),
        (Some(c), _) => Ok(c as i64),
        _ => Err("empty character constant".into()),
    }
}
