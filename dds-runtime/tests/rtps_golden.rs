//! Decoding real Cyclone DDS 11 datagrams (tests/fixtures/rtps, see its README), and a full receive path:
//! Cyclone's SPDP and SEDP make our participant match a local reader, whose samples (fragmented ones too,
//! plus a dispose and an unregister) then arrive from the captured datagrams.

use std::time::{Duration, Instant};

use dds_runtime::qos::*;
use dds_runtime::rtps::discovery::{ParticipantData, ReaderData, WriterData};
use dds_runtime::rtps::messages::*;
use dds_runtime::rtps::*;

fn fixture(name: &str) -> Vec<u8> {
    let p = format!("{}/tests/fixtures/rtps/{name}", env!("CARGO_MANIFEST_DIR"));
    std::fs::read(&p).unwrap_or_else(|e| panic!("{p}: {e}"))
}

const ALL: &[&str] = &[
    "spdp_multicast.bin",
    "spdp_multicast_2.bin",
    "heartbeats.bin",
    "acknacks.bin",
    "acknack.bin",
    "participant_message.bin",
    "sedp_subscription.bin",
    "sedp_publication.bin",
    "data_1.bin",
    "data_2.bin",
    "data_3.bin",
    "data_frag_1.bin",
    "data_frag_2.bin",
    "data_frag_3.bin",
    "data_frag_4.bin",
    "data_frag_5.bin",
    "heartbeat_frag.bin",
    "dispose.bin",
    "unregister.bin",
];

fn submessages(msg: &[u8]) -> (Header, Vec<Submessage<'_>>) {
    let (h, it) = MessageIter::parse(msg).unwrap();
    (h, it.collect::<Result<Vec<_>, _>>().unwrap())
}

#[test]
fn every_fixture_decodes_completely() {
    for name in ALL {
        let msg = fixture(name);
        let (h, subs) = submessages(&msg);
        assert_eq!(h.version, ProtocolVersion::V2_5, "{name}");
        assert_eq!(h.vendor_id, VendorId::CYCLONE, "{name}");
        assert!(!subs.is_empty(), "{name}");
        assert!(
            subs.iter()
                .all(|s| !matches!(s, Submessage::Unknown { .. })),
            "{name}: {subs:?}"
        );
    }
}

fn data_payloads<'a>(subs: &[Submessage<'a>]) -> Vec<Data<'a>> {
    subs.iter()
        .filter_map(|s| {
            if let Submessage::Data(d) = s {
                Some(*d)
            } else {
                None
            }
        })
        .collect()
}

#[test]
fn cyclone_spdp() {
    let msg = fixture("spdp_multicast.bin");
    let (h, subs) = submessages(&msg);
    let datas = data_payloads(&subs);
    assert_eq!(datas[0].writer_id, EntityId::SPDP_WRITER);
    let p = ParticipantData::decode(datas[0].payload.unwrap()).unwrap();
    assert_eq!(p.guid_prefix, h.guid_prefix);
    assert_eq!(p.vendor_id, VendorId::CYCLONE);
    assert_eq!(p.protocol_version, ProtocolVersion::V2_5);
    assert_eq!(p.domain_id, Some(0));
    // Cyclone's default lease is 10 s.
    assert_eq!(p.lease_duration, Duration::from_secs(10));
    let b = p.builtin_endpoints;
    use dds_runtime::rtps::discovery::builtin::*;
    for bit in [
        PUBLICATIONS_ANNOUNCER,
        PUBLICATIONS_DETECTOR,
        SUBSCRIPTIONS_ANNOUNCER,
        SUBSCRIPTIONS_DETECTOR,
        PARTICIPANT_MESSAGE_WRITER,
    ] {
        assert!(b & bit != 0, "{b:#x} lacks {bit:#x}");
    }
    assert!(p
        .metatraffic_unicast
        .iter()
        .all(|l| l.kind == Locator::KIND_UDPV4));
    assert!(!p.default_unicast.is_empty());
    // Cyclone 11 picks ephemeral unicast ports (not the PB/DG/PG formula) unless a participant index is set.
    assert!(p.metatraffic_unicast[0].port > 0 && p.metatraffic_unicast[0].port < 65536);
    // Our own encoding of the same data decodes to the same value.
    assert_eq!(ParticipantData::decode(&p.encode()).unwrap(), p);
}

