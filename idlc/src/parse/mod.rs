//! Parsing: the pest grammar in `idl.pest`, syntax-error reporting, and AST construction (`build.rs`).
//!
//! [`parse`] splits the translation unit where an included file begins or ends and looks each piece up in a
//! [`ParseCache`] before parsing it, so a run that includes one file from many inputs parses it once.
mod build;
pub mod literal;
mod pieces;

pub use pieces::ParseCache;

use crate::ast::Spec;
use crate::diag::{Code, Diagnostic, Diagnostics};
use crate::preprocess::Output;
use pest::error::InputLocation;
use pest::Parser as _;
use std::sync::Arc;

mod grammar {
    // pest_derive generates `Rule` without docs.
    #![allow(missing_docs, unreachable_pub)]
    /// The pest parser generated from `idl.pest`.
    #[derive(pest_derive::Parser)]
    #[grammar = "parse/idl.pest"]
    pub(crate) struct IdlParser;
}
pub(crate) use grammar::{IdlParser, Rule};

/// Deepest bracket nesting accepted; deeper input is refused before pest recurses into it.
pub const MAX_NESTING: usize = 100;

/// Parses preprocessed text into syntax trees, one per piece of the translation unit, in order; together they
/// are the whole specification. Pieces already in `cache` are not parsed again. Syntax errors are reported
/// into `diags`; the result is then empty.
pub fn parse(pp: &Output, cache: &mut ParseCache, diags: &mut Diagnostics) -> Vec<Arc<Spec>> {
    if let Some(off) = too_deep(&pp.text) {
        diags.push(
            Diagnostic::error(
                Code::Limit,
                format!("brackets nested more than {MAX_NESTING} deep"),
            )
            .at(pp.map.loc(off, off + 1), "nesting limit reached here"),
        );
        return vec![];
    }
    if let Some(specs) = cache.parse_pieces(pp, diags) {
        return specs;
    }
    vec![Arc::new(parse_whole(pp, diags))]
}

/// Parses the whole text in one go; on a syntax error, reports the furthest failure.
fn parse_whole(pp: &Output, diags: &mut Diagnostics) -> Spec {
    match IdlParser::parse(Rule::specification, &pp.text) {
        Ok(mut pairs) => {
            let spec = pairs
                .next()
                .expect("specification rule always produces a pair");
            build::Builder::new(pp, diags).specification(spec)
        }
        Err(_) => {
            // Parse again with pest's detailed tracking of expected tokens, which costs time only on failure.
            pest::set_error_detail(true);
            let detailed = IdlParser::parse(Rule::specification, &pp.text);
            pest::set_error_detail(false);
            if let Err(e) = detailed {
                diags.push(syntax_error(pp, &e));
            }
            Spec::default()
        }
    }
}

/// Offset where bracket nesting first exceeds [`MAX_NESTING`], skipping comments and literals.
fn too_deep(text: &str) -> Option<usize> {
    let b = text.as_bytes();
    let mut depth = 0usize;
    let mut i = 0;
    while i < b.len() {
        match b[i] {
            b'/' if b.get(i + 1) == Some(&b'/') => {
                i = b[i..]
                    .iter()
                    .position(|&c| c == b'\n')
                    .map_or(b.len(), |p| i + p);
            }
            b'/' if b.get(i + 1) == Some(&b'*') => {
                i = text[i + 2..].find("*/").map_or(b.len(), |p| i + 2 + p + 2);
                continue;
            }
            b'"' | b'\'' => {
                let q = b[i];
                i += 1;
                while i < b.len() && b[i] != q && b[i] != b'\n' {
                    i += if b[i] == b'\\' { 2 } else { 1 };
                }
            }
            b'(' | b'{' | b'[' => depth += 1,
            b'<' if b.get(i + 1) != Some(&b'<') && (i == 0 || b[i - 1] != b'<') => depth += 1,
            b')' | b'}' | b']' | b'>' => depth = depth.saturating_sub(1),
            _ => {}
        }
        if depth > MAX_NESTING {
            return Some(i);
        }
        i += 1;
    }
    None
}

/// Human names of grammar rules, for "expected X".
fn rule_name(r: Rule) -> Option<&'static str> {
    use Rule::*;
    Some(match r {
        identifier => "identifier",
        scoped_name => "name",
        type_spec | base_type | template_type | integer_type | floating_type | switch_type
        | const_type => "type",
        const_expr | tmpl_expr | primary_expr | unary_expr | literal | int_lit | float_lit => {
            "expression"
        }
        annotation_appl => "annotation",
        definition => "definition",
        member => "member",
        declarator | declarators => "declarator",
        case_stmt | case_label | K_CASE => "`case`",
        default_label | K_DEFAULT => "`default`",
        enumerator => "enumerator",
        bitfield | bitfield_spec | K_BITFIELD => "`bitfield`",
        array_size => "`[`",
        EOI => "end of file",
        K_MODULE => "`module`",
        K_STRUCT => "`struct`",
        K_UNION => "`union`",
        K_SWITCH => "`switch`",
        K_ENUM => "`enum`",
        K_TYPEDEF => "`typedef`",
        K_CONST => "`const`",
        or_op | xor_op | and_op | shift_op | shl_op | add_op | mult_op => "operator",
        named_param => "parameter",
        _ => return None,
    })
}

