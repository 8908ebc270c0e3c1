//! XTypes 1.3: the type system ([`typeobject`]), what a Rust type says about itself ([`XTypesType`], emitted by
//! `#[derive(DdsType)]`), and the per-type [`TypeInformation`]/[`typeobject::TypeMapping`] built from it.

// Assignability decides matching, and reads the TYPE_CONSISTENCY_ENFORCEMENT policy of `qos`.
#[cfg(feature = "rtps")]
pub mod assign;
pub mod dynamic;
pub mod store;
pub mod typelookup;
pub mod typeobject;

/// Environment variable that turns `PID_TYPE_INFORMATION` in SEDP off (`off`, `0` or `false`); it is on by
/// default.
pub const ANNOUNCE_ENV: &str = "DDS_TYPE_INFORMATION";

/// Whether endpoints announce their type information: yes, unless [`ANNOUNCE_ENV`] says `off` (for a peer
/// that mishandles it). Peers that do not know our types ask for them through the TypeLookup service, which
/// every participant serves. Read once per process.
pub fn announce_type_information() -> bool {
    static ON: std::sync::OnceLock<bool> = std::sync::OnceLock::new();
    *ON.get_or_init(|| {
        !std::env::var(ANNOUNCE_ENV)
            .is_ok_and(|v| matches!(v.to_ascii_lowercase().as_str(), "off" | "0" | "false"))
    })
}

/// What an endpoint of a type with these XCDR2 `TypeInformation` bytes announces in SEDP: the bytes when
/// [`announce_type_information`] is on, else nothing.
pub fn announced_type_information(bytes: Option<&[u8]>) -> Option<TypeInformation> {
    bytes
        .filter(|_| announce_type_information())
        .map(|b| TypeInformation(b.to_vec()))
}

/// What an endpoint of a type with these XCDR2 `TypeInformation` and `TypeMapping` bytes announces in SEDP:
/// [`announced_type_information`], except for types that use `int8`/`uint8`, which Cyclone DDS 0.10 peers
/// cannot resolve (see `compat`): they announce nothing and match by name.
pub fn announced_type_information_for(
    information: Option<&[u8]>,
    mapping: Option<&[u8]>,
) -> Option<TypeInformation> {
    if mapping.is_none_or(compat::uses_int8) {
        return None;
    }
    announced_type_information(information)
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

mod alias;
mod build;
mod compat;
mod describe;
mod error;
mod objects;
mod octet;
mod scc;
mod shape;

pub use alias::{Bounded, Octet};
pub use build::TypeSupport;
pub use describe::{
    bounded_desc, BitmaskDef, CaseDef, EnumDef, MemberDef, NamedRef, StructDef, TypeDef, TypeDesc,
    TypeRef, UnionDef, XTypesType,
};
pub use error::BuildError;
pub use octet::{bounded_octet_desc, octet_desc, OctetType};
