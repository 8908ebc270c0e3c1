//! Message codec: round trips of every submessage in both byte orders, and hostile input (every truncation,
//! bit flips, random bytes) that must never panic, in the decoder and in a live participant.

mod rtps_support;

use std::time::{Duration, Instant};

use dds_runtime::rtps::messages::parameter::pid;
use dds_runtime::rtps::messages::*;
use dds_runtime::rtps::*;
use rtps_support::Rng;

fn sn_set(base: i64, bits: &[u32]) -> SequenceNumberSet {
    let mut s = SequenceNumberSet::empty(SequenceNumber(base));
    for b in bits {
        s.insert_offset(*b);
    }
    s
}

fn all_submessages<'a>(
    inline: ParameterList<'a>,
    payload: &'a [u8],
    reply: &'a [u8],
) -> Vec<Submessage<'a>> {
    let r = EntityId([0, 0, 1, 7]);
    let w = EntityId([0, 0, 1, 2]);
    let mut fs = FragmentNumberSet::empty(3);
    fs.insert(3);
    fs.insert(40);
    vec![
        Submessage::Pad,
        Submessage::AckNack(AckNack {
            reader_id: r,
            writer_id: w,
            reader_sn_state: sn_set(5, &[0, 3, 255]),
            count: 9,
            final_flag: true,
        }),
        Submessage::AckNack(AckNack {
            reader_id: r,
            writer_id: w,
            reader_sn_state: sn_set(1, &[]),
            count: 1,
            final_flag: false,
        }),
        Submessage::Heartbeat(Heartbeat {
            reader_id: EntityId::UNKNOWN,
            writer_id: w,
            first_sn: SequenceNumber(1),
            last_sn: SequenceNumber((7 << 32) + 3),
            count: 4,
            final_flag: false,
            liveliness_flag: true,
            group_info: None,
        }),
        Submessage::Heartbeat(Heartbeat {
            reader_id: EntityId::UNKNOWN,
            writer_id: w,
            first_sn: SequenceNumber(3),
            last_sn: SequenceNumber(9),
            count: 5,
            final_flag: true,
            liveliness_flag: false,
            group_info: Some(HeartbeatGroupInfo {
                current_gsn: SequenceNumber(40),
                first_gsn: SequenceNumber(11),
                last_gsn: SequenceNumber((1 << 32) + 38),
                writer_set: [1, 2, 3, 4],
                secure_writer_set: [0; 4],
            }),
        }),
        Submessage::Gap(Gap {
            reader_id: r,
            writer_id: w,
            gap_start: SequenceNumber(2),
            gap_list: sn_set(9, &[1, 31, 32]),
        }),
        Submessage::InfoTs(Some(Time {
            seconds: 1_700_000_000,
            fraction: 0x8000_0000,
        })),
        Submessage::InfoTs(None),
        Submessage::InfoSrc(messages::InfoSource {
            version: ProtocolVersion::V2_5,
            vendor_id: VendorId::THIS,
            guid_prefix: GuidPrefix([3; 12]),
        }),
        Submessage::InfoDst(GuidPrefix([4; 12])),
        Submessage::InfoReplyIp4(messages::InfoReplyIp4 {
            unicast: Locator::udpv4([10, 1, 2, 3], 7411),
            multicast: Some(Locator::udpv4([239, 255, 0, 1], 7401)),
        }),
        Submessage::decode(id::INFO_REPLY, 0x01, reply).unwrap(),
        Submessage::Data(Data {
            reader_id: r,
            writer_id: w,
            writer_sn: SequenceNumber(77),
            inline_qos: Some(inline),
            payload: Some(payload),
            key_flag: false,
            non_standard_flag: false,
        }),
        Submessage::Data(Data {
            reader_id: r,
            writer_id: w,
            writer_sn: SequenceNumber(78),
            inline_qos: Some(inline),
            payload: Some(&payload[..4]),
            key_flag: true,
            non_standard_flag: false,
        }),
        Submessage::Data(Data {
            reader_id: r,
            writer_id: w,
            writer_sn: SequenceNumber(79),
            inline_qos: None,
            payload: None,
            key_flag: false,
            non_standard_flag: false,
        }),
        Submessage::DataFrag(DataFrag {
            reader_id: r,
            writer_id: w,
            writer_sn: SequenceNumber(80),
            fragment_starting_num: 2,
            fragments_in_submessage: 2,
            fragment_size: 4,
            sample_size: 100,
            inline_qos: Some(inline),
            payload: &payload[..8],
            key_flag: false,
            non_standard_flag: false,
        }),
        Submessage::HeartbeatFrag(HeartbeatFrag {
            reader_id: r,
            writer_id: w,
            writer_sn: SequenceNumber(80),
            last_fragment_num: 25,
            count: 2,
        }),
        Submessage::NackFrag(NackFrag {
            reader_id: r,
            writer_id: w,
            writer_sn: SequenceNumber(80),
            fragment_number_state: fs,
            count: 3,
        }),
        Submessage::Unknown {
            id: 0x80,
            flags: 0x00,
            body: &payload[..8],
        },
    ]
}