#[test]
fn cyclone_sedp_with_type_information() {
    let msg = fixture("sedp_publication.bin");
    let (_, subs) = submessages(&msg);
    let d = data_payloads(&subs)[0];
    assert_eq!(d.writer_id, EntityId::SEDP_PUBLICATIONS_WRITER);
    let w = WriterData::decode(d.payload.unwrap()).unwrap();
    assert_eq!(w.topic_name, "GoldenTopic");
    assert_eq!(w.type_name, "Golden::Msg");
    assert_eq!(w.guid.entity_id.kind(), entity_kind::USER_WRITER_WITH_KEY);
    assert_eq!(w.qos.writer.durability, Durability::TransientLocal);
    assert_eq!(w.qos.writer.history, History::KeepLast(4));
    // Absent from the wire: the writer default, reliable.
    assert!(w.qos.writer.reliability.is_reliable());
    let ti = w.type_information.as_ref().expect("TYPE_INFORMATION kept");
    assert!(ti.0.len() > 40);

    let msg = fixture("sedp_subscription.bin");
    let (_, subs) = submessages(&msg);
    let d = data_payloads(&subs)[0];
    assert_eq!(d.writer_id, EntityId::SEDP_SUBSCRIPTIONS_WRITER);
    let r = ReaderData::decode(d.payload.unwrap()).unwrap();
    assert_eq!(r.topic_name, "GoldenTopic");
    assert_eq!(r.qos.reader.durability, Durability::TransientLocal);
    assert!(r.qos.reader.reliability.is_reliable());
    match r.qos.reader.reliability {
        Reliability::Reliable { max_blocking_time } => {
            assert!(
                max_blocking_time.abs_diff(Duration::from_millis(100)) < Duration::from_micros(1),
                "{max_blocking_time:?}"
            )
        }
        _ => unreachable!(),
    }
    assert!(r.type_information.is_some());
    // They match each other.
    let m = dds_runtime::rtps::discovery::matching::match_endpoints(&w, &r);
    assert_eq!(
        m,
        dds_runtime::rtps::discovery::matching::MatchResult::Match
    );
}

#[test]
fn cyclone_fragments_and_status_info() {
    let msg = fixture("data_frag_1.bin");
    let (_, subs) = submessages(&msg);
    let Some(Submessage::DataFrag(f)) = subs.iter().find(|s| matches!(s, Submessage::DataFrag(_)))
    else {
        panic!()
    };
    assert_eq!(f.fragment_starting_num, 1);
    assert_eq!(f.fragment_size, 1024);
    assert!(f.sample_size > 20_000);
    assert_eq!(f.payload.len(), f.fragments_in_submessage as usize * 1024);
    let msg = fixture("dispose.bin");
    let (_, subs) = submessages(&msg);
    let d = data_payloads(&subs)[0];
    assert_eq!(d.inline_qos.unwrap().status_info(), Some(1));
    assert!(d.key_flag);
    let msg = fixture("unregister.bin");
    let (_, subs) = submessages(&msg);
    // unregister_instance with autodispose_unregistered_instances (the default): dispose + unregister.
    assert_eq!(
        data_payloads(&subs)[0].inline_qos.unwrap().status_info(),
        Some(3)
    );
}

