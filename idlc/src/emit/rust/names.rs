//! IDL names to idiomatic Rust names: modules and fields snake_case, types UpperCamelCase, constants
//! SCREAMING_SNAKE_CASE; Rust keywords become raw identifiers.

const KEYWORDS: &[&str] = &[
    "as", "break", "const", "continue", "crate", "else", "enum", "extern", "false", "fn", "for",
    "if", "impl", "in", "let", "loop", "match", "mod", "move", "mut", "pub", "ref", "return",
    "self", "Self", "static", "struct", "super", "trait", "true", "type", "unsafe", "use", "where",
    "while", "async", "await", "dyn", "abstract", "become", "box", "do", "final", "macro",
    "override", "priv", "typeof", "unsized", "virtual", "yield", "try", "gen",
];

/// Words into parts at underscores and case changes: `HTTPServer_id2` → [HTTP, Server, id2].
fn words(s: &str) -> Vec<String> {
    let mut out = Vec::new();
    for part in s.split('_').filter(|p| !p.is_empty()) {
        let cs: Vec<char> = part.chars().collect();
        let mut cur = String::new();
        for i in 0..cs.len() {
            let c = cs[i];
            if i > 0 && c.is_uppercase() {
                let prev = cs[i - 1];
                let next_lower = cs.get(i + 1).is_some_and(|n| n.is_lowercase());
                if prev.is_lowercase()
                    || prev.is_ascii_digit()
                    || (prev.is_uppercase() && next_lower)
                {
                    out.push(std::mem::take(&mut cur));
                }
            }
            cur.push(c);
        }
        if !cur.is_empty() {
            out.push(cur);
        }
    }
    out
}

/// `snake_case` (modules, fields, bitset accessors); a leading digit gets a `_`.
pub fn snake(s: &str) -> String {
    let w = words(s);
    if w.is_empty() {
        return "_".into();
    }
    let mut r = w
        .iter()
        .map(|w| w.to_lowercase())
        .collect::<Vec<_>>()
        .join("_");
    if r.starts_with(|c: char| c.is_ascii_digit()) {
        r.insert(0, '_');
    }
    r
}

/// `UpperCamelCase` (types, enumerators, union variants); a name already in camel case is kept as written.
pub fn upper_camel(s: &str) -> String {
    // Already acceptable camel case (acronyms allowed): keep the author's spelling.
    let has_lower = s.chars().any(|c| c.is_lowercase());
    if s.starts_with(|c: char| c.is_ascii_uppercase())
        && !s.contains('_')
        && (has_lower || s.len() == 1)
    {
        return s.to_string();
    }
    let mut r = String::new();
    for w in words(s) {
        let all_upper = w.chars().all(|c| !c.is_lowercase());
        let mut cs = w.chars();
        if let Some(f) = cs.next() {
            r.extend(f.to_uppercase());
            let rest: String = cs.collect();
            r.push_str(&if all_upper { rest.to_lowercase() } else { rest });
        }
    }
    if r.is_empty() || r.starts_with(|c: char| c.is_ascii_digit()) {
        r.insert(0, 'T');
    }
    r
}

pub(super) fn screaming(s: &str) -> String {
    snake(s).to_uppercase()
}

/// Makes a name usable as an identifier: raw identifier for keywords, suffix for the four that cannot be raw.
pub(super) fn ident(s: &str) -> String {
    match s {
        "self" | "Self" | "super" | "crate" | "_" => format!("{s}_"),
        _ if KEYWORDS.contains(&s) => format!("r#{s}"),
        _ => s.to_string(),
    }
}

/// The name without a raw prefix, for comparing with the IDL name.
pub(super) fn bare(s: &str) -> &str {
    s.strip_prefix("r#").unwrap_or(s)
}

/// Escapes text for a Rust string literal.
pub(super) fn lit_str(s: &str) -> String {
    format!("{s:?}")
}

#[cfg(test)]
mod tests {
    use super::*;
    #[test]
    fn cases() {
        assert_eq!(snake("ShapeType"), "shape_type");
        assert_eq!(snake("HTTPServer"), "http_server");
        assert_eq!(snake("x"), "x");
        assert_eq!(snake("std_msgs"), "std_msgs");
        assert_eq!(snake("a__b"), "a_b");
        assert_eq!(snake("position3D"), "position3_d");
        assert_eq!(upper_camel("shape_type"), "ShapeType");
        assert_eq!(upper_camel("RED"), "Red");
        assert_eq!(upper_camel("COLOR_RED"), "ColorRed");
        assert_eq!(upper_camel("HTTPServer"), "HTTPServer");
        assert_eq!(upper_camel("ID"), "Id");
        assert_eq!(upper_camel("X"), "X");
        assert_eq!(upper_camel("point3D"), "Point3D");
        assert_eq!(screaming("maxLen"), "MAX_LEN");
        assert_eq!(ident("type"), "r#type");
        assert_eq!(ident("self"), "self_");
    }
}
