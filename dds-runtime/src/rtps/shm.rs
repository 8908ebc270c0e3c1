//! Shared-memory pairs, the core's side (no shared memory is touched here): which peers can use it, and the
//! frame a writer's change travels in through its channel.
//!
//! A participant that can exchange samples over shared memory announces two SPDP properties
//! (`PID_PROPERTY_LIST`): its host's identity ([`SHM_HOST_PROPERTY`]) and the identity of its node in shared
//! memory ([`SHM_NODE_PROPERTY`]). Two participants that both announce them with the same host match their
//! user endpoints without wire state: the writer's changes go through the writer's channel as
//! [`ShmChange`] frames (see [`Participant::poll_shm`](super::Participant::poll_shm) and
//! [`Participant::receive_shm`](super::Participant::receive_shm)). Every other peer keeps RTPS over UDP.
//! The I/O side is `transport::shm` (feature `shm`).

use std::sync::Arc;

use super::api::{ChangeKind, WriteChange};
use super::types::{EntityId, Guid, SequenceNumber, Time};

/// The SPDP property holding the announcing host's identity (its kernel boot id).
pub const SHM_HOST_PROPERTY: &str = "dds.shm.host";

/// The SPDP property holding the announcing participant's node id in shared memory (hexadecimal): a
/// writer waits for the subscribers of these nodes before it sends on its channel.
pub const SHM_NODE_PROPERTY: &str = "dds.shm.node";

/// The value of property `name` in `properties`.
fn property<'a>(properties: &'a [(String, String)], name: &str) -> Option<&'a str> {
    properties
        .iter()
        .find(|(k, _)| k == name)
        .map(|(_, v)| v.as_str())
}

/// Whether participants that announced `own` and `peer` can exchange samples over shared memory: both
/// announce a node, and the same host. Symmetric, so that both sides of a pair decide alike.
pub fn shm_peers(own: &[(String, String)], peer: &[(String, String)]) -> bool {
    let host = property(own, SHM_HOST_PROPERTY);
    host.is_some()
        && host == property(peer, SHM_HOST_PROPERTY)
        && property(own, SHM_NODE_PROPERTY).is_some()
        && property(peer, SHM_NODE_PROPERTY).is_some()
}

/// The shared-memory node a participant announced in `properties`.
pub(crate) fn shm_node(properties: &[(String, String)]) -> Option<&str> {
    property(properties, SHM_NODE_PROPERTY)
}

/// The channel (iceoryx2 service name) of a writer: one per writer, read by every participant with a
/// reader matched with it over shared memory.
pub fn shm_channel_name(writer: &Guid) -> String {
    let hex: String = writer
        .to_bytes()
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect();
    format!("dds/w/{hex}")
}

/// A change a writer sends on its channel: the frame is [`ShmChange::HEADER_LEN`] bytes of header (written
/// by [`ShmChange::write_header`]) followed by the serialized sample as written, encapsulation included.
#[derive(Debug, Clone)]
#[non_exhaustive]
pub struct ShmChange {
    /// The local writer.
    pub writer: EntityId,
    /// Its sequence number.
    pub sequence: SequenceNumber,
    /// The change (its payload is shared with the writer's history, not copied).
    pub change: WriteChange,
    /// `Some(reader)`: for that reader only (the history a durable reader gets when it matches).
    pub target: Option<Guid>,
    /// The shared-memory nodes (participants) whose readers must get it: the channel's sender waits, for a
    /// bounded time, for their subscribers before it sends.
    pub nodes: Arc<[String]>,
    /// Whether the writer is reliable (a full reader queue is waited for, not skipped).
    pub reliable: bool,
    /// Only an assertion of the writer's liveliness (`DataWriter::assert_liveliness`): no change.
    pub liveliness: bool,
}

const MAGIC: [u8; 4] = *b"DSM1";
const HAS_KEY_HASH: u8 = 1;
const HAS_TIMESTAMP: u8 = 2;
const HAS_TARGET: u8 = 4;
const LIVELINESS: u8 = 8;

/// A frame's header, decoded.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub struct ShmHeader {
    /// The change's sequence number (0 for a liveliness assertion).
    pub sequence: SequenceNumber,
    /// What it does to its instance.
    pub kind: ChangeKind,
    /// Its key hash, when the writer gave one.
    pub key_hash: Option<[u8; 16]>,
    /// The writer's timestamp, if any.
    pub source_timestamp: Option<Time>,
    /// `Some(reader)`: for that reader only.
    pub target: Option<Guid>,
    /// Only a liveliness assertion.
    pub liveliness: bool,
}

impl ShmChange {
    /// Bytes of header before the serialized sample (a multiple of 8, so that the sample keeps its
    /// alignment).
    pub const HEADER_LEN: usize = 64;

    /// Bytes of the whole frame.
    pub fn frame_len(&self) -> usize {
        Self::HEADER_LEN + self.change.payload.len()
    }

