//! The XTypes 1.3 TypeLookup service (§7.6.3.3), sans-I/O: its messages ([`messages`]) with their wire codec
//! ([`codec`]: the RPC-over-DDS `TypeLookup_Request`/`TypeLookup_Reply`, byte for byte what Cyclone DDS sends),
//! the server side that answers from a [`TypeStore`](super::store::TypeStore) ([`server`]) and the client side
//! that asks for types it lacks and checks every answer's hash before storing it ([`client`]).
//!
//! Nothing here knows RTPS: GUIDs are plain 16-byte arrays and time comes in as an argument. The participant
//! (`rtps::participant`) carries the messages on the four built-in endpoints.

pub mod client;
pub mod codec;
pub mod messages;
pub mod server;

pub use client::{Client, ClientLimits, ReplyOutcome};
pub use codec::{decode_reply, decode_request, encode_reply, encode_request, TypeLookupError};
pub use messages::{
    Call, RemoteExceptionCode, Reply, Request, Return, SampleIdentity, TypeDependencies, TypesOut,
    GET_DEPENDENCIES_HASH_ID, GET_TYPES_HASH_ID,
};
pub use server::{RateLimiter, Server, ServerLimits};
