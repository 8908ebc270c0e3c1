//! Builtin endpoint set bits (§8.5.3.4, plus the 2.4+ topic bits) and the participant-message data.

use crate::rtps::types::{EntityId, GuidPrefix};

/// The SPDP writer.
pub const PARTICIPANT_ANNOUNCER: u32 = 1 << 0;
/// The SPDP reader.
pub const PARTICIPANT_DETECTOR: u32 = 1 << 1;
/// The SEDP publications writer.
pub const PUBLICATIONS_ANNOUNCER: u32 = 1 << 2;
/// The SEDP publications reader.
pub const PUBLICATIONS_DETECTOR: u32 = 1 << 3;
/// The SEDP subscriptions writer.
pub const SUBSCRIPTIONS_ANNOUNCER: u32 = 1 << 4;
/// The SEDP subscriptions reader.
pub const SUBSCRIPTIONS_DETECTOR: u32 = 1 << 5;
/// The participant message writer.
pub const PARTICIPANT_MESSAGE_WRITER: u32 = 1 << 10;
/// The participant message reader.
pub const PARTICIPANT_MESSAGE_READER: u32 = 1 << 11;
/// The TypeLookup service's request writer (XTypes 1.3 §7.6.3.3.4).
pub const TYPELOOKUP_REQUEST_WRITER: u32 = 1 << 12;
/// The TypeLookup service's request reader.
pub const TYPELOOKUP_REQUEST_READER: u32 = 1 << 13;
/// The TypeLookup service's reply writer.
pub const TYPELOOKUP_REPLY_WRITER: u32 = 1 << 14;
/// The TypeLookup service's reply reader.
pub const TYPELOOKUP_REPLY_READER: u32 = 1 << 15;
/// The SEDP topics writer.
pub const TOPICS_ANNOUNCER: u32 = 1 << 28;
/// The SEDP topics reader.
pub const TOPICS_DETECTOR: u32 = 1 << 29;

/// What we announce.
pub const OURS: u32 = PARTICIPANT_ANNOUNCER
    | PARTICIPANT_DETECTOR
    | PUBLICATIONS_ANNOUNCER
    | PUBLICATIONS_DETECTOR
    | SUBSCRIPTIONS_ANNOUNCER
    | SUBSCRIPTIONS_DETECTOR
    | PARTICIPANT_MESSAGE_WRITER
    | PARTICIPANT_MESSAGE_READER
    | TYPELOOKUP_REQUEST_WRITER
    | TYPELOOKUP_REQUEST_READER
    | TYPELOOKUP_REPLY_WRITER
    | TYPELOOKUP_REPLY_READER;

/// (our writer, the remote reader it serves, the bit the remote must announce for that reader).
pub const WRITER_PAIRS: [(EntityId, EntityId, u32); 5] = [
    (
        EntityId::SEDP_PUBLICATIONS_WRITER,
        EntityId::SEDP_PUBLICATIONS_READER,
        PUBLICATIONS_DETECTOR,
    ),
    (
        EntityId::SEDP_SUBSCRIPTIONS_WRITER,
        EntityId::SEDP_SUBSCRIPTIONS_READER,
        SUBSCRIPTIONS_DETECTOR,
    ),
    (
        EntityId::P2P_MESSAGE_WRITER,
        EntityId::P2P_MESSAGE_READER,
        PARTICIPANT_MESSAGE_READER,
    ),
    (
        EntityId::TYPELOOKUP_REQUEST_WRITER,
        EntityId::TYPELOOKUP_REQUEST_READER,
        TYPELOOKUP_REQUEST_READER,
    ),
    (
        EntityId::TYPELOOKUP_REPLY_WRITER,
        EntityId::TYPELOOKUP_REPLY_READER,
        TYPELOOKUP_REPLY_READER,
    ),
];

/// (our reader, the remote writer it listens to, the bit the remote must announce for that writer).
pub const READER_PAIRS: [(EntityId, EntityId, u32); 5] = [
    (
        EntityId::SEDP_PUBLICATIONS_READER,
        EntityId::SEDP_PUBLICATIONS_WRITER,
        PUBLICATIONS_ANNOUNCER,
    ),
    (
        EntityId::SEDP_SUBSCRIPTIONS_READER,
        EntityId::SEDP_SUBSCRIPTIONS_WRITER,
        SUBSCRIPTIONS_ANNOUNCER,
    ),
    (
        EntityId::P2P_MESSAGE_READER,
        EntityId::P2P_MESSAGE_WRITER,
        PARTICIPANT_MESSAGE_WRITER,
    ),
    (
        EntityId::TYPELOOKUP_REQUEST_READER,
        EntityId::TYPELOOKUP_REQUEST_WRITER,
        TYPELOOKUP_REQUEST_WRITER,
    ),
    (
        EntityId::TYPELOOKUP_REPLY_READER,
        EntityId::TYPELOOKUP_REPLY_WRITER,
        TYPELOOKUP_REPLY_WRITER,
    ),
];

/// ParticipantMessageData kinds (§9.6.2.1).
pub const PMD_KIND_AUTOMATIC: [u8; 4] = [0, 0, 0, 1];
/// ParticipantMessageData kind: manual liveliness by participant.
pub const PMD_KIND_MANUAL: [u8; 4] = [0, 0, 0, 2];

/// Serializes ParticipantMessageData (CDR little-endian with encapsulation header).
pub fn encode_participant_message(prefix: &GuidPrefix, kind: [u8; 4], data: &[u8]) -> Vec<u8> {
    let mut v = Vec::with_capacity(24 + data.len());
    v.extend_from_slice(&[0x00, 0x01, 0x00, 0x00]);
    v.extend_from_slice(&prefix.0);
    v.extend_from_slice(&kind);
    v.extend_from_slice(&(data.len() as u32).to_le_bytes());
    v.extend_from_slice(data);
    v
}

/// Reads (participant prefix, kind) from a ParticipantMessageData payload or its key.
pub fn decode_participant_message(payload: &[u8]) -> Option<(GuidPrefix, [u8; 4])> {
    let body = payload.get(4..20)?;
    let mut p = [0u8; 12];
    p.copy_from_slice(&body[..12]);
    Some((GuidPrefix(p), [body[12], body[13], body[14], body[15]]))
}

/// The key hash of a ParticipantMessageData instance: prefix and kind (16 bytes, no MD5 needed).
pub fn participant_message_key(prefix: &GuidPrefix, kind: [u8; 4]) -> [u8; 16] {
    let mut k = [0u8; 16];
    k[..12].copy_from_slice(&prefix.0);
    k[12..].copy_from_slice(&kind);
    k
}
