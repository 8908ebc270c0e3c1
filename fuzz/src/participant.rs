//! Arbitrary datagrams into a live sans-I/O `Participant` that has discovered a peer and matched a reader and
//! a writer with it, so hostile input reaches the reliable reader/writer state machines, defragmentation and
//! discovery. Must never panic, and timers keep working afterwards.

use std::sync::{Arc, OnceLock};
use std::time::{Duration, Instant};

use dds_runtime::qos::{DataReaderQos, DataWriterQos, Durability, Reliability};
use dds_runtime::rtps::discovery::{ParticipantData, ReaderData, WriterData};
use dds_runtime::rtps::messages::{Data, Header, MessageBuilder, Submessage};
use dds_runtime::rtps::*;

const PEER: GuidPrefix = GuidPrefix([0x01, 0x10, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10]);

/// Datagrams that make a fresh participant discover PEER with one writer and one reader on topic "F".
fn discovery() -> &'static Vec<Vec<u8>> {
    static D: OnceLock<Vec<Vec<u8>>> = OnceLock::new();
    D.get_or_init(|| {
        let h = Header {
            version: ProtocolVersion::V2_5,
            vendor_id: VendorId::CYCLONE,
            guid_prefix: PEER,
        };
        let spdp = ParticipantData {
            guid_prefix: PEER,
            vendor_id: VendorId::CYCLONE,
            domain_id: Some(0),
            metatraffic_unicast: vec![Locator::udpv4([127, 0, 0, 2], 7410)],
            default_unicast: vec![Locator::udpv4([127, 0, 0, 2], 7411)],
            builtin_endpoints: dds_runtime::rtps::discovery::builtin::OURS,
            ..Default::default()
        }
        .encode();
        let rq = DataReaderQos::builder()
            .reliability(Reliability::RELIABLE)
            .build();
        let w = WriterData {
            guid: Guid::new(PEER, EntityId([0, 0, 1, 2])),
            topic_name: "F".into(),
            type_name: "T".into(),
            ..Default::default()
        }
        .encode();
        let r = ReaderData {
            guid: Guid::new(PEER, EntityId([0, 0, 2, 7])),
            topic_name: "F".into(),
            type_name: "T".into(),
            qos: Arc::new(rq.into()),
            ..Default::default()
        }
        .encode();
        let mut out = Vec::new();
        for (wid, sn, payload) in [
            (EntityId::SPDP_WRITER, 1, &spdp),
            (EntityId::SEDP_PUBLICATIONS_WRITER, 1, &w),
            (EntityId::SEDP_SUBSCRIPTIONS_WRITER, 1, &r),
        ] {
            let mut b = MessageBuilder::new(&h);
            b.push(&Submessage::Data(Data {
                reader_id: EntityId::UNKNOWN,
                writer_id: wid,
                writer_sn: SequenceNumber(sn),
                inline_qos: None,
                payload: Some(payload),
                key_flag: false,
                non_standard_flag: false,
            }));
            out.push(b.finish());
        }
        out
    })
}

/// One input: several datagrams, split at 0xfe bytes, from the discovered peer.
pub fn participant_one(data: &[u8]) {
    let now = Instant::now();
    let c = ParticipantConfig::builder(0, 0, GuidPrefix([7; 12]), [127, 0, 0, 1])
        .expect("domain 0 ports are in range")
        .defrag_max_bytes(1usize << 20)
        .build();
    let mut p = Participant::new(c, now);
    let wq = DataWriterQos::builder()
        .durability(Durability::TransientLocal)
        .build();
    let w = p
        .create_writer(now, WriterSpec::new("F", "T", true, wq))
        .unwrap();
    let rq = DataReaderQos::builder()
        .reliability(Reliability::RELIABLE)
        .build();
    p.create_reader(now, ReaderSpec::new("F", "T", true, rq))
        .unwrap();
    for d in discovery() {
        p.handle_datagram(now, d);
    }
    let _ = p.write(
        now,
        w,
        WriteChange::alive(vec![0, 1, 0, 0, 1, 2, 3, 4]).with_key_hash([1; 16]),
    );
    // The input is several datagrams, split at 0xfe bytes, all claiming to come from PEER.
    for chunk in data.split(|&b| b == 0xfe) {
        let mut msg = b"RTPS\x02\x05\x01\x10".to_vec();
        msg.extend_from_slice(&PEER.0);
        msg.extend_from_slice(chunk);
        // Both receive paths: copying payloads out, and samples sharing the datagram's buffer.
        p.handle_datagram(now, &msg);
        p.handle_shared_datagram(now, &Payload::from(msg));
        p.handle_datagram(now, chunk);
    }
    let later = now + Duration::from_secs(1);
    p.handle_timeout(later);
    while p.poll_transmit(later).is_some() {}
    while p.poll_event().is_some() {}
    assert!(p.poll_timeout().is_some());
}
