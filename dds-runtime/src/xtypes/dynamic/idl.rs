//! Dynamic types from IDL text (feature `idl`): idlc's front end (preprocess, parse, resolve, validate) gives
//! the resolved model, and each declaration becomes a [`DynamicType`] with the ids, flags and extensibility
//! the derive would give the Rust type idlc emits for it.

use std::collections::{BTreeMap, HashMap};
use std::path::Path;

use idlc::ast::Prim;
use idlc::driver::{Compilation, Options};
use idlc::model::{self, AutoId, DeclId, DeclKind, Model, Type};

use crate::cdr::Extensibility;

use super::builder::{BitmaskBuilder, EnumBuilder, MemberBuilder, StructBuilder, UnionBuilder};
use super::error::DynamicError;
use super::types::{close_forward, DynamicType, Primitive};

/// Why IDL text gave no types.
#[derive(Debug, Clone, thiserror::Error)]
#[non_exhaustive]
pub enum IdlError {
    /// The IDL has errors (idlc's diagnostics, rendered).
    #[error("IDL errors:\n{0}")]
    Compile(String),
    /// A declaration cannot be a dynamic type.
    #[error("{name}: {source}")]
    Type {
        /// The declaration.
        name: String,
        /// Why.
        source: DynamicError,
    },
}

/// Every struct, union, enum, bitmask and typedef of an IDL file, by scoped name (`Mod::Type`).
pub fn types_from_idl_file(
    path: &Path,
    opts: &Options,
) -> Result<BTreeMap<String, DynamicType>, IdlError> {
    convert(idlc::driver::compile_file(path, opts))
}

/// Every struct, union, enum, bitmask and typedef of IDL text (`name` is used in messages), by scoped name.
/// Options are idlc's defaults (`@appendable` when not annotated, as for the types idlc emits).
pub fn types_from_idl(name: &str, text: &str) -> Result<BTreeMap<String, DynamicType>, IdlError> {
    let files = idlc::preprocess::MemVfs::default();
    convert(idlc::driver::compile_str(
        name,
        text,
        &Options::default(),
        &files,
    ))
}

fn convert(mut c: Compilation) -> Result<BTreeMap<String, DynamicType>, IdlError> {
    if c.has_errors() {
        return Err(IdlError::Compile(c.render_diagnostics(Default::default())));
    }
    let mut conv = Converter {
        model: &c.model,
        done: HashMap::new(),
    };
    let mut out = BTreeMap::new();
    for (id, d) in c.model.decls.iter().enumerate() {
        let convertible = matches!(
            d.kind,
            DeclKind::Struct(_)
                | DeclKind::Union(_)
                | DeclKind::Enum(_)
                | DeclKind::Bitmask(_)
                | DeclKind::Alias { .. }
        );
        if !convertible {
            continue;
        }
        // A declaration that cannot be converted (`fixed`, `any`) is left out; using it is an error.
        if let Ok(t) = conv.decl(id, 0) {
            out.insert(d.scoped_name(), t);
        }
    }
    Ok(out)
}

/// Re-exported so that callers can set include directories and defines without depending on idlc.
pub use idlc::driver::Options as IdlOptions;

struct Converter<'a> {
    model: &'a Model,
    done: HashMap<DeclId, DynamicType>,
}

fn ext(e: model::Extensibility) -> Extensibility {
    match e {
        model::Extensibility::Final => Extensibility::Final,
        model::Extensibility::Appendable => Extensibility::Appendable,
        model::Extensibility::Mutable => Extensibility::Mutable,
    }
}

fn unsupported(what: &str) -> DynamicError {
    DynamicError::Unresolved(format!("{what} has no dynamic type"))
}

