//! Builders of named dynamic types: structs, unions, enums and bitmasks.

use crate::cdr::Extensibility;

use super::error::DynamicError;
use super::types::{
    BitFlag, BitmaskType, DynamicType, EnumType, Enumerator, Member, StructType, TypeKind,
    UnionCase, UnionType,
};

/// A member of a struct being built; [`MemberBuilder::new`] then the flags.
#[derive(Debug, Clone)]
pub struct MemberBuilder {
    name: String,
    ty: DynamicType,
    id: Option<u32>,
    hash_id: Option<String>,
    key: bool,
    optional: bool,
    external: bool,
    must_understand: bool,
    use_default: bool,
}

impl MemberBuilder {
    /// A plain member.
    pub fn new(name: impl Into<String>, ty: DynamicType) -> Self {
        MemberBuilder {
            name: name.into(),
            ty,
            id: None,
            hash_id: None,
            key: false,
            optional: false,
            external: false,
            must_understand: false,
            use_default: false,
        }
    }

    /// `@id(id)`.
    pub fn id(mut self, id: u32) -> Self {
        self.id = Some(id);
        self
    }

    /// `@hashid`: the id is the hash of the member name.
    pub fn hash_id(mut self) -> Self {
        self.hash_id = Some(String::new());
        self
    }

    /// `@hashid("s")`: the id is the hash of `s`.
    pub fn hash_id_of(mut self, s: impl Into<String>) -> Self {
        self.hash_id = Some(s.into());
        self
    }

    /// `@default(...)`: a reader that lacks the member takes its default (TRY_CONSTRUCT2 in the type object;
    /// the value itself is not kept).
    pub fn use_default(mut self) -> Self {
        self.use_default = true;
        self
    }

    /// `@key`.
    pub fn key(mut self) -> Self {
        self.key = true;
        self
    }

    /// `@optional`.
    pub fn optional(mut self) -> Self {
        self.optional = true;
        self
    }

    /// `@external`.
    pub fn external(mut self) -> Self {
        self.external = true;
        self
    }

    /// `@must_understand`.
    pub fn must_understand(mut self) -> Self {
        self.must_understand = true;
        self
    }
}

/// The member id `@hashid` / `@autoid(HASH)` gives a name: the MD5 of the name, little endian, 28 bits.
pub fn hash_member_id(name: &str) -> u32 {
    u32::from_le_bytes(crate::xtypes::typeobject::name_hash(name)) & 0x0fff_ffff
}

/// Builds a [`StructType`].
#[derive(Debug, Clone)]
pub struct StructBuilder {
    name: String,
    extensibility: Extensibility,
    base: Option<DynamicType>,
    autoid_hash: bool,
    nested: bool,
    members: Vec<MemberBuilder>,
}

impl StructBuilder {
    /// An empty `@appendable` struct (IDL's default extensibility).
    pub fn new(name: impl Into<String>) -> Self {
        StructBuilder {
            name: name.into(),
            extensibility: Extensibility::Appendable,
            base: None,
            autoid_hash: false,
            nested: false,
            members: Vec::new(),
        }
    }

    /// `@final`, `@appendable` or `@mutable`.
    pub fn extensibility(mut self, e: Extensibility) -> Self {
        self.extensibility = e;
        self
    }

    /// The base struct (its members come first).
    pub fn base(mut self, base: DynamicType) -> Self {
        self.base = Some(base);
        self
    }

    /// `@autoid(HASH)`: members without `@id` get the hash of their name.
    pub fn autoid_hash(mut self) -> Self {
        self.autoid_hash = true;
        self
    }

    /// `@nested`: not meant as a topic type (IS_NESTED in the type object).
    pub fn nested(mut self) -> Self {
        self.nested = true;
        self
    }

    /// Adds a plain member.
    pub fn member(self, name: impl Into<String>, ty: DynamicType) -> Self {
        self.with(MemberBuilder::new(name, ty))
    }

    /// Adds a member with flags.
    pub fn with(mut self, m: MemberBuilder) -> Self {
        self.members.push(m);
        self
    }

