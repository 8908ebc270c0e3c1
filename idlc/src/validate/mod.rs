//! Semantic checks on the resolved model. Each check reports with its own code and keeps going.
use crate::diag::{Code, Diagnostic, Diagnostics};
use crate::model::*;
use std::collections::HashMap;

/// Checks the model as a whole (union labels, keys, member ids, ...), reporting into `diags`.
pub fn validate(model: &Model, diags: &mut Diagnostics) {
    for (id, d) in model.decls.iter().enumerate() {
        match &d.kind {
            DeclKind::Struct(s) => check_struct(model, id, s, diags),
            DeclKind::Union(u) => check_union(model, u, diags),
            DeclKind::Enum(e) => check_enum(e, diags),
            DeclKind::Bitmask(b) => check_bitmask(b, diags),
            _ => {}
        }
    }
    check_infinite(model, diags);
}

/// Fields of the base chain, outermost base first.
fn all_fields<'a>(model: &'a Model, s: &'a Struct) -> Vec<&'a Field> {
    let mut chain = vec![s];
    let mut cur = s;
    while let Some(b) = cur.base {
        match &model.decls[b].kind {
            DeclKind::Struct(bs) if chain.len() < 64 => {
                chain.push(bs);
                cur = bs;
            }
            _ => break,
        }
    }
    chain.iter().rev().flat_map(|s| s.fields.iter()).collect()
}

/// The member id XTypes assigns to each field (§7.3.1.2.1.1, sequential or hashed).
pub fn member_ids(model: &Model, s: &Struct) -> Vec<u32> {
    let fields = all_fields(model, s);
    let mut ids = Vec::with_capacity(fields.len());
    let mut next = 0u32;
    for f in fields {
        let id = if let Some(id) = f.id {
            id
        } else if let Some(h) = &f.hashid {
            hash_id(if h.is_empty() { &f.name } else { h })
        } else if s.autoid == AutoId::Hash {
            hash_id(&f.name)
        } else {
            next
        };
        next = id.wrapping_add(1);
        ids.push(id);
    }
    ids
}

/// XTypes hash-based member id: the first four bytes of MD5(name), little-endian, masked to 28 bits.
pub fn hash_id(name: &str) -> u32 {
    use md5::{Digest, Md5};
    let h = Md5::digest(name.as_bytes());
    u32::from_le_bytes([h[0], h[1], h[2], h[3]]) & 0x0FFF_FFFF
}

fn check_struct(model: &Model, _id: DeclId, s: &Struct, diags: &mut Diagnostics) {
    let fields = all_fields(model, s);
    // Names, exact and case-insensitive.
    let mut seen: HashMap<String, &Field> = HashMap::new();
    for f in &fields {
        if let Some(prev) = seen.get(&f.name.to_ascii_lowercase()) {
            let (code, msg) = if prev.name == f.name {
                (
                    Code::DuplicateMember,
                    format!("member `{}` is declared twice", f.name),
                )
            } else {
                (
                    Code::CaseCollision,
                    format!(
                        "member `{}` collides with `{}`: names must differ by more than case",
                        f.name, prev.name
                    ),
                )
            };
            diags.push(
                Diagnostic::error(code, msg)
                    .at(f.loc, "redeclared here")
                    .also(prev.loc, "first declared here"),
            );
        } else {
            seen.insert(f.name.to_ascii_lowercase(), f);
        }
    }
    // Ids.
    let ids = member_ids(model, s);
    let mut by_id: HashMap<u32, &Field> = HashMap::new();
    for (f, id) in fields.iter().zip(ids) {
        if let Some(prev) = by_id.insert(id, f) {
            let msg = format!(
                "members `{}` and `{}` both have member id {id}",
                prev.name, f.name
            );
            diags.push(
                Diagnostic::error(Code::DuplicateId, msg)
                    .at(f.loc, format!("id {id}"))
                    .also(prev.loc, "same id here")
                    .help("give one of them a distinct `@id`"),
            );
        }
    }
    // A derived struct may not add keys to a keyed base (XTypes 1.3 §7.2.2.4.4.4.3).
    if s.base.is_some() {
        let base_keyed = fields.len() > s.fields.len()
            && fields[..fields.len() - s.fields.len()]
                .iter()
                .any(|f| f.key);
        if base_keyed {
            for f in s.fields.iter().filter(|f| f.key) {
                let msg = format!("derived struct adds key member `{}`", f.name);
                diags.push(
                    Diagnostic::error(Code::DerivedKey, msg)
                        .at(f.loc, "key declared in a derived struct")
                        .help("the key of a derived struct is the key of its base; move the key to the base"),
                );
            }
        }
    }
}

fn check_union(model: &Model, u: &Union, diags: &mut Diagnostics) {
    let mut seen: Vec<(&Value, crate::source::Loc)> = Vec::new();
    let mut default: Option<crate::source::Loc> = None;
    let mut names: HashMap<String, &UnionCase> = HashMap::new();
    for c in &u.cases {
        if let Some(prev) = names.get(&c.name.to_ascii_lowercase()) {
            let msg = format!("union member `{}` is declared twice", c.name);
            diags.push(
                Diagnostic::error(Code::DuplicateMember, msg)
                    .at(c.loc, "redeclared here")
                    .also(prev.loc, "first declared here"),
            );
        } else {
            names.insert(c.name.to_ascii_lowercase(), c);
        }
        if let Some(loc) = c.default_loc {
            if let Some(prev) = default {
                diags.push(
                    Diagnostic::error(
                        Code::SeveralDefaults,
                        "union has more than one `default` label",
                    )
                    .at(loc, "second default")
                    .also(prev, "first default"),
                );
            }
            default = Some(loc);
        }
        for (v, loc) in c.labels.iter().zip(&c.label_locs) {
            if let Some((_, prev)) = seen.iter().find(|(p, _)| *p == v) {
                let msg = format!("duplicate case label {}", show(model, v));
                diags.push(
                    Diagnostic::error(Code::DuplicateLabel, msg)
                        .at(*loc, "repeated here")
                        .also(*prev, "first used here"),
                );
            } else {
                seen.push((v, *loc));
            }
        }
    }
    if let Some(d) = default {
        check_unreachable_default(model, u, d, diags);
    }
}

