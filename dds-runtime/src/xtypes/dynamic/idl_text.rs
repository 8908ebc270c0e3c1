//! [`DynamicType::to_idl`]: a type and every named type it uses, as IDL text (what `dds typeof` prints).

use std::fmt::Write;

use crate::cdr::Extensibility;

use super::types::{DynamicType, TypeKind};

impl DynamicType {
    /// The type as IDL: every named type it depends on first, each in its modules, then the type itself.
    pub fn to_idl(&self) -> String {
        let mut order: Vec<DynamicType> = Vec::new();
        collect(self, &mut order, 0);
        let mut out = String::new();
        for t in &order {
            declare(t, &mut out);
        }
        out
    }
}

fn is_named(t: &DynamicType) -> bool {
    matches!(
        t.kind(),
        TypeKind::Struct(_)
            | TypeKind::Union(_)
            | TypeKind::Enum(_)
            | TypeKind::Bitmask(_)
            | TypeKind::Alias { .. }
    )
}

/// Named types in dependency order (post-order), each once.
fn collect(t: &DynamicType, order: &mut Vec<DynamicType>, depth: u32) {
    if depth > 64 || (is_named(t) && order.iter().any(|x| x.name() == t.name())) {
        return;
    }
    match t.kind() {
        TypeKind::Struct(s) => {
            if let Some(b) = &s.base {
                collect(b, order, depth + 1);
            }
            let own = s.levels.len().checked_sub(2).map_or(0, |i| s.levels[i]);
            for m in &s.members[own..] {
                collect(&m.ty, order, depth + 1);
            }
        }
        TypeKind::Union(u) => {
            collect(&u.discriminator, order, depth + 1);
            for c in &u.cases {
                collect(&c.ty, order, depth + 1);
            }
        }
        TypeKind::Alias { target, .. } => collect(target, order, depth + 1),
        TypeKind::Sequence { element, .. } | TypeKind::Array { element, .. } => {
            collect(element, order, depth + 1)
        }
        TypeKind::Map { key, value, .. } => {
            collect(key, order, depth + 1);
            collect(value, order, depth + 1);
        }
        _ => {}
    }
    if is_named(t) {
        order.push(t.clone());
    }
}

/// How a member of type `t` named `name` is declared (arrays put their dimensions after the name).
fn decl(t: &DynamicType, name: &str) -> String {
    match t.kind() {
        TypeKind::Array { element, dims } => {
            let d: String = dims.iter().map(|d| format!("[{d}]")).collect();
            format!("{} {name}{d}", spelling(element))
        }
        _ => format!("{} {name}", spelling(t)),
    }
}

/// A type's spelling where it is used: the scoped name of a named type, else the IDL type expression.
fn spelling(t: &DynamicType) -> String {
    match t.kind() {
        TypeKind::Sequence { element, bound } => match bound {
            Some(b) => format!("sequence<{}, {b}>", spelling(element)),
            None => format!("sequence<{}>", spelling(element)),
        },
        TypeKind::Map { key, value, bound } => match bound {
            Some(b) => format!("map<{}, {}, {b}>", spelling(key), spelling(value)),
            None => format!("map<{}, {}>", spelling(key), spelling(value)),
        },
        _ => t.name(),
    }
}

fn ext_annotation(e: Extensibility) -> &'static str {
    match e {
        Extensibility::Final => "@final",
        Extensibility::Appendable => "@appendable",
        Extensibility::Mutable => "@mutable",
    }
}

/// Writes `t` inside its modules.
fn declare(t: &DynamicType, out: &mut String) {
    let full = t.name();
    let parts: Vec<&str> = full.split("::").collect();
    let (modules, local) = parts.split_at(parts.len() - 1);
    let mut ind = String::new();
    for m in modules {
        let _ = writeln!(out, "{ind}module {m} {{");
        ind.push_str("    ");
    }
    let local = local[0];
    match t.kind() {
        TypeKind::Struct(s) => {
            let own = s.levels.len().checked_sub(2).map_or(0, |i| s.levels[i]);
            let base = s
                .base
                .as_ref()
                .map(|b| format!(" : {}", b.name()))
                .unwrap_or_default();
            let _ = writeln!(
                out,
                "{ind}{}\n{ind}struct {local}{base} {{",
                ext_annotation(s.extensibility)
            );
            for m in &s.members[own..] {
                let mut a = format!("@id({}) ", m.id);
                for (on, name) in [
                    (m.key, "@key "),
                    (m.optional, "@optional "),
                    (m.external, "@external "),
                    (m.must_understand, "@must_understand "),
                ] {
                    if on {
                        a.push_str(name);
                    }
                }
                let _ = writeln!(out, "{ind}    {a}{};", decl(&m.ty, &m.name));
            }
            let _ = writeln!(out, "{ind}}};");
        }
        TypeKind::Union(u) => {
            let key = if u.disc_key { "@key " } else { "" };
            let _ = writeln!(
                out,
                "{ind}{}\n{ind}union {local} switch ({key}{}) {{",
                ext_annotation(u.extensibility),
                spelling(&u.discriminator)
            );
            for c in &u.cases {
                let mut labels: Vec<String> = c
                    .labels
                    .iter()
                    .map(|l| format!("case {}:", label(&u.discriminator, *l)))
                    .collect();
                if c.is_default {
                    labels.push("default:".into());
                }
                let _ = writeln!(
                    out,
                    "{ind}    {}\n{ind}        {};",
                    labels.join(" "),
                    decl(&c.ty, &c.name)
                );
            }
            let _ = writeln!(out, "{ind}}};");
        }
        TypeKind::Enum(e) => {
            if e.bit_bound != 32 {
                let _ = writeln!(out, "{ind}@bit_bound({})", e.bit_bound);
            }
            let lits: Vec<String> = e
                .literals
                .iter()
                .map(|l| format!("{ind}    @value({}) {}", l.value, l.name))
                .collect();
            let _ = writeln!(out, "{ind}enum {local} {{\n{}\n{ind}}};", lits.join(",\n"));
        }
        TypeKind::Bitmask(b) => {
            let flags: Vec<String> = b
                .flags
                .iter()
                .map(|f| format!("{ind}    @position({}) {}", f.position, f.name))
                .collect();
            let _ = writeln!(
                out,
                "{ind}@bit_bound({})\n{ind}bitmask {local} {{\n{}\n{ind}}};",
                b.bit_bound,
                flags.join(",\n")
            );
        }
        TypeKind::Alias { target, .. } => {
            let _ = writeln!(out, "{ind}typedef {};", decl(target, local));
        }
        _ => {}
    }
    for _ in modules {
        ind.truncate(ind.len() - 4);
        let _ = writeln!(out, "{ind}}};");
    }
}

fn label(disc: &DynamicType, v: i64) -> String {
    match disc.resolved().kind() {
        TypeKind::Enum(e) => e.name_of(v as i32).map_or_else(
            || v.to_string(),
            |n| {
                format!("{}::{n}", e.name.rsplit_once("::").map_or("", |p| p.0))
                    .trim_start_matches("::")
                    .to_string()
            },
        ),
        TypeKind::Primitive(super::Primitive::Bool) => {
            (if v != 0 { "TRUE" } else { "FALSE" }).to_string()
        }
        TypeKind::Primitive(super::Primitive::Char8) => format!("'{}'", char::from(v as u8)),
        _ => v.to_string(),
    }
}
