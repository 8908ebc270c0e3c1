//! Turns a change received by a reader into a cache input: decodes the sample (or its key) and maps
//! key-only changes to their instance.

use std::time::{Instant, SystemTime};

use foldhash::HashMap;

use crate::cdr::{self, DdsType};
use crate::rtps::{ChangeKind, Payload, ReceivedSample};

use super::cache::Incoming;
use super::driver::RemoteWriterInfo;

/// Most key hashes remembered per reader for mapping key-hash-only disposes to instances.
const MAX_REMEMBERED_HASHES: usize = 65536;

fn system_time(t: Option<crate::rtps::Time>) -> Option<SystemTime> {
    t.and_then(|t| t.to_unix())
        .map(|d| SystemTime::UNIX_EPOCH + d)
}

/// The sample itself when the payload carries it (intra-process delivery of `write_owned`/`write_shared`:
/// no serialization), else read in place when the type can (`dcps::InPlace`), else decoded from the bytes.
fn local_or_deserialize<T: DdsType>(
    payload: &mut Payload,
    spare: &mut Vec<T>,
) -> Result<T, cdr::DecodeError> {
    if payload.is_local() {
        let mut slot: Option<T> = None;
        match std::mem::take(payload).take_local_into(&mut slot) {
            Ok(()) => {
                if let Some(d) = slot {
                    return Ok(d);
                }
            }
            Err(p) => *payload = p,
        }
    }
    if let Some(d) = T::decode_shared(&*payload) {
        return Ok(d);
    }
    match spare.pop() {
        Some(mut v) => cdr::deserialize_into(payload, &mut v).map(|()| v),
        None => cdr::deserialize::<T>(payload),
    }
}

/// Most values given back by the application ([`DataReader::recycle`](super::DataReader::recycle)) that a
/// reader keeps for decoding later samples into.
pub(crate) const MAX_SPARE_VALUES: usize = 1024;

/// What a reader's decoding keeps from one change to the next.
pub(crate) struct Decoding<T> {
    /// Key hash → serialized key, learnt from samples that carried both (for key-hash-only disposes).
    pub(crate) by_hash: HashMap<[u8; 16], Vec<u8>>,
    /// The key hash indexed last (in `by_hash`): a stream of one instance indexes it once, not per sample.
    last_hash: Option<[u8; 16]>,
    /// Values the application gave back, to decode into: their strings and sequences keep their buffers.
    spare: Vec<T>,
}

impl<T> Decoding<T> {
    pub(crate) fn new() -> Self {
        Decoding {
            by_hash: HashMap::default(),
            last_hash: None,
            spare: Vec::new(),
        }
    }

    /// Whether another given-back value would be kept.
    pub(crate) fn has_room(&self) -> bool {
        self.spare.len() < MAX_SPARE_VALUES
    }

    /// Keeps `v` to decode a later sample into (the caller checked [`Self::has_room`]).
    pub(crate) fn keep(&mut self, v: T) {
        self.spare.push(v);
    }
}

/// What a reader needs to know of its sample type `T` to decode changes and identify instances: derived
/// types know it statically ([`Derived`]), dynamic ones through their `DynamicType`. One decoding step
/// ([`decode_change_with`]) and one cache serve both.
pub(crate) trait SampleCodec<T> {
    /// The type has key members.
    fn keyed(&self) -> bool;
    /// A sample from its payload, decoded into one of the `spare` values where the codec can reuse them.
    fn decode(&self, payload: &mut Payload, spare: &mut Vec<T>) -> Result<T, cdr::DecodeError>;
    /// A sample holding the key values, from a key payload.
    fn decode_key(&self, payload: &[u8]) -> Result<T, cdr::DecodeError>;
    /// The serialized key that identifies the sample's instance.
    fn instance_key(&self, v: &T, out: &mut Vec<u8>) -> Result<(), cdr::EncodeError>;
    /// The key hash a writer using `version` sends.
    fn key_hash(&self, v: &T, version: cdr::XcdrVersion) -> Result<[u8; 16], cdr::EncodeError>;
}

/// [`SampleCodec`] of a `#[derive(DdsType)]` type.
pub(crate) struct Derived;

impl<T: DdsType> SampleCodec<T> for Derived {
    fn keyed(&self) -> bool {
        T::IS_KEYED
    }
    fn decode(&self, payload: &mut Payload, spare: &mut Vec<T>) -> Result<T, cdr::DecodeError> {
        local_or_deserialize::<T>(payload, spare)
    }
    fn decode_key(&self, payload: &[u8]) -> Result<T, cdr::DecodeError> {
        cdr::deserialize_key::<T>(payload)
    }
    fn instance_key(&self, v: &T, out: &mut Vec<u8>) -> Result<(), cdr::EncodeError> {
        cdr::instance_key(v, out)
    }
    fn key_hash(&self, v: &T, version: cdr::XcdrVersion) -> Result<[u8; 16], cdr::EncodeError> {
        cdr::key_hash(v, version)
    }
}

