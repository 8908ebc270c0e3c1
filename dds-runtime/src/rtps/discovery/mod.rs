//! Discovery: SPDP (participants), SEDP (endpoints), the builtin endpoints and matching.

pub mod builtin;
mod content_filter;
pub mod matching;
pub mod ports;
mod qos_params;
mod sedp;
mod spdp;
pub mod topics;

pub use content_filter::ContentFilterProperty;
pub(crate) use sedp::{encode_endpoint_key, endpoint_guid as endpoint_guid_of};
pub use sedp::{EndpointData, EndpointQos, ReaderData, WriterData};
pub use spdp::ParticipantData;
pub use topics::TopicData;

/// Encapsulation of discovery payloads: PL_CDR little-endian (0x0003) and big-endian (0x0002).
pub(crate) const PL_CDR_LE: [u8; 4] = [0x00, 0x03, 0x00, 0x00];
pub(crate) const PL_CDR_BE_ID: [u8; 2] = [0x00, 0x02];

/// Splits a discovery payload into its parameter list and byte order.
pub(crate) fn pl_payload(
    payload: &[u8],
) -> Result<crate::rtps::messages::ParameterList<'_>, crate::rtps::messages::WireError> {
    use crate::rtps::messages::{ParameterList, WireError};
    if payload.len() < 4 {
        return Err(WireError::Truncated);
    }
    let le = match [payload[0], payload[1]] {
        [0x00, 0x03] => true,
        x if x == PL_CDR_BE_ID => false,
        _ => return Err(WireError::Invalid("discovery encapsulation")),
    };
    Ok(ParameterList::parse(&payload[4..], le)?.0)
}