fn inline_qos_bytes(le: bool) -> Vec<u8> {
    let mut v = Vec::new();
    let mut w = ParameterWriter::new(&mut v, le);
    w.raw(pid::KEY_HASH, &[9; 16]);
    w.raw(pid::STATUS_INFO, &[0, 0, 0, 1]);
    w.without_sentinel();
    v
}

fn reply_body(le: bool) -> Vec<u8> {
    let put32 = |v: &mut Vec<u8>, x: u32| {
        v.extend_from_slice(&if le { x.to_le_bytes() } else { x.to_be_bytes() })
    };
    let mut b = Vec::new();
    put32(&mut b, 2);
    for port in [7411u32, 7413] {
        put32(&mut b, 1);
        put32(&mut b, port);
        b.extend_from_slice(&[0; 12]);
        b.extend_from_slice(&[127, 0, 0, 1]);
    }
    b
}

#[test]
fn every_submessage_round_trips_in_both_byte_orders() {
    let payload: Vec<u8> = (0..16).collect();
    for le in [true, false] {
        let q = inline_qos_bytes(le);
        let inline = ParameterList {
            data: &q,
            little_endian: le,
        };
        let reply = reply_body(true);
        let subs = all_submessages(inline, &payload, &reply);
        for sub in &subs {
            let mut buf = Vec::new();
            sub.encode(&mut buf, le);
            assert_eq!(buf.len() % 4, 0);
            assert_eq!(buf[1] & 1 != 0, le);
            let mut it = MessageIter::new(&buf);
            let back = it.next().unwrap().unwrap();
            assert!(it.next().is_none());
            // Inline QoS re-encoded in the other byte order compares by content.
            match (sub, &back) {
                (Submessage::Data(a), Submessage::Data(b)) => {
                    assert_eq!(
                        (a.writer_sn, a.payload, a.key_flag),
                        (b.writer_sn, b.payload, b.key_flag)
                    );
                    assert_eq!(
                        a.inline_qos.map(|q| q.key_hash()),
                        b.inline_qos.map(|q| q.key_hash())
                    );
                    assert_eq!(
                        a.inline_qos.map(|q| q.status_info()),
                        b.inline_qos.map(|q| q.status_info())
                    );
                }
                (Submessage::DataFrag(a), Submessage::DataFrag(b)) => {
                    assert_eq!(
                        (a.fragment_starting_num, a.payload, a.sample_size),
                        (b.fragment_starting_num, b.payload, b.sample_size)
                    );
                    assert_eq!(
                        a.inline_qos.map(|q| q.key_hash()),
                        b.inline_qos.map(|q| q.key_hash())
                    );
                }
                (Submessage::InfoReply(a), Submessage::InfoReply(b)) => {
                    assert_eq!(
                        a.unicast().collect::<Vec<_>>(),
                        b.unicast().collect::<Vec<_>>()
                    );
                    assert_eq!(a.unicast().count(), 2);
                }
                (
                    Submessage::Unknown { id: a, body: x, .. },
                    Submessage::Unknown { id: b, body: y, .. },
                ) => {
                    assert_eq!((a, x), (b, y));
                }
                (a, b) => assert_eq!(a, b),
            }
        }
    }
}

