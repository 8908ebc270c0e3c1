//! XTypes 1.3: the type system ([`typeobject`]), what a Rust type says about itself ([`XTypesType`], emitted by
//! `#[derive(DdsType)]`), and the per-type [`TypeInformation`]/[`typeobject::TypeMapping`] built from it.

pub mod typeobject;

/// The XCDR2-serialized `TypeInformation` (PID_TYPE_INFORMATION, 0x0075), kept verbatim: what SEDP carries.
/// [`TypeInformation::decode`] gives the structured [`typeobject::TypeInformation`].
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct TypeInformation(pub Vec<u8>);

impl TypeInformation {
    /// The serialized bytes, as received or to be announced.
    pub fn as_bytes(&self) -> &[u8] {
        &self.0
    }

    /// Decodes the bytes (bounded; hostile input is an error).
    pub fn decode(&self) -> Result<typeobject::TypeInformation, crate::cdr::DecodeError> {
        typeobject::from_bytes(&self.0)
    }
}

mod build;
mod describe;
mod error;
mod objects;

pub use build::TypeSupport;
pub use describe::{
    bounded_desc, BitmaskDef, CaseDef, EnumDef, MemberDef, NamedRef, StructDef, TypeDef, TypeDesc,
    TypeRef, UnionDef, XTypesType,
};
pub use error::BuildError;
