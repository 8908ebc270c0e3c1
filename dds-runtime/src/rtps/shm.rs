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
/// by [`ShmChange::write_header`]) followed by the serialized sample as written, encapsulation included
/// (or, for a sample written in a loan, the sample where the header's payload range says).
#[derive(Debug, Clone)]
#[non_exhaustive]
pub struct ShmChange {
    /// The local writer.
    pub writer: EntityId,
    /// Its sequence number.
    pub sequence: SequenceNumber,
    /// The change (its payload is shared with the writer's history, not copied; empty when `loaned`).
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
    /// The end of the history replayed to `target` (a durable reader): no change; what follows on the
    /// channel is newer than that history.
    pub history_end: bool,
    /// The sample is already in a buffer loaned from the writer's channel (`DataWriter::loan`): the driver
    /// sends that buffer, with this header written into it, instead of copying `change.payload`.
    pub loaned: bool,
}

const MAGIC: [u8; 4] = *b"DSM1";
const HAS_KEY_HASH: u8 = 1;
const HAS_TIMESTAMP: u8 = 2;
const HAS_TARGET: u8 = 4;
const LIVELINESS: u8 = 8;
const HISTORY_END: u8 = 16;
const HAS_RANGE: u8 = 32;
const KNOWN_FLAGS: u8 =
    HAS_KEY_HASH | HAS_TIMESTAMP | HAS_TARGET | LIVELINESS | HISTORY_END | HAS_RANGE;

/// Why bytes read from a channel are not a frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum FrameError {
    /// Shorter than a header.
    #[error("shared-memory frame of {0} bytes: shorter than its header")]
    Truncated(usize),
    /// Not our magic number.
    #[error("not a shared-memory frame (bad magic)")]
    BadMagic,
    /// Flag bits this version does not know.
    #[error("shared-memory frame with unknown flags {0:#04x}")]
    UnknownFlags(u8),
    /// A payload range outside the frame.
    #[error("shared-memory frame payload {offset}+{len} outside its {frame} bytes")]
    BadRange {
        /// Where the header says the payload starts.
        offset: usize,
        /// Its length, as the header says.
        len: usize,
        /// The frame's length.
        frame: usize,
    },
}

/// A frame's header, decoded.
#[derive(Debug, Clone, PartialEq, Eq)]
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
    /// The end of the history replayed to `target`.
    pub history_end: bool,
    /// Where the serialized sample is in the frame (checked to lie inside it).
    pub payload: std::ops::Range<usize>,
}

impl ShmChange {
    /// Bytes of header before the serialized sample (a multiple of 8, so that the sample keeps its
    /// alignment).
    pub const HEADER_LEN: usize = 64;

    /// A change for the channel of `writer`, to every reader of `nodes` (no target, not a liveliness
    /// assertion, not the end of a history, not loaned: set those fields after).
    pub fn new(
        writer: EntityId,
        sequence: SequenceNumber,
        change: WriteChange,
        nodes: Arc<[String]>,
        reliable: bool,
    ) -> Self {
        ShmChange {
            writer,
            sequence,
            change,
            target: None,
            nodes,
            reliable,
            liveliness: false,
            history_end: false,
            loaned: false,
        }
    }

    /// Bytes of the whole frame (for a frame that carries its payload after the header).
    pub fn frame_len(&self) -> usize {
        Self::HEADER_LEN + self.change.payload.len()
    }

    /// Writes the header into the first [`HEADER_LEN`](Self::HEADER_LEN) bytes of `out` (which must hold
    /// them); the serialized sample follows it.
    pub fn write_header(&self, out: &mut [u8]) {
        self.write_header_with(out, None);
    }

