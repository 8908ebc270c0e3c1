//! The grammar of DDS 1.4 Annex B, by recursive descent over the tokens of [`super::lexer`]:
//!
//! ```text
//! FilterExpression ::= Condition
//! QueryExpression  ::= [Condition] ['ORDER BY' FIELDNAME {',' FIELDNAME}]
//! Condition        ::= Condition 'OR' Condition | Condition 'AND' Condition | 'NOT' Condition
//!                    | '(' Condition ')' | Predicate
//! Predicate        ::= Operand RelOp Operand | Operand ['NOT'] 'BETWEEN' Operand 'AND' Operand
//!                    | Operand ['NOT'] 'LIKE' Operand
//! Operand          ::= FIELDNAME | literal | PARAMETER
//! ```
//!
//! `AND` binds tighter than `OR`. The spec requires a field on one side of a predicate; this parser also takes
//! two constants. `AND`/`OR` chains are flat lists, so evaluation depth is bounded by the nesting limit.

use super::error::FilterError;
use super::lexer::{Literal, RelOp, Tok};
use super::value::PathSegment;

/// Deepest nesting of parentheses and `NOT`.
pub(crate) const MAX_DEPTH: usize = 64;
/// Longest expression accepted.
pub(crate) const MAX_LEN: usize = 64 * 1024;

#[derive(Debug, Clone, PartialEq)]
pub(crate) enum Operand {
    Field(Vec<PathSegment>),
    Lit(Literal),
    Param(usize),
}

#[derive(Debug, Clone, PartialEq)]
pub(crate) enum Expr {
    And(Vec<Expr>),
    Or(Vec<Expr>),
    Not(Box<Expr>),
    Cmp(Operand, RelOp, Operand),
    Between(Operand, Operand, Operand),
    Like(Operand, Operand),
}

/// A parsed expression: its condition (none: every sample), its sort keys and the parameters it uses.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Parsed {
    pub(crate) condition: Option<Expr>,
    pub(crate) order_by: Vec<Vec<PathSegment>>,
    /// One more than the highest `%n` used.
    pub(crate) params_needed: usize,
}

/// Parses a filter (`query == false`: a condition is required and ORDER BY refused) or a query.
pub(crate) fn parse(text: &str, query: bool) -> Result<Parsed, FilterError> {
    if text.len() > MAX_LEN {
        return Err(FilterError::TooLong { limit: MAX_LEN });
    }
    let toks = super::lexer::tokenize(text)?;
    let mut p = Parser {
        toks,
        pos: 0,
        end: text.len(),
        depth: 0,
        params_needed: 0,
    };
    let condition = if p.at_end() || p.peek_keyword("ORDER") {
        if !query {
            return Err(FilterError::Empty);
        }
        None
    } else {
        Some(p.or()?)
    };
    let mut order_by = Vec::new();
    if p.peek_keyword("ORDER") {
        if !query {
            return Err(FilterError::OrderByInFilter);
        }
        p.pos += 1;
        p.expect_keyword("BY")?;
        loop {
            order_by.push(p.field("a field name after ORDER BY")?);
            if p.peek() != Some(&Tok::Comma) {
                break;
            }
            p.pos += 1;
        }
    }
    if !p.at_end() {
        return Err(p.unexpected("AND, OR or the end of the expression"));
    }
    Ok(Parsed {
        condition,
        order_by,
        params_needed: p.params_needed,
    })
}

struct Parser {
    toks: Vec<(usize, Tok)>,
    pos: usize,
    end: usize,
    depth: usize,
    params_needed: usize,
}

impl Parser {
    fn peek(&self) -> Option<&Tok> {
        self.toks.get(self.pos).map(|(_, t)| t)
    }
    fn at_end(&self) -> bool {
        self.pos >= self.toks.len()
    }
    fn peek_keyword(&self, kw: &str) -> bool {
        self.peek().is_some_and(|t| t.is_keyword(kw))
    }
    fn eat_keyword(&mut self, kw: &str) -> bool {
        let hit = self.peek_keyword(kw);
        self.pos += usize::from(hit);
        hit
    }
    fn expect_keyword(&mut self, kw: &'static str) -> Result<(), FilterError> {
        if self.eat_keyword(kw) {
            Ok(())
        } else {
            Err(self.unexpected(kw))
        }
    }
    fn unexpected(&self, expected: &'static str) -> FilterError {
        let (pos, found) = match self.toks.get(self.pos) {
            Some((p, t)) => (*p, t.describe()),
            None => (self.end, "the end of the expression".into()),
        };
        FilterError::Unexpected {
            pos,
            expected,
            found,
        }
    }
    fn nest(&mut self) -> Result<(), FilterError> {
        self.depth += 1;
        if self.depth > MAX_DEPTH {
            return Err(FilterError::TooDeep { limit: MAX_DEPTH });
        }
        Ok(())
    }

