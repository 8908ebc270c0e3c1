//! What a Rust type says about its XTypes type: [`XTypesType`], implemented here for the primitives, strings and
//! collections and emitted by `#[derive(DdsType)]` for structs, unions, enums and bitmasks. A description is
//! cheap data with function pointers to the member types' descriptions (so recursive types describe
//! themselves lazily); [`super::TypeSupport`] turns it into type objects once per type.

use std::collections::BTreeMap;

use crate::cdr::{BoundedSeq, BoundedString, Extensibility, Fixed, LongDouble, WChar, WString};

use super::typeobject::kind::*;
use super::typeobject::MemberFlag;

/// A type with an XTypes description.
pub trait XTypesType {
    /// Describes the type. Cheap, but not meant for hot paths: [`super::TypeSupport`] caches what it builds.
    fn xtypes_desc() -> TypeDesc;

    /// The type's objects, identifiers, `TypeInformation` and `TypeMapping`, built once on first use; `None`
    /// for types that are not named (primitives, collections) or cannot be described (see
    /// [`super::BuildError`]). The derive implements it for named types.
    fn type_support() -> Option<&'static super::TypeSupport> {
        None
    }
}

/// A lazily described type: a function returning its [`TypeDesc`].
#[derive(Clone, Copy)]
pub struct TypeRef(pub fn() -> TypeDesc);

impl TypeRef {
    /// The reference to `T`'s description.
    pub fn of<T: XTypesType + ?Sized>() -> Self {
        TypeRef(T::xtypes_desc)
    }

    /// The description.
    pub fn desc(&self) -> TypeDesc {
        (self.0)()
    }
}

impl std::fmt::Debug for TypeRef {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("TypeRef")
    }
}

/// The description of one type.
#[derive(Debug, Clone)]
#[non_exhaustive]
pub enum TypeDesc {
    /// A primitive (`TK_*`).
    Primitive(u8),
    /// `string` (`wide`: `wstring`), 0 for unbounded.
    String {
        /// `wstring`.
        wide: bool,
        /// Bound, 0 for none.
        bound: u32,
    },
    /// `sequence<T, bound>`.
    Sequence {
        /// Bound, 0 for none.
        bound: u32,
        /// Element.
        element: TypeRef,
    },
    /// An array, all dimensions (outermost first) of a non-array element.
    Array {
        /// Dimensions.
        bounds: Vec<u32>,
        /// Element.
        element: TypeRef,
    },
    /// `map<K, V, bound>`.
    Map {
        /// Bound, 0 for none.
        bound: u32,
        /// Key.
        key: TypeRef,
        /// Value.
        value: TypeRef,
    },
    /// A named (constructed) type.
    Named(NamedRef),
    /// A type XTypes 1.3 cannot describe (`fixed`): types containing it get no type information.
    Unsupported(&'static str),
}

/// A named type: its scoped name and its definition.
#[derive(Clone, Copy)]
pub struct NamedRef {
    /// Scoped IDL name, `"Module::Type"`; identifies the type within one description.
    pub name: &'static str,
    /// The definition.
    pub def: fn() -> TypeDef,
}

impl std::fmt::Debug for NamedRef {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "NamedRef({})", self.name)
    }
}

/// The definition of a named type.
#[derive(Debug, Clone)]
#[non_exhaustive]
pub enum TypeDef {
    /// A struct.
    Struct(StructDef),
    /// A union.
    Union(UnionDef),
    /// An enum.
    Enum(EnumDef),
    /// A bitmask.
    Bitmask(BitmaskDef),
    /// A typedef.
    Alias(TypeRef),
}

/// A struct.
#[derive(Debug, Clone)]
pub struct StructDef {
    /// Extensibility.
    pub extensibility: Extensibility,
    /// `@autoid(HASH)`.
    pub autoid_hash: bool,
    /// `@nested` (IS_NESTED).
    pub nested: bool,
    /// The base struct.
    pub base: Option<TypeRef>,
    /// Own members (not the base's), in declaration order.
    pub members: Vec<MemberDef>,
}

/// A struct member.
#[derive(Debug, Clone)]
pub struct MemberDef {
    /// IDL name.
    pub name: &'static str,
    /// Member id.
    pub id: u32,
    /// Key, optional, external, must-understand; try-construct as below.
    pub flags: MemberFlag,
    /// The member's type (inside `Option` for optional members).
    pub ty: TypeRef,
    /// `@hashid` (its string, empty for the member name).
    pub hash_id: Option<&'static str>,
}

impl MemberDef {
    /// A member with Cyclone's default flags (`TRY_CONSTRUCT1`: discard) plus `flags`.
    pub fn new(name: &'static str, id: u32, flags: MemberFlag, ty: TypeRef) -> Self {
        MemberDef {
            name,
            id,
            flags: with_try_construct(flags),
            ty,
            hash_id: None,
        }
    }
}

/// `flags` with Cyclone's default try-construct (`TRY_CONSTRUCT1`: discard) unless they say `TRY_CONSTRUCT2`.
pub(crate) fn with_try_construct(flags: MemberFlag) -> MemberFlag {
    if flags.contains(MemberFlag::TRY_CONSTRUCT2) {
        flags
    } else {
        flags | MemberFlag::TRY_CONSTRUCT1
    }
}

