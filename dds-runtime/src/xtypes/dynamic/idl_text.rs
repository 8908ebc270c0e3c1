//! [`DynamicType::to_idl`]: a type and every named type it uses, as IDL text (what `dds typeof` prints).

use std::fmt::Write;

use crate::cdr::Extensibility;

use super::types::{DynamicType, EnumType, StructType, TypeKind, UnionType};

impl DynamicType {
    /// The type as IDL: every named type it depends on first, each in its modules, then the type itself.
    pub fn to_idl(&self) -> String {
        let mut c = Collector::default();
        c.collect(self, 0);
        let mut out = String::new();
        for (t, forward) in &c.order {
            declare(t, *forward, &mut out);
        }
        out
    }
}

/// IDL 4.2's keywords (§7.2.4, Table 7-6): a name equal to one of them, ignoring case, is written escaped.
const KEYWORDS: &[&str] = &[
    "abstract",
    "alias",
    "any",
    "attribute",
    "bitfield",
    "bitmask",
    "bitset",
    "boolean",
    "case",
    "char",
    "component",
    "connector",
    "const",
    "consumes",
    "context",
    "custom",
    "default",
    "double",
    "emits",
    "enum",
    "eventtype",
    "exception",
    "factory",
    "false",
    "finder",
    "fixed",
    "float",
    "getraises",
    "getter",
    "home",
    "import",
    "in",
    "inout",
    "int16",
    "int32",
    "int64",
    "int8",
    "interface",
    "local",
    "long",
    "manages",
    "map",
    "mirrorport",
    "module",
    "multiple",
    "native",
    "object",
    "octet",
    "oneway",
    "out",
    "port",
    "porttype",
    "primarykey",
    "private",
    "provides",
    "public",
    "publishes",
    "raises",
    "readonly",
    "sequence",
    "setraises",
    "setter",
    "short",
    "string",
    "struct",
    "supports",
    "switch",
    "true",
    "truncatable",
    "typedef",
    "typeid",
    "typename",
    "typeprefix",
    "uint16",
    "uint32",
    "uint64",
    "uint8",
    "union",
    "unsigned",
    "uses",
    "valuebase",
    "valuetype",
    "void",
    "wchar",
    "wstring",
];

/// A name as an IDL identifier: escaped with `_` when it is a keyword.
fn ident(name: &str) -> String {
    if KEYWORDS.contains(&name.to_ascii_lowercase().as_str()) {
        format!("_{name}")
    } else {
        name.to_string()
    }
}

