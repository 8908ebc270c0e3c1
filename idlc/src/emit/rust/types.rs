//! Type mapping IDL → Rust, and which traits a type can derive.
use super::Emitter;
use crate::ast::Prim;
use crate::model::{DeclId, DeclKind, Type};

/// Where a type appears: a struct field can carry `#[dds(bound = N)]`; anywhere else bounds must live in the
/// type (`BoundedString<N>`, `BoundedSeq<T, N>`).
#[derive(Clone, Copy, PartialEq, Eq)]
pub(super) enum Pos {
    Field,
    Nested,
}

impl Emitter<'_> {
    pub(super) fn prim(&self, p: Prim) -> String {
        let rt = &self.opts.runtime_crate;
        match p {
            Prim::Bool => "bool".into(),
            Prim::Octet | Prim::U8 => "u8".into(),
            Prim::Char => "char".into(),
            Prim::WChar => format!("{rt}::cdr::WChar"),
            Prim::I8 => "i8".into(),
            Prim::I16 => "i16".into(),
            Prim::U16 => "u16".into(),
            Prim::I32 => "i32".into(),
            Prim::U32 => "u32".into(),
            Prim::I64 => "i64".into(),
            Prim::U64 => "u64".into(),
            Prim::F32 => "f32".into(),
            Prim::F64 => "f64".into(),
            Prim::F128 => format!("{rt}::cdr::LongDouble"),
            Prim::Any | Prim::Object => "()".into(),
        }
    }

    /// `std` names, fully qualified where the module declares a type of the same name.
    pub(super) fn std(&self, short: &'static str) -> String {
        if !self.shadowed.contains(short) {
            return short.to_string();
        }
        match short {
            "String" => "::std::string::String".into(),
            "Vec" => "::std::vec::Vec".into(),
            "Option" => "::std::option::Option".into(),
            "Box" => "::std::boxed::Box".into(),
            "Default" => "::core::default::Default".into(),
            s => s.to_string(),
        }
    }

    /// The Rust spelling of a type, relative to the module being emitted.
    pub(super) fn rust_type(&self, t: &Type, pos: Pos) -> String {
        let rt = &self.opts.runtime_crate;
        match t {
            Type::Prim { prim } => self.prim(*prim),
            Type::String { wide: true, .. } => format!("{rt}::cdr::WString"),
            Type::String {
                wide: false,
                bound: Some(b),
            } if pos == Pos::Nested => format!("{rt}::cdr::BoundedString<{b}>"),
            Type::String { wide: false, .. } => self.std("String"),
            Type::Sequence { elem, bound } => {
                let e = self.rust_type(elem, Pos::Nested);
                match bound {
                    Some(b) if pos == Pos::Nested => format!("{rt}::cdr::BoundedSeq<{e}, {b}>"),
                    _ => format!("{}<{e}>", self.std("Vec")),
                }
            }
            Type::Map { key, value, .. } => {
                format!(
                    "::std::collections::BTreeMap<{}, {}>",
                    self.rust_type(key, Pos::Nested),
                    self.rust_type(value, Pos::Nested)
                )
            }
            Type::Array { elem, dims } => {
                let mut s = self.rust_type(elem, Pos::Nested);
                for d in dims.iter().rev() {
                    s = format!("[{s}; {d}]");
                }
                s
            }
            Type::Fixed { digits, scale } => format!("{rt}::cdr::Fixed<{digits}, {scale}>"),
            Type::Error => "()".into(),
            Type::Named { decl, .. } => {
                // An alias that hides a bound cannot carry it into a nested position: spell the bounded type.
                if pos == Pos::Nested {
                    let r = self.model.resolve_alias(t);
                    if matches!(
                        r,
                        Type::String {
                            wide: false,
                            bound: Some(_)
                        } | Type::Sequence { bound: Some(_), .. }
                    ) {
                        return self.rust_type(r, Pos::Nested);
                    }
                }
                self.path_to(*decl)
            }
        }
    }

    /// The bound to put on a field of this type (through aliases).
    pub(super) fn field_bound(&self, t: &Type) -> Option<u64> {
        match self.model.resolve_alias(t) {
            Type::String { bound, .. } | Type::Sequence { bound, .. } | Type::Map { bound, .. } => {
                *bound
            }
            _ => None,
        }
    }

    /// Whether `t` goes through a typedef that has an XTypes marker (then the member says so with
    /// `#[dds(xtypes = ...)]`, see [`Self::xtypes_type`]).
    pub(super) fn has_typedef(&self, t: &Type) -> bool {
        match t {
            Type::Named { decl, .. } => !self.typedef_markers[*decl].is_empty(),
            Type::Sequence { elem, .. } | Type::Array { elem, .. } => self.has_typedef(elem),
            Type::Map { key, value, .. } => self.has_typedef(key) || self.has_typedef(value),
            _ => false,
        }
    }

    /// Whether `t` has an XTypes description (`any`, `Object` and failed references have none).
    pub(super) fn describable(&self, t: &Type) -> bool {
        match t {
            Type::Prim { prim } => !matches!(prim, Prim::Any | Prim::Object),
            Type::Error => false,
            Type::Sequence { elem, .. } | Type::Array { elem, .. } => self.describable(elem),
            Type::Map { key, value, .. } => self.describable(key) && self.describable(value),
            Type::Named { decl, .. } => match &self.model.decls[*decl].kind {
                DeclKind::Alias { ty } => self.describable(ty),
                _ => true,
            },
            _ => true,
        }
    }

    /// The spelling of `t` in `#[dds(xtypes = ...)]` and in a typedef marker: typedefs by their markers,
    /// `octet` as `Octet`, every bound in the type.
    pub(super) fn xtypes_type(&self, t: &Type) -> String {
        let rt = &self.opts.runtime_crate;
        match t {
            Type::Prim { prim: Prim::Octet } => format!("{rt}::xtypes::Octet"),
            Type::String {
                wide: true,
                bound: Some(b),
            } => format!("{rt}::xtypes::Bounded<{rt}::cdr::WString, {b}>"),
            Type::Sequence { elem, bound } => {
                let e = self.xtypes_type(elem);
                match bound {
                    Some(b) => format!("{rt}::cdr::BoundedSeq<{e}, {b}>"),
                    None => format!("{}<{e}>", self.std("Vec")),
                }
            }
            Type::Map { key, value, bound } => {
                let m = format!(
                    "::std::collections::BTreeMap<{}, {}>",
                    self.xtypes_type(key),
                    self.xtypes_type(value)
                );
                match bound {
                    Some(b) => format!("{rt}::xtypes::Bounded<{m}, {b}>"),
                    None => m,
                }
            }
            Type::Array { elem, dims } => {
                let mut s = self.xtypes_type(elem);
                for d in dims.iter().rev() {
                    s = format!("[{s}; {d}]");
                }
                s
            }
            Type::Named { decl, .. } if !self.typedef_markers[*decl].is_empty() => {
                self.path_in(*decl, &self.typedef_markers[*decl])
            }
            Type::Named { decl, .. } => self.path_to(*decl),
            _ => self.rust_type(t, Pos::Nested),
        }
    }

    /// Whether `t` is IDL `octet` or a sequence or array (of sequences or arrays) of it, through typedefs:
    /// such a member carries `#[dds(octet)]`, so that its `u8` is described as `octet` (`TK_BYTE`), not
    /// `uint8`.
    pub(super) fn is_octet(&self, t: &Type) -> bool {
        match self.model.resolve_alias(t) {
            Type::Prim { prim } => *prim == Prim::Octet,
            Type::Sequence { elem, .. } | Type::Array { elem, .. } => self.is_octet(elem),
            _ => false,
        }
    }

    /// `Eq` and `Hash` are derivable (no floating point anywhere inside).
    fn eq_hash_in(&self, t: &Type, visiting: &mut Vec<DeclId>) -> bool {
        match t {
            // LongDouble is a byte carrier with Eq and Hash.
            Type::Prim { prim } => !matches!(prim, Prim::F32 | Prim::F64),
            Type::String { .. } | Type::Fixed { .. } | Type::Error => true,
            Type::Sequence { elem, .. } | Type::Array { elem, .. } => {
                self.eq_hash_in(elem, visiting)
            }
            Type::Map { key, value, .. } => {
                self.eq_hash_in(key, visiting) && self.eq_hash_in(value, visiting)
            }
            Type::Named { decl, .. } => self.decl_eq_hash(*decl, visiting),
        }
    }

    pub(super) fn decl_eq_hash(&self, id: DeclId, visiting: &mut Vec<DeclId>) -> bool {
        if let Some(v) = self.eq_cache.borrow().get(&id) {
            return *v;
        }
        if visiting.contains(&id) {
            return true; // recursion through a sequence: decided by the other members
        }
        visiting.push(id);
        let r = match &self.model.decls[id].kind {
            DeclKind::Struct(s) => {
                s.base.is_none_or(|b| self.decl_eq_hash(b, visiting))
                    && s.fields.iter().all(|f| self.eq_hash_in(&f.ty, visiting))
            }
            DeclKind::Union(u) => {
                self.eq_hash_in(&u.discriminator, visiting)
                    && u.cases.iter().all(|c| self.eq_hash_in(&c.ty, visiting))
            }
            DeclKind::Alias { ty } => self.eq_hash_in(ty, visiting),
            _ => true,
        };
        visiting.pop();
        if visiting.is_empty() {
            self.eq_cache.borrow_mut().insert(id, r);
        }
        r
    }

    /// `Default` holds for the type as spelled (arrays longer than 32 have no `Default`).
    pub(super) fn has_default(&self, t: &Type) -> bool {
        match t {
            Type::Array { elem, dims } => dims.iter().all(|d| *d <= 32) && self.has_default(elem),
            Type::Named { .. } => match self.model.resolve_alias(t) {
                r @ Type::Array { .. } => self.has_default(r),
                _ => true,
            },
            _ => true,
        }
    }

    /// An expression producing the default value of a type.
    pub(super) fn default_expr(&self, t: &Type) -> String {
        let t = match t {
            Type::Named { .. } if !self.has_default(t) => self.model.resolve_alias(t),
            _ => t,
        };
        match t {
            Type::Array { elem, dims } if !self.has_default(t) => {
                let inner = if dims.len() > 1 {
                    self.default_expr(&Type::Array {
                        elem: elem.clone(),
                        dims: dims[1..].to_vec(),
                    })
                } else {
                    self.default_expr(elem)
                };
                format!("::core::array::from_fn(|_| {inner})")
            }
            _ => format!("{}::default()", self.std("Default")),
        }
    }
}
