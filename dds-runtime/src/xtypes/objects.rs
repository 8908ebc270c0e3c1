//! The type objects of one named type, from its lowered definition ([`Def`]), in the minimal or the complete
//! form.

use super::error::BuildError;
use super::shape::{Case, Def, Member, Shape};
use super::typeobject::*;
use crate::cdr::Extensibility;

/// Builds the body; `id` resolves a member type to its identifier (minimal or complete).
pub(super) fn body<'a>(
    mut id: impl FnMut(&'a Shape, bool) -> Result<TypeIdentifier, BuildError>,
    name: &str,
    def: &'a Def,
    complete: bool,
) -> Result<TypeBody, BuildError> {
    let detail = TypeDetail {
        ann_builtin: None,
        ann_custom: None,
        type_name: name.to_owned(),
    };
    Ok(match def {
        Def::Struct {
            extensibility,
            autoid_hash,
            nested,
            base,
            members,
        } => TypeBody::Struct {
            flags: type_flags(*extensibility, *autoid_hash, *nested),
            base: match base {
                Some(b) => id(b, complete)?,
                None => TypeIdentifier::None,
            },
            detail,
            members: members
                .iter()
                .map(|m| {
                    Ok(StructMember {
                        id: m.id,
                        flags: m.flags,
                        type_id: id(&m.ty, complete)?,
                        detail: member_detail(m),
                    })
                })
                .collect::<Result<_, BuildError>>()?,
        },
        Def::Union {
            extensibility,
            nested,
            discriminator,
            discriminator_key,
            cases,
        } => {
            let mut disc_flags = MemberFlag::IS_MUST_UNDERSTAND | MemberFlag::TRY_CONSTRUCT1;
            if *discriminator_key {
                disc_flags |= MemberFlag::IS_KEY;
            }
            let members = cases
                .iter()
                .map(|c| Ok(union_member(c, id(&c.ty, complete)?)))
                .collect::<Result<_, BuildError>>()?;
            TypeBody::Union {
                flags: type_flags(*extensibility, false, *nested),
                detail,
                disc_flags,
                disc_type: id(discriminator, complete)?,
                disc_ann_builtin: None,
                disc_ann_custom: None,
                members,
            }
        }
        Def::Enum {
            extensibility,
            bit_bound,
            literals,
        } => TypeBody::Enum {
            flags: type_flags(*extensibility, false, false),
            bit_bound: *bit_bound,
            detail,
            literals: enum_literals(literals),
        },
        Def::Bitmask {
            extensibility,
            bit_bound,
            flags,
        } => TypeBody::Bitmask {
            flags: type_flags(*extensibility, false, false),
            bit_bound: *bit_bound,
            detail,
            bitflags: bitmask_flags(flags),
        },
        Def::Alias(t) => TypeBody::Alias {
            flags: TypeFlag::empty(),
            detail,
            related_flags: MemberFlag::empty(),
            related_type: id(t, complete)?,
            ann_builtin: None,
            ann_custom: None,
        },
    })
}

/// A union case, its type identifier resolved.
fn union_member(c: &Case, type_id: TypeIdentifier) -> UnionMember {
    let mut flags = MemberFlag::TRY_CONSTRUCT1;
    flags.set(MemberFlag::IS_DEFAULT, c.is_default);
    flags.set(MemberFlag::IS_EXTERNAL, c.external);
    UnionMember {
        id: c.id,
        flags,
        type_id,
        labels: c.labels.clone(),
        detail: MemberDetail::named(c.name.as_str()),
    }
}

/// A bitmask's flags, sorted by position.
fn bitmask_flags(flags: &[(String, u16)]) -> Vec<Bitflag> {
    let mut bitflags: Vec<Bitflag> = flags
        .iter()
        .map(|(n, p)| Bitflag {
            position: *p,
            flags: MemberFlag::empty(),
            detail: MemberDetail::named(n.as_str()),
        })
        .collect();
    bitflags.sort_by_key(|f| f.position);
    bitflags
}

/// A struct member's detail: its name, and `@hashid` in the builtin annotations.
fn member_detail(m: &Member) -> MemberDetail {
    let mut detail = MemberDetail::named(m.name.as_str());
    if let Some(h) = &m.hash_id {
        detail.ann_builtin = Some(AppliedBuiltinMemberAnnotations {
            hash_id: Some(h.clone()),
            ..Default::default()
        });
    }
    detail
}

/// Enumerators sorted by value, the default one flagged.
fn enum_literals(literals: &[(String, i32, bool)]) -> Vec<EnumeratedLiteral> {
    let mut out: Vec<EnumeratedLiteral> = literals
        .iter()
        .map(|(n, v, d)| EnumeratedLiteral {
            value: *v,
            flags: if *d {
                MemberFlag::IS_DEFAULT
            } else {
                MemberFlag::empty()
            },
            detail: MemberDetail::named(n.as_str()),
        })
        .collect();
    out.sort_by_key(|l| l.value);
    out
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
