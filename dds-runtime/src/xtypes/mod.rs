//! XTypes 1.3: the type system ([`typeobject`]), what a Rust type says about itself ([`XTypesType`], emitted by
//! `#[derive(DdsType)]`), and the per-type [`TypeInformation`]/[`typeobject::TypeMapping`] built from it.

pub mod assign;
pub mod typeobject;

/// Environment variable that turns on `PID_TYPE_INFORMATION` in SEDP (`on`, `1` or `true`).
pub const ANNOUNCE_ENV: &str = "DDS_TYPE_INFORMATION";

/// Whether endpoints announce their type information: opt-in through [`ANNOUNCE_ENV`] until the TypeLookup
/// service exists, because a peer that receives a type id it cannot resolve (Cyclone DDS 0.10's `ddsperf`, whose
/// type hashes differ from Cyclone 11's) waits for the type and never matches. Read once per process.
pub fn announce_type_information() -> bool {
    static ON: std::sync::OnceLock<bool> = std::sync::OnceLock::new();
    *ON.get_or_init(|| {
        std::env::var(ANNOUNCE_ENV)
            .is_ok_and(|v| matches!(v.to_ascii_lowercase().as_str(), "on" | "1" | "true"))
    })
}

/// What an endpoint of a type with these XCDR2 `TypeInformation` bytes announces in SEDP: the bytes when
/// [`announce_type_information`] is on, else nothing.
pub fn announced_type_information(bytes: Option<&[u8]>) -> Option<TypeInformation> {
    bytes
        .filter(|_| announce_type_information())
        .map(|b| TypeInformation(b.to_vec()))
}

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
