//! The `shm_header` check: arbitrary bytes read from a shared-memory channel through the frame header
//! decoder (`dds_runtime::rtps::shm::decode_header`). It never panics; a header that decodes names a
//! payload inside the frame, and writing it again gives bytes that decode to the same header.

use std::sync::Arc;

use dds_runtime::rtps::shm::{decode_header, ShmChange};
use dds_runtime::rtps::{EntityId, Payload, WriteChange};

/// Runs one input.
pub fn shm_one(data: &[u8]) {
    let Ok(h) = decode_header(data) else { return };
    assert!(
        h.payload.start >= ShmChange::HEADER_LEN && h.payload.end <= data.len(),
        "payload {:?} outside the frame of {} bytes",
        h.payload,
        data.len()
    );
    let change = WriteChange {
        kind: h.kind,
        payload: Payload::copy_from_slice(&data[h.payload.clone()]),
        key_hash: h.key_hash,
        source_timestamp: h.source_timestamp,
    };
    let mut c = ShmChange::new(
        EntityId::UNKNOWN,
        h.sequence,
        change,
        Arc::from(Vec::new()),
        true,
    );
    c.target = h.target;
    c.liveliness = h.liveliness;
    c.history_end = h.history_end;
    let default = ShmChange::HEADER_LEN..data.len();
    let range = (h.payload != default).then(|| h.payload.clone());
    let mut again = data.to_vec();
    c.write_header_with(&mut again, range);
    let back = decode_header(&again).expect("a written header decodes");
    assert_eq!(back, h, "header changed through re-encode");
}