    /// Writes the header into the first [`HEADER_LEN`](Self::HEADER_LEN) bytes of `out` (which must hold
    /// them); the serialized sample follows it.
    pub fn write_header(&self, out: &mut [u8]) {
        let h = &mut out[..Self::HEADER_LEN];
        h.fill(0);
        h[0..4].copy_from_slice(&MAGIC);
        h[4] = self.change.kind.status_info();
        let mut flags = 0;
        h[8..16].copy_from_slice(&self.sequence.0.to_le_bytes());
        if let Some(k) = self.change.key_hash {
            flags |= HAS_KEY_HASH;
            h[16..32].copy_from_slice(&k);
        }
        if let Some(t) = self.change.source_timestamp {
            flags |= HAS_TIMESTAMP;
            h[32..36].copy_from_slice(&t.seconds.to_le_bytes());
            h[36..40].copy_from_slice(&t.fraction.to_le_bytes());
        }
        if let Some(g) = self.target {
            flags |= HAS_TARGET;
            h[40..56].copy_from_slice(&g.to_bytes());
        }
        if self.liveliness {
            flags |= LIVELINESS;
        }
        h[5] = flags;
    }

    /// Copies the whole frame (header, then sample) into `out`, which must be [`frame_len`](Self::frame_len)
    /// bytes long.
    pub fn write_frame(&self, out: &mut [u8]) {
        self.write_header(out);
        out[Self::HEADER_LEN..].copy_from_slice(&self.change.payload);
    }
}

/// The header of `frame`; `None` for anything that is not one of our frames.
pub fn decode_header(frame: &[u8]) -> Option<ShmHeader> {
    let h = frame.get(..ShmChange::HEADER_LEN)?;
    if h[0..4] != MAGIC {
        return None;
    }
    let flags = h[5];
    let arr16 = |r: std::ops::Range<usize>| -> [u8; 16] { h[r].try_into().unwrap_or([0; 16]) };
    let u32_at = |i: usize| u32::from_le_bytes([h[i], h[i + 1], h[i + 2], h[i + 3]]);
    let mut sn = [0u8; 8];
    sn.copy_from_slice(&h[8..16]);
    Some(ShmHeader {
        sequence: SequenceNumber(i64::from_le_bytes(sn)),
        kind: ChangeKind::from_status_info(h[4]),
        key_hash: (flags & HAS_KEY_HASH != 0).then(|| arr16(16..32)),
        source_timestamp: (flags & HAS_TIMESTAMP != 0).then(|| Time {
            seconds: u32_at(32) as i32,
            fraction: u32_at(36),
        }),
        target: (flags & HAS_TARGET != 0).then(|| Guid::from_bytes(arr16(40..56))),
        liveliness: flags & LIVELINESS != 0,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rtps::api::Payload;
    use crate::rtps::types::GuidPrefix;

    fn props(host: &str, node: Option<&str>) -> Vec<(String, String)> {
        let mut p = vec![(SHM_HOST_PROPERTY.to_owned(), host.to_owned())];
        if let Some(n) = node {
            p.push((SHM_NODE_PROPERTY.to_owned(), n.to_owned()));
        }
        p
    }

    #[test]
    fn peers_need_the_same_host_and_both_nodes() {
        assert!(shm_peers(&props("h", Some("1")), &props("h", Some("2"))));
        assert!(!shm_peers(&props("h", Some("1")), &props("g", Some("2"))));
        assert!(!shm_peers(&props("h", Some("1")), &props("h", None)));
        assert!(!shm_peers(&props("h", None), &props("h", Some("2"))));
        assert!(!shm_peers(&[], &[]));
    }

    #[test]
    fn header_round_trip_and_garbage() {
        let target = Guid::new(GuidPrefix([7; 12]), EntityId([0, 0, 1, 0x07]));
        let c = ShmChange {
            writer: EntityId([0, 0, 1, 0x02]),
            sequence: SequenceNumber(0x1234_5678_9abc),
            change: WriteChange {
                kind: ChangeKind::DisposeUnregister,
                payload: Payload::copy_from_slice(&[0, 1, 0, 0, 9, 9]),
                key_hash: Some([3; 16]),
                source_timestamp: Some(Time {
                    seconds: -5,
                    fraction: 77,
                }),
            },
            target: Some(target),
            nodes: Arc::from(Vec::new()),
            reliable: true,
            liveliness: false,
        };
        let mut frame = vec![0xff; c.frame_len()];
        c.write_frame(&mut frame);
        let h = decode_header(&frame).expect("a frame");
        assert_eq!(h.sequence, c.sequence);
        assert_eq!(h.kind, ChangeKind::DisposeUnregister);
        assert_eq!(h.key_hash, Some([3; 16]));
        assert_eq!(h.source_timestamp, c.change.source_timestamp);
        assert_eq!(h.target, Some(target));
        assert!(!h.liveliness);
        assert_eq!(&frame[ShmChange::HEADER_LEN..], &[0, 1, 0, 0, 9, 9]);
        assert!(decode_header(&frame[..10]).is_none());
        frame[0] = b'X';
        assert!(decode_header(&frame).is_none());
    }
}