    /// The struct. Ids not given continue from the previous member's (the base's last one + 1 first).
    pub fn build(self) -> Result<DynamicType, DynamicError> {
        let (mut members, mut levels) = match &self.base {
            None => (Vec::new(), Vec::new()),
            Some(b) => match b.resolved().kind() {
                TypeKind::Struct(s) => (s.members.clone(), s.levels.clone()),
                _ => {
                    return Err(DynamicError::Invalid(format!(
                        "base of {} is not a struct",
                        self.name
                    )))
                }
            },
        };
        let mut next = members.last().map_or(0, |m: &Member| m.id + 1);
        for m in self.members {
            let id = match (m.id, m.hash_id.as_deref()) {
                (Some(id), _) => id,
                (None, Some(h)) if !h.is_empty() => hash_member_id(h),
                (None, Some(_)) => hash_member_id(&m.name),
                (None, None) if self.autoid_hash => hash_member_id(&m.name),
                (None, None) => next,
            };
            if id > 0x0fff_ffff {
                return Err(DynamicError::Invalid(format!(
                    "member id {id:#x} of {}",
                    m.name
                )));
            }
            if members.iter().any(|x| x.name == m.name || x.id == id) {
                return Err(DynamicError::Invalid(format!(
                    "{}: member {} repeats a name or id",
                    self.name, m.name
                )));
            }
            next = id + 1;
            members.push(Member {
                name: m.name,
                id,
                ty: m.ty,
                key: m.key,
                optional: m.optional,
                external: m.external,
                must_understand: m.must_understand,
                hash_id: m.hash_id,
                use_default: m.use_default,
            });
        }
        levels.push(members.len());
        Ok(DynamicType::new(TypeKind::Struct(StructType {
            name: self.name,
            extensibility: self.extensibility,
            base: self.base,
            members,
            autoid_hash: self.autoid_hash,
            nested: self.nested,
            levels,
        })))
    }
}

/// Builds a [`UnionType`].
#[derive(Debug, Clone)]
pub struct UnionBuilder {
    name: String,
    extensibility: Extensibility,
    discriminator: DynamicType,
    disc_key: bool,
    nested: bool,
    /// The cases, each with its explicit id (the others are numbered in `build`, by the extensibility).
    cases: Vec<(UnionCase, Option<u32>)>,
}

impl UnionBuilder {
    /// An empty `@appendable` union with this discriminator type.
    pub fn new(name: impl Into<String>, discriminator: DynamicType) -> Self {
        UnionBuilder {
            name: name.into(),
            extensibility: Extensibility::Appendable,
            discriminator,
            disc_key: false,
            nested: false,
            cases: Vec::new(),
        }
    }

    /// `@final`, `@appendable` or `@mutable`.
    pub fn extensibility(mut self, e: Extensibility) -> Self {
        self.extensibility = e;
        self
    }

    /// `@key` on the discriminator.
    pub fn key(mut self) -> Self {
        self.disc_key = true;
        self
    }

    /// `@nested`: not meant as a topic type (IS_NESTED in the type object).
    pub fn nested(mut self) -> Self {
        self.nested = true;
        self
    }

    /// Adds a case with its labels; ids are numbered as [`UnionType::first_member_id`] says.
    pub fn case(self, name: impl Into<String>, ty: DynamicType, labels: Vec<i64>) -> Self {
        self.case_with(name, ty, labels, false, None)
    }

    /// Adds the `default` case (it may have labels too).
    pub fn default_case(self, name: impl Into<String>, ty: DynamicType, labels: Vec<i64>) -> Self {
        self.case_with(name, ty, labels, true, None)
    }

    /// Adds a case with every detail: whether it is the default, and an explicit id.
    pub fn case_with(
        mut self,
        name: impl Into<String>,
        ty: DynamicType,
        labels: Vec<i64>,
        is_default: bool,
        id: Option<u32>,
    ) -> Self {
        let case = UnionCase {
            name: name.into(),
            id: 0,
            ty,
            labels,
            is_default,
            external: false,
        };
        self.cases.push((case, id));
        self
    }

    /// The union.
    pub fn build(self) -> Result<DynamicType, DynamicError> {
        let ok = match self.discriminator.resolved().kind() {
            TypeKind::Enum(_) => true,
            TypeKind::Primitive(p) => !matches!(
                p,
                super::Primitive::Float32 | super::Primitive::Float64 | super::Primitive::Float128
            ),
            _ => false,
        };
        if !ok {
            return Err(DynamicError::Invalid(format!(
                "{}: discriminator {} is not an integer, boolean, char or enum",
                self.name,
                self.discriminator.name()
            )));
        }
        if self.cases.iter().filter(|(c, _)| c.is_default).count() > 1 {
            return Err(DynamicError::Invalid(format!(
                "{}: two default cases",
                self.name
            )));
        }
        Ok(DynamicType::new(TypeKind::Union(UnionType {
            name: self.name,
            extensibility: self.extensibility,
            discriminator: self.discriminator,
            disc_key: self.disc_key,
            cases: number_cases(self.cases, self.extensibility),
            nested: self.nested,
        })))
    }
}

