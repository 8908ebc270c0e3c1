//! The error type of the DCPS API.

use crate::cdr::{DecodeError, EncodeError};
use crate::config::ConfigError;
use crate::filter::FilterError;
use crate::qos::QosPolicyId;
use crate::rtps::{CoreError, WriteError};

/// Errors returned by DCPS operations (DDS 1.4 §2.2.1.1 return codes, plus Rust-side causes).
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum DdsError {
    /// A blocking operation (write under flow control, wait_for_acknowledgments, a wait) ran out of time.
    #[error("timed out")]
    Timeout,
    /// The operation is not allowed in the entity's current state.
    #[error("precondition not met: {0}")]
    PreconditionNotMet(&'static str),
    /// An argument is invalid.
    #[error("bad parameter: {0}")]
    BadParameter(String),
    /// A resource limit would be exceeded.
    #[error("out of resources: {0}")]
    OutOfResources(&'static str),
    /// The sample could not be serialized.
    #[error("encode: {0}")]
    Encode(#[from] EncodeError),
    /// A payload could not be deserialized.
    #[error("decode: {0}")]
    Decode(#[from] DecodeError),
    /// A socket or thread operation failed.
    #[error("i/o: {0}")]
    Io(#[from] std::io::Error),
    /// Invalid configuration.
    #[error("config: {0}")]
    Config(#[from] ConfigError),
    /// The entity (or its participant) has been deleted.
    #[error("entity already deleted")]
    AlreadyDeleted,
    /// `set_qos` tried to change a policy that cannot change once the entity is enabled (DDS
    /// IMMUTABLE_POLICY).
    #[error("immutable policy: {0:?}")]
    ImmutablePolicy(QosPolicyId),
    /// The QoS values contradict each other (DDS INCONSISTENT_POLICY).
    #[error("inconsistent policy: {0}")]
    InconsistentPolicy(&'static str),
    /// The entity is not enabled yet (DDS NOT_ENABLED): see `enable()` and
    /// ENTITY_FACTORY.autoenable_created_entities.
    #[error("entity not enabled")]
    NotEnabled,
    /// The feature is not implemented.
    #[error("unsupported: {0}")]
    Unsupported(&'static str),
    /// The protocol core refused to create an entity.
    #[error("rtps: {0}")]
    Core(#[from] CoreError),
    /// A content filter or query expression, or its parameters, were refused.
    #[error("filter: {0}")]
    Filter(#[from] FilterError),
    /// The protocol core refused a write for a reason not covered by another variant.
    #[error("rtps write: {0}")]
    Write(#[source] WriteError),
}

/// `Result<T, DdsError>`.
pub type DdsResult<T> = Result<T, DdsError>;