/// A message holding every submessage, with our header.
fn big_message(le: bool) -> Vec<u8> {
    let payload: Vec<u8> = (0..16).collect();
    let q = inline_qos_bytes(le);
    let reply = reply_body(true);
    let mut msg = Vec::new();
    Header {
        version: ProtocolVersion::V2_5,
        vendor_id: VendorId::THIS,
        guid_prefix: GuidPrefix([1; 12]),
    }
    .write(&mut msg);
    for s in all_submessages(
        ParameterList {
            data: &q,
            little_endian: le,
        },
        &payload,
        &reply,
    ) {
        s.encode(&mut msg, le);
    }
    msg
}

#[test]
fn octets_to_next_header_zero_means_rest_of_message() {
    let payload = [0u8, 1, 0, 0, 5, 6, 7, 8];
    let d = Submessage::Data(Data {
        reader_id: EntityId::UNKNOWN,
        writer_id: EntityId([0, 0, 1, 3]),
        writer_sn: SequenceNumber(1),
        inline_qos: None,
        payload: Some(&payload),
        key_flag: false,
        non_standard_flag: false,
    });
    let mut buf = Vec::new();
    d.encode(&mut buf, true);
    buf[2] = 0;
    buf[3] = 0;
    let back: Vec<_> = MessageIter::new(&buf).collect();
    assert_eq!(back.len(), 1);
    let Ok(Submessage::Data(x)) = back[0] else {
        panic!()
    };
    assert_eq!(x.payload, Some(&payload[..]));
    // PAD and INFO_TS with 0 are empty, and what follows them is still parsed.
    let mut buf = Vec::new();
    Submessage::Pad.encode(&mut buf, true);
    Submessage::InfoTs(None).encode(&mut buf, true);
    d.encode(&mut buf, true);
    assert_eq!(MessageIter::new(&buf).filter(|r| r.is_ok()).count(), 3);
}

#[test]
fn unknown_and_vendor_submessages_are_skipped() {
    let mut msg = big_message(true);
    // A vendor submessage (0x80) and an unknown standard one (0x05) in the middle.
    let mut extra = Vec::new();
    Submessage::Unknown {
        id: 0x05,
        flags: 0,
        body: &[1, 2, 3, 4],
    }
    .encode(&mut extra, true);
    msg.splice(20..20, extra);
    let subs: Vec<_> = MessageIter::parse(&msg)
        .unwrap()
        .1
        .collect::<Result<_, _>>()
        .unwrap();
    assert!(matches!(subs[0], Submessage::Unknown { id: 0x05, .. }));
    assert!(subs.iter().any(|s| matches!(s, Submessage::Heartbeat(_))));
}

#[test]
fn must_understand_inline_qos_drops_the_sample_not_the_reader() {
    // A DATA whose inline QoS has an unknown must-understand PID: the decoder keeps it raw; the check rejects it.
    let mut q = Vec::new();
    let mut w = ParameterWriter::new(&mut q, true);
    w.raw(0x4abc, &[0; 4]);
    w.without_sentinel();
    let pl = ParameterList {
        data: &q,
        little_endian: true,
    };
    assert!(pl.check_must_understand(|p| p == pid::KEY_HASH).is_err());
    let mut q2 = Vec::new();
    let mut w = ParameterWriter::new(&mut q2, true);
    w.raw(0xc000, &[0; 4]);
    w.without_sentinel();
    assert!(ParameterList {
        data: &q2,
        little_endian: true
    }
    .check_must_understand(|_| false)
    .is_ok());
}

#[test]
fn every_truncation_is_rejected_or_shorter_never_a_panic() {
    for le in [true, false] {
        let msg = big_message(le);
        let full = MessageIter::parse(&msg).unwrap().1.count();
        for n in 0..msg.len() {
            let cut = &msg[..n];
            match MessageIter::parse(cut) {
                Err(_) => assert!(n < 20),
                Ok((_, it)) => {
                    let items: Vec<_> = it.collect();
                    let ok = items.iter().filter(|r| r.is_ok()).count();
                    assert!(ok <= full);
                }
            }
        }
    }
}

fn fixtures() -> Vec<Vec<u8>> {
    let dir = format!("{}/tests/fixtures/rtps", env!("CARGO_MANIFEST_DIR"));
    let mut v: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .filter_map(|e| e.ok())
        .filter(|e| e.path().extension().is_some_and(|x| x == "bin"))
        .map(|e| std::fs::read(e.path()).unwrap())
        .collect();
    v.push(big_message(true));
    v.push(big_message(false));
    v
}

