//! The `rtps_decode` check: message walk, per-submessage re-encode round trip, and the discovery decoders.

use dds_runtime::rtps::discovery::{ParticipantData, ReaderData, WriterData};
use dds_runtime::rtps::messages::{MessageIter, Submessage};

/// The byte orders a decoded submessage can be re-encoded in and still compare equal: raw bytes it carries
/// (inline QoS, unknown bodies) keep the order they arrived in.
fn orders(s: &Submessage<'_>) -> &'static [bool] {
    let fixed = match s {
        Submessage::Data(d) => d.inline_qos.map(|q| q.little_endian),
        Submessage::DataFrag(d) => d.inline_qos.map(|q| q.little_endian),
        Submessage::Unknown { flags, .. } => Some(flags & 1 != 0),
        _ => None,
    };
    match fixed {
        Some(true) => &[true],
        Some(false) => &[false],
        None => &[true, false],
    }
}

/// Runs one input.
pub fn rtps_one(data: &[u8]) {
    if let Ok((_header, iter)) = MessageIter::parse(data) {
        for sub in iter {
            let Ok(sub) = sub else { break };
            if let Submessage::Data(d) = &sub {
                if let Some(q) = d.inline_qos {
                    let _ = q.iter().count();
                    let _ = q.key_hash();
                    let _ = q.status_info();
                }
                if let Some(p) = d.payload {
                    decode_discovery(p);
                }
            }
            for &le in orders(&sub) {
                let mut out = Vec::new();
                sub.encode(&mut out, le);
                let mut again = MessageIter::new(&out);
                let back = again
                    .next()
                    .unwrap_or_else(|| {
                        panic!("re-encoded submessage vanished: {sub:?}\n{out:02x?}")
                    })
                    .unwrap_or_else(|e| {
                        panic!("re-encoded submessage does not decode ({e}): {sub:?}\n{out:02x?}")
                    });
                assert_eq!(
                    sub, back,
                    "submessage changed through re-encode (le={le})\n{out:02x?}"
                );
                assert!(
                    again.next().is_none(),
                    "re-encoding produced trailing submessages: {out:02x?}"
                );
            }
        }
    }
    // The bytes may also be a discovery payload on their own.
    decode_discovery(data);
}

fn decode_discovery(payload: &[u8]) {
    let _ = ParticipantData::decode(payload);
    let _ = WriterData::decode(payload);
    let _ = ReaderData::decode(payload);
}
