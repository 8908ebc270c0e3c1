//! IDL `octet` for Rust `u8` (what `#[dds(octet)]` means): Rust has one `u8` for IDL `octet` and `uint8`, and
//! [`XTypesType`] describes `u8` as `uint8` (`TK_UINT8`, new in XTypes 1.3). A member marked `octet` is
//! described with `TK_BYTE` instead, through every sequence, array, option and box around the `u8`, as Cyclone
//! DDS describes IDL `octet`. Both kinds have the same serialized form, so only the type objects differ.

use crate::cdr::BoundedSeq;

use super::describe::{array_of, with_bound, TypeDesc, TypeRef, XTypesType};
use super::typeobject::kind::TK_BYTE;

/// A type built of `u8` whose description can say `octet` (see the module doc).
pub trait OctetType: XTypesType {
    /// The description with `octet` (`TK_BYTE`) for `u8`.
    fn octet_desc() -> TypeDesc;
}

impl OctetType for u8 {
    fn octet_desc() -> TypeDesc {
        TypeDesc::Primitive(TK_BYTE)
    }
}

impl<T: OctetType> OctetType for Vec<T> {
    fn octet_desc() -> TypeDesc {
        TypeDesc::Sequence {
            bound: 0,
            element: TypeRef(T::octet_desc),
        }
    }
}

impl<T: OctetType, const N: usize> OctetType for BoundedSeq<T, N> {
    fn octet_desc() -> TypeDesc {
        TypeDesc::Sequence {
            bound: N as u32,
            element: TypeRef(T::octet_desc),
        }
    }
}

impl<T: OctetType, const N: usize> OctetType for [T; N] {
    fn octet_desc() -> TypeDesc {
        array_of(N as u32, TypeRef(T::octet_desc))
    }
}

impl<T: OctetType> OctetType for Option<T> {
    fn octet_desc() -> TypeDesc {
        T::octet_desc()
    }
}

impl<T: OctetType> OctetType for Box<T> {
    fn octet_desc() -> TypeDesc {
        T::octet_desc()
    }
}

/// [`OctetType::octet_desc`] of `T` (what `#[dds(octet)]` means).
pub fn octet_desc<T: OctetType + ?Sized>() -> TypeDesc {
    T::octet_desc()
}

/// [`octet_desc`] with the IDL bound `N` on the outermost sequence (`#[dds(octet, bound = N)]`).
pub fn bounded_octet_desc<T: OctetType + ?Sized, const N: u32>() -> TypeDesc {
    with_bound(T::octet_desc(), N)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::xtypes::typeobject::kind::TK_UINT8;

    fn element(d: TypeDesc) -> TypeDesc {
        match d {
            TypeDesc::Sequence { element, .. } | TypeDesc::Array { element, .. } => element.desc(),
            other => panic!("not a collection: {other:?}"),
        }
    }

    #[test]
    fn octet_reaches_through_collections() {
        assert!(matches!(u8::xtypes_desc(), TypeDesc::Primitive(TK_UINT8)));
        assert!(matches!(octet_desc::<u8>(), TypeDesc::Primitive(TK_BYTE)));
        assert!(matches!(
            element(octet_desc::<Vec<u8>>()),
            TypeDesc::Primitive(TK_BYTE)
        ));
        assert!(matches!(
            element(element(octet_desc::<Vec<Vec<u8>>>())),
            TypeDesc::Primitive(TK_BYTE)
        ));
        match octet_desc::<[[u8; 3]; 2]>() {
            TypeDesc::Array { bounds, element } => {
                assert_eq!(bounds, vec![2, 3]);
                assert!(matches!(element.desc(), TypeDesc::Primitive(TK_BYTE)));
            }
            other => panic!("{other:?}"),
        }
        assert!(matches!(
            bounded_octet_desc::<Vec<u8>, 16>(),
            TypeDesc::Sequence { bound: 16, .. }
        ));
        assert!(matches!(
            octet_desc::<Option<Box<u8>>>(),
            TypeDesc::Primitive(TK_BYTE)
        ));
    }
}