/// Gives the cases without an explicit id the next one: from [`UnionType::first_member_id`], and after an
/// explicit id from that id.
fn number_cases(cases: Vec<(UnionCase, Option<u32>)>, ext: Extensibility) -> Vec<UnionCase> {
    let mut next = UnionType::first_member_id(ext);
    cases
        .into_iter()
        .map(|(mut c, id)| {
            c.id = id.unwrap_or(next);
            next = c.id.wrapping_add(1);
            c
        })
        .collect()
}

/// Builds an [`EnumType`].
#[derive(Debug, Clone)]
pub struct EnumBuilder {
    ty: EnumType,
}

impl EnumBuilder {
    /// An empty enum (`@bit_bound(32)`).
    pub fn new(name: impl Into<String>) -> Self {
        EnumBuilder {
            ty: EnumType {
                name: name.into(),
                bit_bound: 32,
                literals: Vec::new(),
                default: 0,
                extensibility: Extensibility::Final,
            },
        }
    }

    /// `@bit_bound(n)`.
    pub fn bit_bound(mut self, n: u16) -> Self {
        self.ty.bit_bound = n;
        self
    }

    /// `@final`, `@appendable` or `@mutable` (in the type object only).
    pub fn extensibility(mut self, e: Extensibility) -> Self {
        self.ty.extensibility = e;
        self
    }

    /// Adds an enumerator with the value after the previous one (0 first).
    pub fn literal(self, name: impl Into<String>) -> Self {
        let v = self
            .ty
            .literals
            .last()
            .map_or(0, |l| l.value.wrapping_add(1));
        self.literal_value(name, v)
    }

    /// Adds an enumerator with an explicit `@value`.
    pub fn literal_value(mut self, name: impl Into<String>, value: i32) -> Self {
        self.ty.literals.push(Enumerator {
            name: name.into(),
            value,
        });
        self
    }

    /// `@default_literal` on the enumerator at `index`.
    pub fn default_literal(mut self, index: usize) -> Self {
        self.ty.default = index;
        self
    }

    /// The enum.
    pub fn build(self) -> Result<DynamicType, DynamicError> {
        let t = self.ty;
        if t.literals.is_empty()
            || t.default >= t.literals.len()
            || !(1..=32).contains(&t.bit_bound)
        {
            return Err(DynamicError::Invalid(format!(
                "enum {}: no enumerators or a bad bit bound",
                t.name
            )));
        }
        Ok(DynamicType::new(TypeKind::Enum(t)))
    }
}

/// Builds a [`BitmaskType`].
#[derive(Debug, Clone)]
pub struct BitmaskBuilder {
    ty: BitmaskType,
}

impl BitmaskBuilder {
    /// An empty bitmask (`@bit_bound(32)`).
    pub fn new(name: impl Into<String>) -> Self {
        BitmaskBuilder {
            ty: BitmaskType {
                name: name.into(),
                bit_bound: 32,
                flags: Vec::new(),
                extensibility: Extensibility::Final,
            },
        }
    }

    /// `@bit_bound(n)`.
    pub fn bit_bound(mut self, n: u16) -> Self {
        self.ty.bit_bound = n;
        self
    }

    /// `@final`, `@appendable` or `@mutable` (in the type object only).
    pub fn extensibility(mut self, e: Extensibility) -> Self {
        self.ty.extensibility = e;
        self
    }

    /// Adds a flag at the position after the previous one (0 first).
    pub fn flag(self, name: impl Into<String>) -> Self {
        let p = self.ty.flags.last().map_or(0, |f| f.position + 1);
        self.flag_at(name, p)
    }

    /// Adds a flag at an explicit `@position`.
    pub fn flag_at(mut self, name: impl Into<String>, position: u16) -> Self {
        self.ty.flags.push(BitFlag {
            name: name.into(),
            position,
        });
        self
    }

    /// The bitmask.
    pub fn build(self) -> Result<DynamicType, DynamicError> {
        let t = self.ty;
        if !(1..=64).contains(&t.bit_bound) || t.flags.iter().any(|f| f.position >= t.bit_bound) {
            return Err(DynamicError::Invalid(format!(
                "bitmask {}: a flag lies past the bit bound",
                t.name
            )));
        }
        Ok(DynamicType::new(TypeKind::Bitmask(t)))
    }
}