/// A participant that knows the Cyclone peers of the fixtures, so hostile input reaches deep code paths.
fn primed_participant(now: Instant) -> Participant {
    let mut p = Participant::new(
        ParticipantConfig::new(0, 3, GuidPrefix([7; 12]), [127, 0, 0, 1]).unwrap(),
        now,
    );
    let rq = dds_runtime::qos::DataReaderQos::builder()
        .reliability(dds_runtime::qos::Reliability::RELIABLE)
        .build();
    p.create_reader(now, ReaderSpec::new("GoldenTopic", "Golden::Msg", true, rq))
        .unwrap();
    p.create_writer(
        now,
        WriterSpec::new(
            "GoldenTopic",
            "Golden::Msg",
            true,
            dds_runtime::qos::DataWriterQos::default(),
        ),
    )
    .unwrap();
    for f in fixtures() {
        p.handle_datagram(now, &f);
    }
    p
}

fn drain(p: &mut Participant, now: Instant) {
    while p.poll_transmit(now).is_some() {}
    while p.poll_event().is_some() {}
}

#[test]
fn participant_survives_truncations_and_bit_flips() {
    let now = Instant::now();
    let mut p = primed_participant(now);
    let mut rng = Rng::new(11);
    for f in fixtures() {
        for n in 0..f.len() {
            p.handle_datagram(now, &f[..n]);
        }
        for _ in 0..300 {
            let mut m = f.clone();
            for _ in 0..1 + rng.below(4) {
                let i = rng.below(m.len() as u64) as usize;
                m[i] ^= 1 << rng.below(8);
            }
            p.handle_datagram(now, &m);
        }
        drain(&mut p, now);
    }
    p.handle_timeout(now + Duration::from_secs(1));
    drain(&mut p, now);
}

#[test]
fn random_bytes_never_panic() {
    let now = Instant::now();
    let mut p = primed_participant(now);
    let mut rng = Rng::new(5);
    let mut buf = Vec::new();
    for i in 0..20_000 {
        buf.clear();
        let len = rng.below(300) as usize;
        // Half of them get a valid header so the submessage parser is exercised.
        if i % 2 == 0 {
            buf.extend_from_slice(b"RTPS\x02\x05\x01\x10");
            buf.extend_from_slice(&[
                0x01, 0x10, 0xc9, 0x2b, 0xcb, 0xc0, 0x5a, 0x23, 0x8b, 0x86, 0xce, 0x17,
            ]);
        }
        buf.extend((0..len).map(|_| rng.next_u64() as u8));
        let _ = MessageIter::parse(&buf).map(|(_, it)| it.count());
        p.handle_datagram(now, &buf);
        if i % 1000 == 0 {
            drain(&mut p, now);
        }
    }
}

#[test]
fn hostile_lengths_do_not_allocate_or_stall() {
    // A DATA_FRAG claiming a 4 GiB sample, fragments of 1 byte, and a huge locator count in INFO_REPLY.
    let df = Submessage::DataFrag(DataFrag {
        reader_id: EntityId::UNKNOWN,
        writer_id: EntityId([0, 0, 1, 2]),
        writer_sn: SequenceNumber(1),
        fragment_starting_num: 1,
        fragments_in_submessage: 1,
        fragment_size: 1,
        sample_size: u32::MAX,
        inline_qos: None,
        payload: &[0],
        key_flag: false,
        non_standard_flag: false,
    });
    let mut buf = Vec::new();
    df.encode(&mut buf, true);
    let Ok(Submessage::DataFrag(d)) = MessageIter::new(&buf).next().unwrap() else {
        panic!()
    };
    assert_eq!(d.total_fragments(), u32::MAX);
    let mut reply = vec![0x0f, 0x01, 8, 0, 0xff, 0xff, 0xff, 0x7f, 0, 0, 0, 0];
    reply.truncate(12);
    assert!(MessageIter::new(&reply).next().unwrap().is_err());
    // A parameter list with a length running past the end.
    let bad = [0x00u8, 0x03, 0, 0, 0x05, 0x00, 0xff, 0xff, 1, 2];
    assert!(dds_runtime::rtps::discovery::ReaderData::decode(&bad).is_err());
}