    fn or(&mut self) -> Result<Expr, FilterError> {
        self.chain("OR", Self::and, Expr::Or)
    }

    fn and(&mut self) -> Result<Expr, FilterError> {
        self.chain("AND", Self::not, Expr::And)
    }

    /// `term {kw term}` as one flat list (a single term stands alone).
    fn chain(
        &mut self,
        kw: &str,
        term: fn(&mut Self) -> Result<Expr, FilterError>,
        list: fn(Vec<Expr>) -> Expr,
    ) -> Result<Expr, FilterError> {
        let mut terms = vec![term(self)?];
        while self.eat_keyword(kw) {
            terms.push(term(self)?);
        }
        Ok(if terms.len() == 1 {
            terms.remove(0)
        } else {
            list(terms)
        })
    }

    fn not(&mut self) -> Result<Expr, FilterError> {
        if self.eat_keyword("NOT") {
            self.nest()?;
            let e = Expr::Not(Box::new(self.not()?));
            self.depth -= 1;
            return Ok(e);
        }
        if self.peek() == Some(&Tok::LParen) {
            self.pos += 1;
            self.nest()?;
            let e = self.or()?;
            if self.peek() != Some(&Tok::RParen) {
                return Err(self.unexpected("')'"));
            }
            self.pos += 1;
            self.depth -= 1;
            return Ok(e);
        }
        self.predicate()
    }

    fn predicate(&mut self) -> Result<Expr, FilterError> {
        let a = self.operand()?;
        let negate = self.eat_keyword("NOT");
        let e = if self.eat_keyword("BETWEEN") {
            let lo = self.operand()?;
            self.expect_keyword("AND")?;
            Expr::Between(a, lo, self.operand()?)
        } else if self.eat_keyword("LIKE") {
            Expr::Like(a, self.operand()?)
        } else if negate {
            return Err(self.unexpected("BETWEEN or LIKE after NOT"));
        } else if let Some(Tok::Op(op)) = self.peek() {
            let op = *op;
            self.pos += 1;
            Expr::Cmp(a, op, self.operand()?)
        } else if self.peek_keyword("MATCH") {
            let pos = self.toks[self.pos].0;
            return Err(FilterError::UnsupportedOperator {
                pos,
                op: "MATCH".into(),
            });
        } else {
            return Err(self.unexpected("a relational operator, BETWEEN or LIKE"));
        };
        Ok(if negate { Expr::Not(Box::new(e)) } else { e })
    }

    fn operand(&mut self) -> Result<Operand, FilterError> {
        let o = match self.peek() {
            Some(Tok::Path(p, text)) if !is_reserved(text) => Operand::Field(p.clone()),
            Some(Tok::Lit(l)) => Operand::Lit(l.clone()),
            Some(Tok::Param(n)) => Operand::Param(*n),
            _ => return Err(self.unexpected("a field name, a literal or a parameter")),
        };
        if let Operand::Param(n) = o {
            self.params_needed = self.params_needed.max(n + 1);
        }
        self.pos += 1;
        Ok(o)
    }

    fn field(&mut self, expected: &'static str) -> Result<Vec<PathSegment>, FilterError> {
        match self.peek() {
            Some(Tok::Path(p, text)) if !is_reserved(text) => {
                let p = p.clone();
                self.pos += 1;
                Ok(p)
            }
            _ => Err(self.unexpected(expected)),
        }
    }
}

/// Keywords that cannot name a field.
fn is_reserved(word: &str) -> bool {
    const RESERVED: [&str; 8] = [
        "AND", "OR", "NOT", "BETWEEN", "LIKE", "ORDER", "BY", "MATCH",
    ];
    RESERVED.iter().any(|k| word.eq_ignore_ascii_case(k))
}
