//! IDL typedefs in type objects. Rust writes a typedef as a type alias (`type MyLong = i32;`), which a derive
//! cannot see, yet XTypes describes a member of typedef type through the typedef (a `TK_ALIAS` object named
//! after it), and Cyclone DDS does so: a struct using `MyLong` and one using `long` have different type
//! identifiers. A member says which typedefs its type goes through with `#[dds(xtypes = T)]`, where `T` is a
//! Rust type built of [`typedef!`](crate::typedef) markers, [`Octet`], [`Bounded`] and the usual
//! collections; the derive then describes the member as `T`, and encodes it as its Rust type, as before.

use std::marker::PhantomData;

use super::describe::{with_bound, TypeDesc, XTypesType};
use super::typeobject::kind::TK_BYTE;

/// IDL `octet` in a `#[dds(xtypes = ...)]` description (`u8` is described as `uint8`).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Hash)]
pub struct Octet;

impl XTypesType for Octet {
    fn xtypes_desc() -> TypeDesc {
        TypeDesc::Primitive(TK_BYTE)
    }
}

/// `T` (a string, sequence or map) with the IDL bound `N`, in a `#[dds(xtypes = ...)]` description:
/// `Bounded<BTreeMap<K, V>, 8>` is `map<K, V, 8>`. [`BoundedString`](crate::cdr::BoundedString) and
/// [`BoundedSeq`](crate::cdr::BoundedSeq) say the same for strings and sequences.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Hash)]
pub struct Bounded<T: ?Sized, const N: usize>(PhantomData<T>);

impl<T: XTypesType + ?Sized, const N: usize> XTypesType for Bounded<T, N> {
    fn xtypes_desc() -> TypeDesc {
        with_bound(T::xtypes_desc(), N as u32)
    }
}

/// Declares the XTypes description of an IDL typedef: a marker type that a member's `#[dds(xtypes = ...)]`
/// names where the member's type goes through the typedef (see `docs/derive.md`).
///
/// `typedef!(pub MyLongDef = "Golden::MyLong" => i32);` stands for IDL `typedef long MyLong;` in module
/// `Golden`. The target is written as in `#[dds(xtypes = ...)]`, so a typedef of a typedef names the other
/// marker: `typedef!(pub LongsDef = "Golden::Longs" => Vec<MyLongDef>);`.
#[macro_export]
macro_rules! typedef {
    ($(#[$meta:meta])* $vis:vis $marker:ident = $name:literal => $target:ty $(;)?) => {
        $(#[$meta])*
        #[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Hash)]
        $vis struct $marker;

        impl $crate::xtypes::XTypesType for $marker {
            fn xtypes_desc() -> $crate::xtypes::TypeDesc {
                fn def() -> $crate::xtypes::TypeDef {
                    $crate::xtypes::TypeDef::Alias($crate::xtypes::TypeRef::of::<$target>())
                }
                $crate::xtypes::TypeDesc::Named($crate::xtypes::NamedRef { name: $name, def })
            }
        }
    };
}

#[cfg(test)]
mod tests {
    use std::collections::BTreeMap;

    use super::*;
    use crate::xtypes::TypeDef;

    crate::typedef!(MyLong = "M::MyLong" => i32);
    crate::typedef!(Longs = "M::Longs" => Bounded<Vec<MyLong>, 4>);

    #[test]
    fn a_typedef_is_a_named_alias_of_its_target() {
        let TypeDesc::Named(n) = Longs::xtypes_desc() else {
            panic!("not named")
        };
        assert_eq!(n.name, "M::Longs");
        let TypeDef::Alias(target) = (n.def)() else {
            panic!("not an alias")
        };
        let TypeDesc::Sequence { bound: 4, element } = target.desc() else {
            panic!("not a sequence of 4")
        };
        assert!(matches!(element.desc(), TypeDesc::Named(n) if n.name == "M::MyLong"));
        assert!(matches!(
            Bounded::<BTreeMap<Octet, i32>, 3>::xtypes_desc(),
            TypeDesc::Map { bound: 3, .. }
        ));
    }
}