fn syntax_error(pp: &Output, e: &pest::error::Error<Rule>) -> Diagnostic {
    let mut pos = match e.location {
        InputLocation::Pos(p) => p,
        InputLocation::Span((s, _)) => s,
    };
    let mut expected: Vec<String> = Vec::new();
    if let pest::error::ErrorVariant::ParsingError { positives, .. } = &e.variant {
        for r in positives {
            if let Some(n) = rule_name(*r) {
                expected.push(n.to_string());
            }
        }
    }
    if let Some(att) = e.parse_attempts() {
        // Literal tokens (`;`, `}`) can fail further right than any rule: report the furthest point.
        let mut further = Vec::new();
        for cs in att.call_stacks() {
            if let Some(n) = cs.parent.and_then(rule_name) {
                further.push(n.to_string());
            }
        }
        for t in att.expected_tokens() {
            // `ParsingToken` is not exported; its Display is the token text.
            let token = t.to_string();
            let punct = token.chars().all(|c| c.is_ascii_punctuation());
            if !token.is_empty() && punct && !matches!(token.as_str(), "_" | "#" | "/*" | "//") {
                further.push(format!("`{token}`"));
            }
        }
        if att.max_position > pos && !further.is_empty() {
            expected = further;
            pos = att.max_position;
        } else if att.max_position == pos {
            expected.extend(further);
        }
    }
    expected.sort();
    expected.dedup();
    // The closing brace is usually the meaningful alternative; the list of "definition", "type", etc. is noise.
    let found = found_token(&pp.text, pos);
    let mut last_is_ident = false;
    let msg = match expected.len() {
        0 => format!("unexpected {found}"),
        1 => {
            last_is_ident = expected[0] == "identifier";
            format!("expected {}, found {found}", expected[0])
        }
        _ => {
            let last = expected.pop().unwrap_or_default();
            last_is_ident = last == "identifier";
            format!(
                "expected one of {} or {last}, found {found}",
                expected.join(", ")
            )
        }
    };
    let len = found_len(&pp.text, pos).max(1);
    let loc = pp.map.loc(pos, (pos + len).min(pp.text.len().max(pos + 1)));
    let mut d = Diagnostic::error(Code::Syntax, msg).at(loc, "unexpected here");
    let word = &pp.text[pos..pos + found_len(&pp.text, pos)];
    let wants_name = expected
        .iter()
        .any(|e| e == "identifier" || e == "declarator")
        || last_is_ident;
    if !wants_name {
        return d;
    }
    if KEYWORDS.contains(&word) {
        d = d.help(format!(
            "`{word}` is a keyword; to use it as a name write `_{word}`"
        ));
    } else if let Some(kw) = KEYWORDS
        .iter()
        .find(|k| !word.is_empty() && k.eq_ignore_ascii_case(word))
    {
        d = d.help(format!(
            "`{word}` differs only in case from the keyword `{kw}`; escape it as `_{word}`"
        ));
    }
    d
}

/// Keywords that can never be identifiers (IDL 4.2 §7.2.4, the subset this grammar reserves).
pub const KEYWORDS: &[&str] = &[
    "any",
    "bitfield",
    "bitmask",
    "bitset",
    "boolean",
    "case",
    "char",
    "const",
    "default",
    "double",
    "enum",
    "exception",
    "FALSE",
    "fixed",
    "float",
    "int8",
    "int16",
    "int32",
    "int64",
    "interface",
    "long",
    "map",
    "module",
    "native",
    "Object",
    "octet",
    "sequence",
    "short",
    "string",
    "struct",
    "switch",
    "TRUE",
    "typedef",
    "uint8",
    "uint16",
    "uint32",
    "uint64",
    "union",
    "unsigned",
    "valuetype",
    "wchar",
    "wstring",
];

fn found_len(text: &str, pos: usize) -> usize {
    let b = &text.as_bytes()[pos.min(text.len())..];
    match b.first() {
        None => 0,
        Some(c) if c.is_ascii_alphanumeric() || *c == b'_' => b
            .iter()
            .take_while(|c| c.is_ascii_alphanumeric() || **c == b'_')
            .count()
            .min(64),
        Some(_) => text[pos..].chars().next().map_or(1, char::len_utf8),
    }
}

fn found_token(text: &str, pos: usize) -> String {
    let n = found_len(text, pos);
    if n == 0 {
        return "end of file".into();
    }
    let t = &text[pos..pos + n];
    if t.as_bytes()[0].is_ascii_digit() {
        format!("number `{t}`")
    } else if t.as_bytes()[0].is_ascii_alphabetic() || t.starts_with('_') {
        if KEYWORDS.contains(&t) {
            format!("keyword `{t}`")
        } else {
            format!("`{t}`")
        }
    } else {
        format!("`{t}`")
    }
}