/// A scoped name (`A::B`) with each part an identifier.
fn scoped(name: &str) -> String {
    name.split("::").map(ident).collect::<Vec<_>>().join("::")
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

/// Named types in dependency order (post-order), each once; a recursive type used before its declaration
/// is declared forward first (`struct Node;`: `true` in `order`).
#[derive(Default)]
struct Collector {
    order: Vec<(DynamicType, bool)>,
    /// The named types being collected (their members are being walked).
    busy: Vec<String>,
}

impl Collector {
    fn has(&self, name: &str, forward: bool) -> bool {
        self.order
            .iter()
            .any(|(x, f)| *f == forward && x.name() == name)
    }

    fn collect(&mut self, t: &DynamicType, depth: u32) {
        let t = t.unforwarded();
        if depth > 64 || (is_named(t) && self.has(&t.name(), false)) {
            return;
        }
        let back_edge = matches!(t.kind(), TypeKind::Struct(_) | TypeKind::Union(_))
            && self.busy.contains(&t.name());
        if back_edge {
            // A recursive type met again while its members are walked: declared forward before its users.
            if !self.has(&t.name(), true) {
                self.order.push((t.clone(), true));
            }
            return;
        }
        let d = depth + 1;
        match t.kind() {
            TypeKind::Struct(s) => {
                self.busy.push(s.name.clone());
                if let Some(b) = &s.base {
                    self.collect(b, d);
                }
                for m in s.own_members() {
                    self.collect(&m.ty, d);
                }
                self.busy.pop();
            }
            TypeKind::Union(u) => {
                self.busy.push(u.name.clone());
                self.collect(&u.discriminator, d);
                for c in &u.cases {
                    self.collect(&c.ty, d);
                }
                self.busy.pop();
            }
            TypeKind::Alias { target, .. } => self.collect(target, d),
            TypeKind::Array { element, .. } => self.collect(element, d),
            TypeKind::Sequence { element, .. } => self.collect_element(element, d),
            TypeKind::Map { key, value, .. } => {
                self.collect_element(key, d);
                self.collect_element(value, d);
            }
            _ => {}
        }
        if is_named(t) {
            self.order.push((t.clone(), false));
        }
    }

    /// A sequence's element or a map's key or value: an anonymous array there has no IDL spelling, so it gets a
    /// generated typedef ([`array_typedef_name`]), declared before its first use.
    fn collect_element(&mut self, t: &DynamicType, depth: u32) {
        self.collect(t, depth);
        if matches!(t.kind(), TypeKind::Array { .. }) {
            self.collect(&DynamicType::alias(array_typedef_name(t), t.clone()), depth);
        }
    }
}

/// The name of the typedef [`to_idl`](DynamicType::to_idl) writes for an anonymous array where IDL allows
/// none (`sequence<long[2]>` becomes `typedef long long_array_2[2];` and `sequence<long_array_2>`): the
/// element's spelling and the dimensions, as one identifier, at the outermost scope.
fn array_typedef_name(t: &DynamicType) -> String {
    let TypeKind::Array { element, dims } = t.kind() else {
        return t.name();
    };
    let mut name: String = spelling(element)
        .chars()
        .map(|c| if c.is_ascii_alphanumeric() { c } else { '_' })
        .collect();
    name.push_str("_array");
    for d in dims {
        let _ = write!(name, "_{d}");
    }
    let mut squeezed = String::with_capacity(name.len());
    for c in name.chars() {
        if !(c == '_' && squeezed.ends_with('_')) {
            squeezed.push(c);
        }
    }
    squeezed.trim_matches('_').to_string()
}

/// How a member of type `t` named `name` is declared (arrays put their dimensions after the name).
fn decl(t: &DynamicType, name: &str) -> String {
    match t.kind() {
        TypeKind::Array { element, dims } => {
            let d: String = dims.iter().map(|d| format!("[{d}]")).collect();
            format!("{} {}{d}", spelling(element), ident(name))
        }
        _ => format!("{} {}", spelling(t), ident(name)),
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
        TypeKind::Array { .. } => array_typedef_name(t),
        _ if is_named(t) || matches!(t.kind(), TypeKind::Forward(_)) => scoped(&t.name()),
        _ => t.name(),
    }
}

/// ` @nested` and ` @autoid(HASH)` when they apply.
fn type_annotations(nested: bool, autoid_hash: bool) -> String {
    let mut a = String::new();
    if nested {
        a.push_str(" @nested");
    }
    if autoid_hash {
        a.push_str(" @autoid(HASH)");
    }
    a
}

fn ext_annotation(e: Extensibility) -> &'static str {
    match e {
        Extensibility::Final => "@final",
        Extensibility::Appendable => "@appendable",
        Extensibility::Mutable => "@mutable",
    }
}

/// Writes `t` inside its modules (only `struct T;` or `union T;` when `forward`).
fn declare(t: &DynamicType, forward: bool, out: &mut String) {
    let full = t.name();
    let parts: Vec<&str> = full.split("::").collect();
    let (modules, local) = parts.split_at(parts.len() - 1);
    let mut ind = String::new();
    for m in modules {
        let _ = writeln!(out, "{ind}module {} {{", ident(m));
        ind.push_str("    ");
    }
    let raw = local[0];
    let local = ident(raw);
    match t.kind() {
        TypeKind::Struct(_) if forward => {
            let _ = writeln!(out, "{ind}struct {local};");
        }
        TypeKind::Union(_) if forward => {
            let _ = writeln!(out, "{ind}union {local};");
        }
        TypeKind::Struct(s) => declare_struct(s, &local, &ind, out),
        TypeKind::Union(u) => declare_union(u, &local, &ind, out),
        TypeKind::Enum(e) => declare_enum(e, &local, &ind, out),
        TypeKind::Bitmask(b) => {
            let flags: Vec<String> = b
                .flags
                .iter()
                .map(|f| format!("{ind}    @position({}) {}", f.position, ident(&f.name)))
                .collect();
            let _ = writeln!(
                out,
                "{ind}@bit_bound({})\n{ind}bitmask {local} {{\n{}\n{ind}}};",
                b.bit_bound,
                flags.join(",\n")
            );
        }
        TypeKind::Alias { target, .. } => {
            let _ = writeln!(out, "{ind}typedef {};", decl(target, raw));
        }
        _ => {}
    }
    for _ in modules {
        ind.truncate(ind.len() - 4);
        let _ = writeln!(out, "{ind}}};");
    }
}