#[test]
fn cyclone_writer_delivers_to_our_reader() {
    let now = Instant::now();
    let prefix = GuidPrefix([0x01, 0xdd, 0, 0, 0, 0, 0, 0, 0, 0, 0, 9]);
    let mut p = Participant::new(
        ParticipantConfig::new(0, 5, prefix, [127, 0, 0, 1]).unwrap(),
        now,
    );
    let rq = DataReaderQos::builder()
        .reliability(Reliability::RELIABLE)
        .durability(Durability::TransientLocal)
        .history(History::KeepLast(4))
        .build();
    let r = p
        .create_reader(now, ReaderSpec::new("GoldenTopic", "Golden::Msg", true, rq))
        .unwrap();
    for name in [
        "spdp_multicast.bin",
        "spdp_multicast_2.bin",
        "sedp_publication.bin",
    ] {
        p.handle_datagram(now, &fixture(name));
    }
    let mut events = Vec::new();
    while let Some(e) = p.poll_event() {
        events.push(e);
    }
    assert_eq!(
        events
            .iter()
            .filter(|e| matches!(e, Event::ParticipantDiscovered(_)))
            .count(),
        2
    );
    assert!(
        events
            .iter()
            .any(|e| matches!(e, Event::SubscriptionMatched { matched: true, .. })),
        "{events:?}"
    );
    assert_eq!(p.reader_matches(r).len(), 1);
    // We answer: our SPDP to Cyclone's unicast locator, a pre-emptive ACKNACK, SEDP traffic.
    assert!(p.poll_transmit(now).is_some());

    for name in [
        "data_1.bin",
        "data_2.bin",
        "data_3.bin",
        "data_frag_1.bin",
        "heartbeat_frag.bin",
        "data_frag_2.bin",
        "data_frag_3.bin",
        "data_frag_4.bin",
        "data_frag_5.bin",
        "dispose.bin",
        "unregister.bin",
    ] {
        p.handle_datagram(now, &fixture(name));
    }
    let mut samples = Vec::new();
    while let Some(e) = p.poll_event() {
        if let Event::Sample(s) = e {
            samples.push(s);
        }
    }
    let kinds: Vec<ChangeKind> = samples.iter().map(|s| s.kind).collect();
    use ChangeKind::*;
    assert_eq!(
        kinds,
        vec![Alive, Alive, Alive, Alive, Dispose, DisposeUnregister],
        "{samples:?}"
    );
    for (i, s) in samples.iter().enumerate() {
        assert_eq!(s.sequence, SequenceNumber(i as i64 + 1));
        assert!(s.source_timestamp.is_some());
    }
    // Cyclone sends no key hash with data; the key is in the payload (key-only for dispose/unregister).
    assert_eq!(samples[0].key_hash, None);
    // XCDR1 little-endian: {id: int64 (Python int), text: string}.
    let p0 = &samples[0].payload;
    assert_eq!(&p0[..4], &[0, 1, 0, 0]);
    assert_eq!(i64::from_le_bytes(p0[4..12].try_into().unwrap()), 0);
    assert_eq!(u32::from_le_bytes(p0[12..16].try_into().unwrap()), 8);
    assert_eq!(&p0[16..23], b"hello 0");
    let big = &samples[3].payload;
    assert_eq!(i64::from_le_bytes(big[4..12].try_into().unwrap()), 7);
    assert_eq!(u32::from_le_bytes(big[12..16].try_into().unwrap()), 20001);
    assert!(big[16..16 + 20000].iter().all(|&b| b == b'x'));
    // The dispose of id 1 carries the serialized key.
    let k = &samples[4].payload;
    assert_eq!(&k[..], &[0, 1, 0, 0, 1, 0, 0, 0, 0, 0, 0, 0]);
}

#[test]
fn must_understand_inline_qos_drops_only_that_sample() {
    let now = Instant::now();
    let mut p = Participant::new(
        ParticipantConfig::new(0, 5, GuidPrefix([9; 12]), [127, 0, 0, 1]).unwrap(),
        now,
    );
    let rq = DataReaderQos::builder()
        .reliability(Reliability::RELIABLE)
        .durability(Durability::TransientLocal)
        .build();
    let r = p
        .create_reader(now, ReaderSpec::new("GoldenTopic", "Golden::Msg", true, rq))
        .unwrap();
    for name in [
        "spdp_multicast.bin",
        "spdp_multicast_2.bin",
        "sedp_publication.bin",
    ] {
        p.handle_datagram(now, &fixture(name));
    }
    assert_eq!(p.reader_matches(r).len(), 1);
    // Re-send Cyclone's sample 1 with an extra inline QoS parameter 0x4abc (must-understand, unknown).
    let orig = fixture("data_1.bin");
    let (h, subs) = submessages(&orig);
    let d = data_payloads(&subs)[0];
    let mut q = Vec::new();
    let mut w = ParameterWriter::new(&mut q, true);
    w.raw(0x4abc, &[1, 2, 3, 4]);
    w.without_sentinel();
    let mut b = MessageBuilder::new(&h);
    b.push(&Submessage::Data(Data {
        inline_qos: Some(ParameterList {
            data: &q,
            little_endian: true,
        }),
        ..d
    }));
    p.handle_datagram(now, &b.finish());
    for name in ["data_2.bin", "data_3.bin"] {
        p.handle_datagram(now, &fixture(name));
    }
    let mut seqs = Vec::new();
    while let Some(e) = p.poll_event() {
        if let Event::Sample(s) = e {
            seqs.push(s.sequence.0);
        }
    }
    assert_eq!(seqs, vec![2, 3]);
}