    /// [`write_header`](Self::write_header) of a frame whose serialized sample is at `payload` (a range
    /// of the frame after the header) rather than right after the header.
    pub fn write_header_with(&self, out: &mut [u8], payload: Option<std::ops::Range<usize>>) {
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
        if let Some(r) = payload {
            flags |= HAS_RANGE;
            let field = |v: usize| u32::try_from(v).unwrap_or(u32::MAX).to_le_bytes();
            h[56..60].copy_from_slice(&field(r.start));
            h[60..64].copy_from_slice(&field(r.len()));
        }
        if self.liveliness {
            flags |= LIVELINESS;
        }
        if self.history_end {
            flags |= HISTORY_END;
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

/// The header of `frame`. Never panics and allocates nothing, whatever the bytes.
pub fn decode_header(frame: &[u8]) -> Result<ShmHeader, FrameError> {
    let h: &[u8; ShmChange::HEADER_LEN] = frame
        .get(..ShmChange::HEADER_LEN)
        .and_then(|h| h.try_into().ok())
        .ok_or(FrameError::Truncated(frame.len()))?;
    if h[0..4] != MAGIC {
        return Err(FrameError::BadMagic);
    }
    let flags = h[5];
    if flags & !KNOWN_FLAGS != 0 {
        return Err(FrameError::UnknownFlags(flags));
    }
    let u32_at = |i: usize| u32::from_le_bytes([h[i], h[i + 1], h[i + 2], h[i + 3]]);
    let arr16 = |at: usize| -> [u8; 16] {
        let mut a = [0; 16];
        a.copy_from_slice(&h[at..at + 16]);
        a
    };
    let payload = if flags & HAS_RANGE != 0 {
        let (offset, len) = (u32_at(56) as usize, u32_at(60) as usize);
        let end = offset.checked_add(len).filter(|e| *e <= frame.len());
        match end {
            Some(end) if offset >= ShmChange::HEADER_LEN => offset..end,
            _ => {
                return Err(FrameError::BadRange {
                    offset,
                    len,
                    frame: frame.len(),
                })
            }
        }
    } else {
        ShmChange::HEADER_LEN..frame.len()
    };
    let mut sn = [0u8; 8];
    sn.copy_from_slice(&h[8..16]);
    Ok(ShmHeader {
        sequence: SequenceNumber(i64::from_le_bytes(sn)),
        kind: ChangeKind::from_status_info(h[4]),
        key_hash: (flags & HAS_KEY_HASH != 0).then(|| arr16(16)),
        source_timestamp: (flags & HAS_TIMESTAMP != 0).then(|| Time {
            seconds: u32_at(32) as i32,
            fraction: u32_at(36),
        }),
        target: (flags & HAS_TARGET != 0).then(|| Guid::from_bytes(arr16(40))),
        liveliness: flags & LIVELINESS != 0,
        history_end: flags & HISTORY_END != 0,
        payload,
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

    fn change() -> ShmChange {
        let target = Guid::new(GuidPrefix([7; 12]), EntityId([0, 0, 1, 0x07]));
        let mut c = ShmChange::new(
            EntityId([0, 0, 1, 0x02]),
            SequenceNumber(0x1234_5678_9abc),
            WriteChange {
                kind: ChangeKind::DisposeUnregister,
                payload: Payload::copy_from_slice(&[0, 1, 0, 0, 9, 9]),
                key_hash: Some([3; 16]),
                source_timestamp: Some(Time {
                    seconds: -5,
                    fraction: 77,
                }),
            },
            Arc::from(Vec::new()),
            true,
        );
        c.target = Some(target);
        c
    }

    #[test]
    fn header_round_trip_and_garbage() {
        let c = change();
        let mut frame = vec![0xff; c.frame_len()];
        c.write_frame(&mut frame);
        let h = decode_header(&frame).expect("a frame");
        assert_eq!(h.sequence, c.sequence);
        assert_eq!(h.kind, ChangeKind::DisposeUnregister);
        assert_eq!(h.key_hash, Some([3; 16]));
        assert_eq!(h.source_timestamp, c.change.source_timestamp);
        assert_eq!(h.target, c.target);
        assert!(!h.liveliness && !h.history_end);
        assert_eq!(&frame[h.payload], &[0, 1, 0, 0, 9, 9]);
        assert_eq!(decode_header(&frame[..10]), Err(FrameError::Truncated(10)));
        frame[0] = b'X';
        assert_eq!(decode_header(&frame), Err(FrameError::BadMagic));
    }

    #[test]
    fn payload_range_is_checked_against_the_frame() {
        let mut c = change();
        c.history_end = true;
        let mut frame = vec![0; 100];
        c.write_header_with(&mut frame, Some(72..96));
        let h = decode_header(&frame).expect("a frame");
        assert_eq!((h.payload, h.history_end), (72..96, true));
        c.write_header_with(&mut frame, Some(72..101));
        assert!(matches!(
            decode_header(&frame),
            Err(FrameError::BadRange { .. })
        ));
        c.write_header_with(&mut frame, Some(8..20));
        assert!(matches!(
            decode_header(&frame),
            Err(FrameError::BadRange { .. })
        ));
        // Offset and length that overflow when added.
        frame[56..64].fill(0xff);
        assert!(matches!(
            decode_header(&frame),
            Err(FrameError::BadRange { .. })
        ));
    }

    /// Hostile bytes: every truncation of a valid frame, every single flipped flag bit, and pseudo-random
    /// garbage decode to an error or to a header whose payload range lies inside the frame; none panics.
    #[test]
    fn hostile_frames_give_errors_never_panics() {
        let c = change();
        let mut frame = vec![0; c.frame_len()];
        c.write_frame(&mut frame);
        for n in 0..frame.len() {
            let r = decode_header(&frame[..n]);
            assert!(n >= ShmChange::HEADER_LEN || r == Err(FrameError::Truncated(n)));
        }
        for bit in 0..8 {
            let mut f = frame.clone();
            f[5] ^= 1 << bit;
            if let Ok(h) = decode_header(&f) {
                assert!(h.payload.end <= f.len());
            }
        }
        let mut x: u64 = 0x9e37_79b9_7f4a_7c15;
        for len in [0, 1, 63, 64, 65, 200] {
            for _ in 0..2000 {
                let mut f: Vec<u8> = (0..len)
                    .map(|_| {
                        x ^= x << 13;
                        x ^= x >> 7;
                        x ^= x << 17;
                        x as u8
                    })
                    .collect();
                if len >= 4 {
                    f[..4].copy_from_slice(b"DSM1");
                }
                if let Ok(h) = decode_header(&f) {
                    assert!(h.payload.start >= ShmChange::HEADER_LEN && h.payload.end <= f.len());
                }
            }
        }
    }
}