impl Converter<'_> {
    fn ty(&mut self, t: &Type, depth: u32) -> Result<DynamicType, DynamicError> {
        Ok(match t {
            Type::Prim { prim } => DynamicType::primitive(match prim {
                Prim::Bool => Primitive::Bool,
                Prim::Octet => Primitive::Byte,
                Prim::Char => Primitive::Char8,
                Prim::WChar => Primitive::Char16,
                Prim::I8 => Primitive::Int8,
                Prim::U8 => Primitive::UInt8,
                Prim::I16 => Primitive::Int16,
                Prim::U16 => Primitive::UInt16,
                Prim::I32 => Primitive::Int32,
                Prim::U32 => Primitive::UInt32,
                Prim::I64 => Primitive::Int64,
                Prim::U64 => Primitive::UInt64,
                Prim::F32 => Primitive::Float32,
                Prim::F64 => Primitive::Float64,
                Prim::F128 => Primitive::Float128,
                _ => return Err(unsupported("any/Object")),
            }),
            Type::String { wide, bound } => {
                let b = bound.map(|b| u32::try_from(b).unwrap_or(u32::MAX));
                if *wide {
                    DynamicType::wstring(b)
                } else {
                    DynamicType::string(b)
                }
            }
            Type::Sequence { elem, bound } => DynamicType::sequence(
                self.ty(elem, depth + 1)?,
                bound.map(|b| u32::try_from(b).unwrap_or(u32::MAX)),
            ),
            Type::Map { key, value, bound } => DynamicType::map(
                self.ty(key, depth + 1)?,
                self.ty(value, depth + 1)?,
                bound.map(|b| u32::try_from(b).unwrap_or(u32::MAX)),
            ),
            Type::Array { elem, dims } => DynamicType::array(
                self.ty(elem, depth + 1)?,
                dims.iter()
                    .map(|d| u32::try_from(*d).unwrap_or(u32::MAX))
                    .collect(),
            )?,
            Type::Fixed { .. } => return Err(unsupported("fixed")),
            Type::Named { decl, .. } => self.decl(*decl, depth + 1)?,
            Type::Error => return Err(unsupported("an unresolved type")),
        })
    }

    fn decl(&mut self, id: DeclId, depth: u32) -> Result<DynamicType, DynamicError> {
        if let Some(t) = self.done.get(&id) {
            return Ok(t.clone());
        }
        if depth > 64 {
            return Err(DynamicError::Unresolved(
                "recursive or too deeply nested types".into(),
            ));
        }
        let d = &self.model.decls[id];
        let name = d.scoped_name();
        let t = match &d.kind {
            DeclKind::Alias { ty } => DynamicType::alias(name, self.ty(ty, depth)?),
            DeclKind::Struct(_) | DeclKind::Union(_) => return self.recursive(id, name, depth),
            DeclKind::Enum(e) => {
                let mut b = EnumBuilder::new(name)
                    .default_literal(e.default_index)
                    .extensibility(ext(e.extensibility));
                if let Some(bb) = e.bit_bound {
                    b = b.bit_bound(bb as u16);
                }
                for l in &e.enumerators {
                    b = b.literal_value(&l.name, l.value as i32);
                }
                b.build()?
            }
            DeclKind::Bitmask(m) => {
                let mut b = BitmaskBuilder::new(name).bit_bound(m.bit_bound as u16);
                for f in &m.flags {
                    b = b.flag_at(&f.name, f.position as u16);
                }
                b.build()?
            }
            DeclKind::Bitset(b) => DynamicType::primitive(bitset_storage(b.bits)),
            _ => return Err(unsupported(&name)),
        };
        self.done.insert(id, t.clone());
        Ok(t)
    }

    /// A struct or union, which may refer back to itself (a recursive type): a reference met while its
    /// members are converted gets a forward reference, which the type then defines.
    fn recursive(
        &mut self,
        id: DeclId,
        name: String,
        depth: u32,
    ) -> Result<DynamicType, DynamicError> {
        let forward = DynamicType::forward(name.clone());
        self.done.insert(id, forward.clone());
        let t = match &self.model.decls[id].kind {
            DeclKind::Struct(s) => self.structure(name, s, depth),
            DeclKind::Union(u) => self.union(name, u, depth),
            _ => Err(unsupported(&name)),
        };
        match &t {
            Ok(t) => {
                self.done.insert(id, t.clone());
                close_forward(forward, t)?;
            }
            Err(_) => {
                self.done.remove(&id);
            }
        }
        t
    }

    fn structure(
        &mut self,
        name: String,
        s: &model::Struct,
        depth: u32,
    ) -> Result<DynamicType, DynamicError> {
        let mut b = StructBuilder::new(name).extensibility(ext(s.extensibility));
        if s.autoid == AutoId::Hash {
            b = b.autoid_hash();
        }
        if s.nested {
            b = b.nested();
        }
        if let Some(base) = s.base {
            b = b.base(self.decl(base, depth + 1)?);
        }
        for f in s.fields.iter().filter(|f| !f.non_serialized) {
            let mut m = MemberBuilder::new(&f.name, self.ty(&f.ty, depth + 1)?);
            m = match (&f.id, &f.hashid) {
                (Some(id), _) => m.id(*id),
                (None, Some(h)) => m.hash_id_of(h),
                (None, None) => m,
            };
            if f.default.is_some() {
                m = m.use_default();
            }
            if f.key {
                m = m.key();
            }
            if f.optional {
                m = m.optional();
            }
            if f.external {
                m = m.external();
            }
            if f.must_understand {
                m = m.must_understand();
            }
            b = b.with(m);
        }
        b.build()
    }

    fn union(
        &mut self,
        name: String,
        u: &model::Union,
        depth: u32,
    ) -> Result<DynamicType, DynamicError> {
        let mut b = UnionBuilder::new(name, self.ty(&u.discriminator, depth + 1)?)
            .extensibility(ext(u.extensibility));
        if u.disc_key {
            b = b.key();
        }
        if u.nested {
            b = b.nested();
        }
        for c in &u.cases {
            let mut labels = Vec::with_capacity(c.labels.len());
            for l in &c.labels {
                labels.push(self.label(l)?);
            }
            b = b.case_with(
                &c.name,
                self.ty(&c.ty, depth + 1)?,
                labels,
                c.is_default,
                c.id,
            );
        }
        b.build()
    }

    fn label(&self, v: &model::Value) -> Result<i64, DynamicError> {
        Ok(match v {
            model::Value::Int(i) => {
                i64::try_from(*i).map_err(|_| unsupported("a label out of range"))?
            }
            model::Value::Char(c) | model::Value::WChar(c) => i64::from(u32::from(*c)),
            model::Value::Bool(b) => i64::from(*b),
            model::Value::Enum(decl, idx) => match &self.model.decls[*decl].kind {
                DeclKind::Enum(e) => e.enumerators.get(*idx).map_or(0, |l| l.value),
                _ => return Err(unsupported("a label")),
            },
            _ => return Err(unsupported("a label")),
        })
    }
}

/// A bitset is the unsigned integer that holds its bits, as idlc's generated code (a `#[dds(transparent)]`
/// newtype over `u8`..`u64`) is on the wire and in the type objects: its fields are accessors, not members, so
/// the dynamic type (and its `to_idl`) has the integer, not the fields.
fn bitset_storage(bits: u32) -> Primitive {
    match bits {
        0..=8 => Primitive::UInt8,
        9..=16 => Primitive::UInt16,
        17..=32 => Primitive::UInt32,
        _ => Primitive::UInt64,
    }
}