/// A union.
#[derive(Debug, Clone)]
pub struct UnionDef {
    /// Extensibility.
    pub extensibility: Extensibility,
    /// `@nested` (IS_NESTED).
    pub nested: bool,
    /// Discriminator type.
    pub discriminator: TypeRef,
    /// The discriminator is a key.
    pub discriminator_key: bool,
    /// The cases.
    pub cases: Vec<CaseDef>,
}

/// A union case.
#[derive(Debug, Clone)]
pub struct CaseDef {
    /// IDL name.
    pub name: &'static str,
    /// Member id.
    pub id: u32,
    /// Labels (empty for `default` alone).
    pub labels: Vec<i32>,
    /// The `default` case.
    pub is_default: bool,
    /// The case's type (`None`: no member, not describable in XTypes and left out).
    pub ty: Option<TypeRef>,
    /// `@external`.
    pub external: bool,
}

/// An enum.
#[derive(Debug, Clone)]
pub struct EnumDef {
    /// Extensibility.
    pub extensibility: Extensibility,
    /// `@bit_bound`.
    pub bit_bound: u16,
    /// Enumerators: name, value, whether it is the default.
    pub literals: Vec<(&'static str, i32, bool)>,
}

/// A bitmask.
#[derive(Debug, Clone)]
pub struct BitmaskDef {
    /// Extensibility.
    pub extensibility: Extensibility,
    /// `@bit_bound`.
    pub bit_bound: u16,
    /// Flags: name, position.
    pub flags: Vec<(String, u16)>,
}

/// The description of `T` with an IDL bound applied to its outermost string, sequence or map (what
/// `#[dds(bound = N)]` means).
pub fn bounded_desc<T: XTypesType + ?Sized, const N: u32>() -> TypeDesc {
    with_bound(T::xtypes_desc(), N)
}

/// `desc` with the IDL bound `n` applied to its outermost string, sequence or map.
pub(crate) fn with_bound(desc: TypeDesc, n: u32) -> TypeDesc {
    match desc {
        TypeDesc::String { wide, .. } => TypeDesc::String { wide, bound: n },
        TypeDesc::Sequence { element, .. } => TypeDesc::Sequence { bound: n, element },
        TypeDesc::Map { key, value, .. } => TypeDesc::Map {
            bound: n,
            key,
            value,
        },
        other => other,
    }
}

/// An array of `n` elements of `element` (an array of arrays is one multi-dimensional array, as in IDL).
pub(crate) fn array_of(n: u32, element: TypeRef) -> TypeDesc {
    match element.desc() {
        TypeDesc::Array {
            mut bounds,
            element,
        } => {
            bounds.insert(0, n);
            TypeDesc::Array { bounds, element }
        }
        _ => TypeDesc::Array {
            bounds: vec![n],
            element,
        },
    }
}

macro_rules! primitive {
    ($($t:ty => $k:expr),* $(,)?) => {$(
        impl XTypesType for $t {
            fn xtypes_desc() -> TypeDesc {
                TypeDesc::Primitive($k)
            }
        }
    )*};
}

primitive! {
    bool => TK_BOOLEAN, u8 => TK_UINT8, i8 => TK_INT8, i16 => TK_INT16, u16 => TK_UINT16, i32 => TK_INT32,
    u32 => TK_UINT32, i64 => TK_INT64, u64 => TK_UINT64, f32 => TK_FLOAT32, f64 => TK_FLOAT64,
    char => TK_CHAR8, WChar => TK_CHAR16, LongDouble => TK_FLOAT128,
}

impl XTypesType for String {
    fn xtypes_desc() -> TypeDesc {
        TypeDesc::String {
            wide: false,
            bound: 0,
        }
    }
}

impl XTypesType for WString {
    fn xtypes_desc() -> TypeDesc {
        TypeDesc::String {
            wide: true,
            bound: 0,
        }
    }
}

impl<const N: usize> XTypesType for BoundedString<N> {
    fn xtypes_desc() -> TypeDesc {
        TypeDesc::String {
            wide: false,
            bound: N as u32,
        }
    }
}

impl<T: XTypesType> XTypesType for Vec<T> {
    fn xtypes_desc() -> TypeDesc {
        TypeDesc::Sequence {
            bound: 0,
            element: TypeRef::of::<T>(),
        }
    }
}

impl<T: XTypesType, const N: usize> XTypesType for BoundedSeq<T, N> {
    fn xtypes_desc() -> TypeDesc {
        TypeDesc::Sequence {
            bound: N as u32,
            element: TypeRef::of::<T>(),
        }
    }
}

impl<T: XTypesType, const N: usize> XTypesType for [T; N] {
    fn xtypes_desc() -> TypeDesc {
        array_of(N as u32, TypeRef::of::<T>())
    }
}

impl<K: XTypesType, V: XTypesType> XTypesType for BTreeMap<K, V> {
    fn xtypes_desc() -> TypeDesc {
        TypeDesc::Map {
            bound: 0,
            key: TypeRef::of::<K>(),
            value: TypeRef::of::<V>(),
        }
    }
}

impl<T: XTypesType> XTypesType for Box<T> {
    fn xtypes_desc() -> TypeDesc {
        T::xtypes_desc()
    }
}

impl<T: XTypesType> XTypesType for Option<T> {
    fn xtypes_desc() -> TypeDesc {
        T::xtypes_desc()
    }
}

impl<const D: u32, const S: u32> XTypesType for Fixed<D, S> {
    fn xtypes_desc() -> TypeDesc {
        TypeDesc::Unsupported("fixed<digits, scale> has no XTypes 1.3 type kind")
    }
}
