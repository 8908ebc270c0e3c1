//! The TypeLookup request and reply (XTypes 1.3 §7.6.3.3.3, with the RPC header of DDS-RPC 1.0 §7.5.1.1), as
//! plain values.

use crate::xtypes::typeobject::{
    TypeIdentifier, TypeIdentifierPair, TypeIdentifierTypeObjectPair, TypeIdentifierWithSize,
};

/// `TypeLookup_getTypes_HashId`: the discriminator of `getTypes` (`@hashid("getTypes")`).
pub const GET_TYPES_HASH_ID: u32 = 0x0182_52d3;
/// `TypeLookup_getDependencies_HashId`: the discriminator of `getTypeDependencies`.
pub const GET_DEPENDENCIES_HASH_ID: u32 = 0x05aa_fb31;

/// `SampleIdentity`: the writer of a request and the request's sequence number.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub struct SampleIdentity {
    /// The GUID of the writer (prefix, then entity id).
    pub writer_guid: [u8; 16],
    /// Its sequence number (`high << 32 | low`).
    pub sequence_number: i64,
}

/// `RemoteExceptionCode` of a reply header.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[non_exhaustive]
pub enum RemoteExceptionCode {
    /// `REMOTE_EX_OK`.
    #[default]
    Ok,
    /// `REMOTE_EX_UNSUPPORTED`.
    Unsupported,
    /// `REMOTE_EX_INVALID_ARGUMENT`.
    InvalidArgument,
    /// `REMOTE_EX_OUT_OF_RESOURCES`.
    OutOfResources,
    /// `REMOTE_EX_UNKNOWN_OPERATION`.
    UnknownOperation,
    /// `REMOTE_EX_UNKNOWN_EXCEPTION`.
    UnknownException,
}

impl RemoteExceptionCode {
    /// The enumerator's value.
    pub fn to_u32(self) -> u32 {
        match self {
            RemoteExceptionCode::Ok => 0,
            RemoteExceptionCode::Unsupported => 1,
            RemoteExceptionCode::InvalidArgument => 2,
            RemoteExceptionCode::OutOfResources => 3,
            RemoteExceptionCode::UnknownOperation => 4,
            RemoteExceptionCode::UnknownException => 5,
        }
    }

    /// The enumerator of a value, if it is one.
    pub fn from_u32(v: u32) -> Option<Self> {
        Some(match v {
            0 => RemoteExceptionCode::Ok,
            1 => RemoteExceptionCode::Unsupported,
            2 => RemoteExceptionCode::InvalidArgument,
            3 => RemoteExceptionCode::OutOfResources,
            4 => RemoteExceptionCode::UnknownOperation,
            5 => RemoteExceptionCode::UnknownException,
            _ => return None,
        })
    }
}

/// `TypeLookup_Call`: what a request asks.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Call {
    /// `getTypes`: the type objects of these identifiers.
    GetTypes(Vec<TypeIdentifier>),
    /// `getTypeDependencies`: the identifiers these types depend on, from `continuation_point` on (empty:
    /// from the start).
    GetTypeDependencies {
        /// The types.
        type_ids: Vec<TypeIdentifier>,
        /// Opaque, at most 32 bytes: where the previous reply stopped.
        continuation_point: Vec<u8>,
    },
    /// An operation this side does not know (its discriminator); answered `REMOTE_EX_UNKNOWN_OPERATION`.
    Other(u32),
}

/// `TypeLookup_Request`: the RPC request header and the call.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Request {
    /// `requestId`: the requesting writer and the request's sequence number.
    pub request_id: SampleIdentity,
    /// `instanceName` (at most 255 characters).
    pub instance_name: String,
    /// The call.
    pub call: Call,
}

/// `TypeLookup_getTypes_Out`.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct TypesOut {
    /// The objects found.
    pub types: Vec<TypeIdentifierTypeObjectPair>,
    /// Complete → minimal identifier pairs (may be empty).
    pub complete_to_minimal: Vec<TypeIdentifierPair>,
}

/// `TypeLookup_getTypeDependencies_Out`.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct TypeDependencies {
    /// One page of the dependencies.
    pub dependent_typeids: Vec<TypeIdentifierWithSize>,
    /// Where the next page starts (empty: this was the last one).
    pub continuation_point: Vec<u8>,
}

/// `TypeLookup_Return`: what a reply carries. A result union whose discriminator is not `DDS_RETCODE_OK`
/// has no value: it is the `Err` return code.
#[derive(Debug, Clone, PartialEq)]
pub enum Return {
    /// The answer to `getTypes`.
    GetTypes(Result<TypesOut, i32>),
    /// The answer to `getTypeDependencies`.
    GetTypeDependencies(Result<TypeDependencies, i32>),
    /// An operation this side does not know (its discriminator).
    Other(u32),
}

/// `TypeLookup_Reply`: the RPC reply header and the return value.
#[derive(Debug, Clone, PartialEq)]
pub struct Reply {
    /// `relatedRequestId`: the identity of the request this answers.
    pub related_request_id: SampleIdentity,
    /// `remoteEx`.
    pub remote_ex: RemoteExceptionCode,
    /// The return value.
    pub return_data: Return,
}