/// A `default:` is only meaningful when some discriminator value has no label (enums and booleans are finite).
fn check_unreachable_default(
    model: &Model,
    u: &Union,
    default: crate::source::Loc,
    diags: &mut Diagnostics,
) {
    let total = match model.resolve_alias(&u.discriminator) {
        Type::Named { decl, .. } => match &model.decls[*decl].kind {
            DeclKind::Enum(e) => e.enumerators.len(),
            _ => return,
        },
        Type::Prim {
            prim: crate::ast::Prim::Bool,
        } => 2,
        _ => return,
    };
    let mut labels: Vec<&Value> = u.cases.iter().flat_map(|c| c.labels.iter()).collect();
    labels.dedup();
    let distinct = labels
        .iter()
        .enumerate()
        .filter(|(i, v)| !labels[..*i].contains(v))
        .count();
    if distinct >= total {
        diags.push(
            Diagnostic::error(Code::UnreachableDefault, "the `default` member can never be selected")
                .at(default, "unreachable default")
                .help("every value of the discriminator already has a case label; remove `default` or a label"),
        );
    }
}

fn show(model: &Model, v: &Value) -> String {
    match v {
        Value::Enum(d, i) => match &model.decls[*d].kind {
            DeclKind::Enum(e) => format!("`{}`", e.enumerators[*i].name),
            _ => "?".into(),
        },
        Value::Int(i) => format!("`{i}`"),
        Value::Char(c) | Value::WChar(c) => format!("`{c:?}`"),
        Value::Bool(b) => format!("`{}`", if *b { "TRUE" } else { "FALSE" }),
        other => format!("{other:?}"),
    }
}

fn check_enum(e: &Enum, diags: &mut Diagnostics) {
    let mut seen: HashMap<i64, &Enumerator> = HashMap::new();
    for en in &e.enumerators {
        if let Some(prev) = seen.insert(en.value, en) {
            let msg = format!(
                "enumerators `{}` and `{}` have the same value {}",
                prev.name, en.name, en.value
            );
            diags.push(
                Diagnostic::error(Code::DuplicateValue, msg)
                    .at(en.loc, "same value")
                    .also(prev.loc, "first here"),
            );
        }
    }
}

fn check_bitmask(b: &Bitmask, diags: &mut Diagnostics) {
    let mut seen: HashMap<u32, &Flag> = HashMap::new();
    for f in &b.flags {
        if let Some(prev) = seen.insert(f.position, f) {
            let msg = format!(
                "flags `{}` and `{}` have the same position {}",
                prev.name, f.name, f.position
            );
            diags.push(
                Diagnostic::error(Code::DuplicateValue, msg)
                    .at(f.loc, "same position")
                    .also(prev.loc, "first here"),
            );
        }
    }
}

/// A struct or union that contains itself by value (not through a sequence, map or @external) has no
/// finite size.
fn check_infinite(model: &Model, diags: &mut Diagnostics) {
    fn direct(model: &Model, t: &Type, out: &mut Vec<DeclId>) {
        match t {
            Type::Array { elem, .. } => direct(model, elem, out),
            Type::Named { decl, .. } => match &model.decls[*decl].kind {
                DeclKind::Alias { ty } => direct(model, ty, out),
                DeclKind::Struct(_) | DeclKind::Union(_) => out.push(*decl),
                _ => {}
            },
            _ => {}
        }
    }
    let n = model.decls.len();
    let mut edges: Vec<Vec<(DeclId, crate::source::Loc)>> = vec![vec![]; n];
    for (id, d) in model.decls.iter().enumerate() {
        let mut push = |t: &Type, ext: bool, loc| {
            if ext {
                return;
            }
            let mut v = vec![];
            direct(model, t, &mut v);
            edges[id].extend(v.into_iter().map(|x| (x, loc)));
        };
        match &d.kind {
            DeclKind::Struct(s) => {
                if let Some(b) = s.base {
                    push(
                        &Type::Named {
                            decl: b,
                            name: String::new(),
                        },
                        false,
                        d.loc,
                    );
                }
                for f in &s.fields {
                    push(&f.ty, f.external, f.loc);
                }
            }
            DeclKind::Union(u) => {
                for c in &u.cases {
                    push(&c.ty, c.external, c.loc);
                }
            }
            _ => {}
        }
    }
    // Iterative DFS with colours.
    let mut colour = vec![0u8; n];
    for start in 0..n {
        if colour[start] != 0 {
            continue;
        }
        let mut stack: Vec<(DeclId, usize)> = vec![(start, 0)];
        colour[start] = 1;
        while let Some((node, i)) = stack.pop() {
            if i < edges[node].len() {
                stack.push((node, i + 1));
                let (next, loc) = edges[node][i];
                if colour[next] == 1 {
                    let msg = format!(
                        "`{}` contains itself by value and would have infinite size",
                        model.decls[next].scoped_name()
                    );
                    diags.push(
                        Diagnostic::error(Code::InfiniteType, msg)
                            .at(loc, "recursive without indirection")
                            .help("mark the member `@external`, or use a sequence"),
                    );
                } else if colour[next] == 0 {
                    colour[next] = 1;
                    stack.push((next, 0));
                }
            } else {
                colour[node] = 2;
            }
        }
    }
}