fn declare_struct(s: &StructType, local: &str, ind: &str, out: &mut String) {
    let base = s
        .base
        .as_ref()
        .map(|b| format!(" : {}", scoped(&b.name())))
        .unwrap_or_default();
    let _ = writeln!(
        out,
        "{ind}{}{}\n{ind}struct {local}{base} {{",
        ext_annotation(s.extensibility),
        type_annotations(s.nested, s.autoid_hash)
    );
    for m in s.own_members() {
        let mut a = match m.hash_id.as_deref() {
            Some("") => "@hashid ".to_string(),
            Some(h) => format!("@hashid(\"{h}\") "),
            None => format!("@id({}) ", m.id),
        };
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

fn declare_union(u: &UnionType, local: &str, ind: &str, out: &mut String) {
    let key = if u.disc_key { "@key " } else { "" };
    let _ = writeln!(
        out,
        "{ind}{}{}\n{ind}union {local} switch ({key}{}) {{",
        ext_annotation(u.extensibility),
        type_annotations(u.nested, false),
        spelling(&u.discriminator)
    );
    let mut next_id = UnionType::first_member_id(u.extensibility);
    for c in &u.cases {
        // Ids are written where they are not the default numbering.
        let mut a = if c.id == next_id {
            String::new()
        } else {
            format!("@id({}) ", c.id)
        };
        next_id = c.id.wrapping_add(1);
        if c.external {
            a.push_str("@external ");
        }
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
            "{ind}    {}\n{ind}        {a}{};",
            labels.join(" "),
            decl(&c.ty, &c.name)
        );
    }
    let _ = writeln!(out, "{ind}}};");
}

fn declare_enum(e: &EnumType, local: &str, ind: &str, out: &mut String) {
    if e.extensibility != Extensibility::Final {
        let _ = writeln!(out, "{ind}{}", ext_annotation(e.extensibility));
    }
    if e.bit_bound != 32 {
        let _ = writeln!(out, "{ind}@bit_bound({})", e.bit_bound);
    }
    let lits: Vec<String> = e
        .literals
        .iter()
        .enumerate()
        .map(|(i, l)| {
            let d = if i == e.default && i != 0 {
                "@default_literal "
            } else {
                ""
            };
            format!("{ind}    {d}@value({}) {}", l.value, ident(&l.name))
        })
        .collect();
    let _ = writeln!(out, "{ind}enum {local} {{\n{}\n{ind}}};", lits.join(",\n"));
}

fn label(disc: &DynamicType, v: i64) -> String {
    match disc.resolved().kind() {
        TypeKind::Enum(e) => e.name_of(v as i32).map_or_else(
            || v.to_string(),
            |n| {
                scoped(
                    format!("{}::{n}", e.name.rsplit_once("::").map_or("", |p| p.0))
                        .trim_start_matches("::"),
                )
            },
        ),
        TypeKind::Primitive(super::Primitive::Bool) => {
            (if v != 0 { "TRUE" } else { "FALSE" }).to_string()
        }
        TypeKind::Primitive(super::Primitive::Char8) => format!("'{}'", char::from(v as u8)),
        _ => v.to_string(),
    }
}

#[cfg(test)]
mod tests {
    use super::super::builder::StructBuilder;
    use super::super::types::Primitive;
    use super::*;

    #[test]
    fn anonymous_arrays_in_sequences_and_maps_get_one_typedef_each() {
        let long3 = DynamicType::array(DynamicType::primitive(Primitive::Int32), vec![3]).unwrap();
        let t = StructBuilder::new("M::S")
            .member("a", DynamicType::sequence(long3.clone(), Some(4)))
            .member(
                "b",
                DynamicType::map(DynamicType::string(None), long3.clone(), None),
            )
            .member("c", long3)
            .build()
            .unwrap();
        let idl = t.to_idl();
        assert_eq!(
            idl.matches("typedef long long_array_3[3];").count(),
            1,
            "{idl}"
        );
        assert!(idl.contains("sequence<long_array_3, 4> a;"), "{idl}");
        assert!(idl.contains("map<string, long_array_3> b;"), "{idl}");
        assert!(idl.contains("long c[3];"), "{idl}");
        assert!(idl.find("typedef").unwrap() < idl.find("struct S").unwrap());
    }
}
