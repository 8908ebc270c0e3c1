//! The type objects of one named type, from its [`TypeDef`], in the minimal or the complete form.

use super::describe::{TypeDef, TypeRef};
use super::error::BuildError;
use super::typeobject::*;
use crate::cdr::Extensibility;

/// Builds the body; `id` resolves a member type to its identifier (minimal or complete).
pub(super) fn body(
    mut id: impl FnMut(&TypeRef, bool) -> Result<TypeIdentifier, BuildError>,
    name: &'static str,
    def: &TypeDef,
    complete: bool,
) -> Result<TypeBody, BuildError> {
    let detail = TypeDetail {
        ann_builtin: None,
        ann_custom: None,
        type_name: name.to_owned(),
    };
    Ok(match def {
        TypeDef::Struct(s) => TypeBody::Struct {
            flags: type_flags(s.extensibility, s.autoid_hash, s.nested),
            base: match &s.base {
                Some(b) => id(b, complete)?,
                None => TypeIdentifier::None,
            },
            detail,
            members: s
                .members
                .iter()
                .map(|m| {
                    let mut detail = MemberDetail::named(m.name);
                    if let Some(h) = m.hash_id {
                        detail.ann_builtin = Some(AppliedBuiltinMemberAnnotations {
                            hash_id: Some(h.to_owned()),
                            ..Default::default()
                        });
                    }
                    Ok(StructMember {
                        id: m.id,
                        flags: m.flags,
                        type_id: id(&m.ty, complete)?,
                        detail,
                    })
                })
                .collect::<Result<_, BuildError>>()?,
        },
        TypeDef::Union(u) => {
            let mut disc_flags = MemberFlag::IS_MUST_UNDERSTAND | MemberFlag::TRY_CONSTRUCT1;
            if u.discriminator_key {
                disc_flags |= MemberFlag::IS_KEY;
            }
            let mut members = Vec::new();
            for c in &u.cases {
                let Some(ty) = &c.ty else { continue };
                let mut flags = MemberFlag::TRY_CONSTRUCT1;
                flags.set(MemberFlag::IS_DEFAULT, c.is_default);
                flags.set(MemberFlag::IS_EXTERNAL, c.external);
                members.push(UnionMember {
                    id: c.id,
                    flags,
                    type_id: id(ty, complete)?,
                    labels: c.labels.clone(),
                    detail: MemberDetail::named(c.name),
                });
            }
            TypeBody::Union {
                flags: type_flags(u.extensibility, false, u.nested),
                detail,
                disc_flags,
                disc_type: id(&u.discriminator, complete)?,
                disc_ann_builtin: None,
                disc_ann_custom: None,
                members,
            }
        }
        TypeDef::Enum(e) => {
            let mut literals: Vec<EnumeratedLiteral> = e
                .literals
                .iter()
                .map(|(n, v, d)| EnumeratedLiteral {
                    value: *v,
                    flags: if *d {
                        MemberFlag::IS_DEFAULT
                    } else {
                        MemberFlag::empty()
                    },
                    detail: MemberDetail::named(*n),
                })
                .collect();
            literals.sort_by_key(|l| l.value);
            TypeBody::Enum {
                flags: type_flags(e.extensibility, false, false),
                bit_bound: e.bit_bound,
                detail,
                literals,
            }
        }
        TypeDef::Bitmask(b) => {
            let mut bitflags: Vec<Bitflag> = b
                .flags
                .iter()
                .map(|(n, p)| Bitflag {
                    position: *p,
                    flags: MemberFlag::empty(),
                    detail: MemberDetail::named(n.clone()),
                })
                .collect();
            bitflags.sort_by_key(|f| f.position);
            TypeBody::Bitmask {
                flags: type_flags(b.extensibility, false, false),
                bit_bound: b.bit_bound,
                detail,
                bitflags,
            }
        }
        TypeDef::Alias(t) => TypeBody::Alias {
            flags: TypeFlag::empty(),
            detail,
            related_flags: MemberFlag::empty(),
            related_type: id(t, complete)?,
            ann_builtin: None,
            ann_custom: None,
        },
    })
}

/// The type flags of an extensibility, `@autoid(HASH)` and `@nested`.
fn type_flags(ext: Extensibility, autoid_hash: bool, nested: bool) -> TypeFlag {
    let mut f = match ext {
        Extensibility::Final => TypeFlag::IS_FINAL,
        Extensibility::Appendable => TypeFlag::IS_APPENDABLE,
        Extensibility::Mutable => TypeFlag::IS_MUTABLE,
    };
    if autoid_hash {
        f |= TypeFlag::IS_AUTOID_HASH;
    }
    if nested {
        f |= TypeFlag::IS_NESTED;
    }
    f
}
