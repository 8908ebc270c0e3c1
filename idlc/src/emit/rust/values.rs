//! Values as Rust expressions: constants, `@default` values, union case labels, enumerator paths; and which
//! default values would build a given type (to keep a recursive union's `Default` finite).
use super::names::{ident, lit_str, upper_camel};
use super::{Dedup, Emitter};
use crate::ast::Prim;
use crate::model::{DeclId, DeclKind, Type, Value};

impl Emitter<'_> {
    pub(super) fn label_expr(&self, v: &Value) -> String {
        match v {
            Value::Int(i) => i.to_string(),
            Value::Char(c) => format!("{c:?}"),
            Value::WChar(c) => format!("{}::cdr::WChar({})", self.opts.runtime_crate, *c as u32),
            Value::Bool(b) => b.to_string(),
            Value::Enum(d, i) => self.enumerator_path(*d, *i),
            other => format!("{other:?}"),
        }
    }

    pub(super) fn enumerator_path(&self, d: DeclId, i: usize) -> String {
        let names = self.enumerator_names(d);
        format!(
            "{}::{}",
            self.path_to(d),
            names.get(i).cloned().unwrap_or_default()
        )
    }

    pub(super) fn enumerator_names(&self, d: DeclId) -> Vec<String> {
        let DeclKind::Enum(e) = &self.model.decls[d].kind else {
            return vec![];
        };
        let mut used = Dedup::new();
        e.enumerators
            .iter()
            .map(|en| used.take(ident(&upper_camel(&en.name))))
            .collect()
    }

    /// Whether `Default::default()` of `t` constructs a value of `target` (empty containers and `None` do not).
    pub(super) fn default_builds(&self, t: &Type, target: DeclId, seen: &mut Vec<DeclId>) -> bool {
        match t {
            Type::Array { elem, .. } => self.default_builds(elem, target, seen),
            Type::Named { decl, .. } => {
                if *decl == target {
                    return true;
                }
                if seen.contains(decl) {
                    return false;
                }
                seen.push(*decl);
                match &self.model.decls[*decl].kind {
                    DeclKind::Alias { ty } => self.default_builds(ty, target, seen),
                    DeclKind::Struct(s) => {
                        s.base.is_some_and(|b| {
                            self.default_builds(
                                &Type::Named {
                                    decl: b,
                                    name: String::new(),
                                },
                                target,
                                seen,
                            )
                        }) || s
                            .fields
                            .iter()
                            .any(|f| !f.optional && self.default_builds(&f.ty, target, seen))
                    }
                    DeclKind::Union(u) => u
                        .cases
                        .first()
                        .is_some_and(|c| self.default_builds(&c.ty, target, seen)),
                    _ => false,
                }
            }
            _ => false,
        }
    }

    /// A value as a Rust expression of type `ty`. `konst`: in a `const` item (strings as `&str`).
    pub(super) fn value_expr(&self, v: &Value, ty: &Type, konst: bool) -> String {
        let resolved = self.model.resolve_alias(ty);
        let float = matches!(
            resolved,
            Type::Prim {
                prim: Prim::F32 | Prim::F64 | Prim::F128
            }
        );
        let f_ty = if matches!(resolved, Type::Prim { prim: Prim::F32 }) {
            "f32"
        } else {
            "f64"
        };
        match v {
            Value::Int(i) if float => format!("{i}.0"),
            Value::Int(i) => i.to_string(),
            Value::Float(f) if f.is_nan() => format!("{f_ty}::NAN"),
            Value::Float(f) if f.is_infinite() => {
                format!("{}{f_ty}::INFINITY", if *f < 0.0 { "-" } else { "" })
            }
            Value::Float(f) => format!("{f:?}"),
            Value::Char(c) => format!("{c:?}"),
            Value::WChar(c) if konst => format!("{c:?}"),
            Value::WChar(c) => format!("{}::cdr::WChar({})", self.opts.runtime_crate, *c as u32),
            Value::Str(s) | Value::WStr(s) | Value::Fixed(s) if konst => lit_str(s),
            Value::Str(s) | Value::WStr(s) | Value::Fixed(s) => {
                format!("::core::convert::From::from({})", lit_str(s))
            }
            Value::Bool(b) => b.to_string(),
            Value::Enum(d, i) => self.enumerator_path(*d, *i),
        }
    }
}