/// [`decode_change_with`] for a derived type.
#[cfg(test)]
pub(crate) fn decode_change<T: DdsType>(
    s: ReceivedSample,
    info: RemoteWriterInfo,
    decoding: &mut Decoding<T>,
    key: Vec<u8>,
    now: Instant,
    rx_time: SystemTime,
) -> Option<Incoming<T>> {
    decode_change_with(&Derived, s, info, decoding, key, now, rx_time)
}

/// Turns a received change into a cache input; `None` (logged) when it cannot be decoded or mapped to an
/// instance. Instances are identified by their serialized key ([`SampleCodec::instance_key`]); a key-only
/// change without a decodable key payload is mapped through its key hash to an instance seen before with the
/// same hash.
pub(crate) fn decode_change_with<T, C: SampleCodec<T>>(
    codec: &C,
    mut s: ReceivedSample,
    info: RemoteWriterInfo,
    decoding: &mut Decoding<T>,
    mut key: Vec<u8>,
    now: Instant,
    rx_time: SystemTime,
) -> Option<Incoming<T>> {
    let source_timestamp = system_time(s.source_timestamp);
    let kind = s.kind;
    let Decoding {
        by_hash,
        last_hash,
        spare,
    } = decoding;
    key.clear();
    let mut data = None;
    let mut key_holder = None;
    if kind == ChangeKind::Alive {
        let d = match codec.decode(&mut s.payload, spare) {
            Ok(d) => d,
            Err(e) => {
                tracing::warn!(writer = ?s.writer, seq = s.sequence.0, error = %e, "dropping undecodable sample");
                return None;
            }
        };
        if codec.keyed() {
            if let Err(e) = codec.instance_key(&d, &mut key) {
                tracing::warn!(error = %e, "cannot compute the instance key");
                return None;
            }
            // Index the key hashes a peer may later send alone (dispose/unregister without payload,
            // e.g. Fast DDS): the one it sent, else the ones we compute for either representation.
            let hashes = match s.key_hash {
                Some(kh) => [Some(kh), None],
                None => [
                    codec.key_hash(&d, cdr::XcdrVersion::Xcdr1).ok(),
                    codec.key_hash(&d, cdr::XcdrVersion::Xcdr2).ok(),
                ],
            };
            for kh in hashes.into_iter().flatten() {
                if *last_hash == Some(kh) {
                    continue;
                }
                if by_hash.len() >= MAX_REMEMBERED_HASHES {
                    by_hash.clear();
                }
                by_hash.entry(kh).or_insert_with(|| key.clone());
                *last_hash = Some(kh);
            }
        }
        data = Some(d);
    } else if codec.keyed() {
        if !s.payload.is_empty() {
            match codec.decode_key(&s.payload) {
                Ok(k) => {
                    if let Err(e) = codec.instance_key(&k, &mut key) {
                        tracing::warn!(error = %e, "cannot compute the instance key");
                        return None;
                    }
                    key_holder = Some(k);
                }
                Err(e) => {
                    tracing::debug!(error = %e, "undecodable key payload; trying the key hash")
                }
            }
        }
        if key_holder.is_none() {
            match s.key_hash.and_then(|kh| by_hash.get(&kh).cloned()) {
                Some(k) => key = k,
                None => {
                    tracing::debug!(writer = ?s.writer, kind = ?s.kind, "key-only change for an unknown instance");
                    return None;
                }
            }
        }
    }
    Some(Incoming {
        writer: s.writer,
        attributed: info.original,
        kind,
        data,
        key,
        key_holder,
        source_timestamp: source_timestamp.unwrap_or(rx_time),
        reception_timestamp: rx_time,
        strength: info.strength,
        expires: info.lifespan.and_then(|l| {
            // Lifespan counts from the source timestamp; its age so far is spent already.
            let age = source_timestamp
                .and_then(|t| rx_time.duration_since(t).ok())
                .unwrap_or_default();
            now.checked_add(l.saturating_sub(age))
        }),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cdr::{ByteOrder, XcdrVersion};
    use crate::rtps::{EntityId, Guid, GuidPrefix, Payload, SequenceNumber};

    #[derive(dds_macros::DdsType, Debug, Clone, PartialEq, Default)]
    #[dds(name = "test::K", appendable)]
    struct K {
        #[dds(key)]
        id: String,
        v: i32,
    }

    fn rs(kind: ChangeKind, payload: Vec<u8>, key_hash: Option<[u8; 16]>) -> ReceivedSample {
        ReceivedSample {
            reader: EntityId([0, 0, 1, 7]),
            writer: Guid::new(GuidPrefix([1; 12]), EntityId([0, 0, 1, 2])),
            sequence: SequenceNumber(1),
            kind,
            payload: Payload::from(payload),
            key_hash,
            source_timestamp: None,
            group_sequence: None,
        }
    }

    /// `decode_change` from a writer with default QoS, now.
    fn decode(s: ReceivedSample, decoding: &mut Decoding<K>) -> Option<Incoming<K>> {
        let now = Instant::now();
        decode_change::<K>(
            s,
            RemoteWriterInfo::default(),
            decoding,
            Vec::new(),
            now,
            SystemTime::now(),
        )
    }

    #[test]
    fn key_only_changes_map_by_key_payload_or_known_hash() {
        let mut by_hash = Decoding::new();
        let s = K {
            id: "a".into(),
            v: 1,
        };
        let mut buf = Vec::new();
        cdr::serialize(&s, XcdrVersion::Xcdr2, ByteOrder::NATIVE, &mut buf).unwrap();
        let kh = cdr::key_hash(&s, XcdrVersion::Xcdr2).unwrap();
        let alive = decode(rs(ChangeKind::Alive, buf, Some(kh)), &mut by_hash).unwrap();
        assert_eq!(alive.data.as_ref(), Some(&s));
        let mut expected = Vec::new();
        cdr::instance_key(&s, &mut expected).unwrap();
        assert_eq!(alive.key, expected);

        let mut kp = Vec::new();
        cdr::serialize_key(&s, XcdrVersion::Xcdr2, ByteOrder::NATIVE, &mut kp).unwrap();
        let d = decode(rs(ChangeKind::Dispose, kp, None), &mut by_hash).unwrap();
        assert_eq!(d.key, expected, "by key payload");
        assert_eq!(d.kind, ChangeKind::Dispose);

        let u = decode(
            rs(ChangeKind::Unregister, Vec::new(), Some(kh)),
            &mut by_hash,
        )
        .unwrap();
        assert_eq!(u.key, expected, "by a key hash seen before");

        let unknown = rs(ChangeKind::Dispose, Vec::new(), Some([9; 16]));
        assert!(decode(unknown, &mut by_hash).is_none());
        let garbage = rs(
            ChangeKind::Alive,
            vec![0, 7, 0, 0, 0xff, 0xff, 0xff, 0x7f],
            None,
        );
        assert!(decode(garbage, &mut by_hash).is_none());
    }

    /// Fast DDS disposes with only PID_KEY_HASH; the alive samples before may have come without one.
    #[test]
    fn key_hash_only_dispose_maps_to_instance_seen_without_hash() {
        let s = K {
            id: "a-rather-long-key-beyond-16-bytes".into(),
            v: 1,
        };
        let mut expected = Vec::new();
        cdr::instance_key(&s, &mut expected).unwrap();
        for version in [XcdrVersion::Xcdr1, XcdrVersion::Xcdr2] {
            let mut by_hash = Decoding::new();
            let mut buf = Vec::new();
            cdr::serialize(&s, version, ByteOrder::NATIVE, &mut buf).unwrap();
            decode(rs(ChangeKind::Alive, buf, None), &mut by_hash).unwrap();
            let kh = cdr::key_hash(&s, version).unwrap();
            let d = decode(rs(ChangeKind::Dispose, Vec::new(), Some(kh)), &mut by_hash)
                .expect("dispose mapped through the computed key hash");
            assert_eq!(d.key, expected);
            assert_eq!(d.kind, ChangeKind::Dispose);
        }
    }

    /// A value given back is decoded into (its string keeps its buffer), and the sample is the new one.
    #[test]
    fn a_kept_value_is_decoded_into() {
        let mut decoding = Decoding::new();
        let mut old = K {
            id: String::with_capacity(64),
            v: 0,
        };
        old.id.push_str("old");
        let buffer = old.id.as_ptr();
        assert!(decoding.has_room());
        decoding.keep(old);
        let s = K {
            id: "new".into(),
            v: 7,
        };
        let mut buf = Vec::new();
        cdr::serialize(&s, XcdrVersion::Xcdr2, ByteOrder::NATIVE, &mut buf).unwrap();
        let d = decode(rs(ChangeKind::Alive, buf.clone(), None), &mut decoding).unwrap();
        let d = d.data.unwrap();
        assert_eq!(d, s);
        assert_eq!(
            d.id.as_ptr(),
            buffer,
            "decoded into the kept value's string"
        );
        // None left: the next one is a fresh value.
        let d2 = decode(rs(ChangeKind::Alive, buf, None), &mut decoding).unwrap();
        assert_eq!(d2.data.unwrap(), s);
        for _ in 0..MAX_SPARE_VALUES {
            decoding.keep(s.clone());
        }
        assert!(!decoding.has_room());
    }
}
