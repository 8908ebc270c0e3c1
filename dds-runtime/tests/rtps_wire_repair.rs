//! Wire forms chosen per reader and fragment-level repair, checked datagram by datagram:
//!   - key-only changes (dispose, unregister) go to Fast DDS readers as DATA with only inline QoS (key hash,
//!     status info) and to every other reader with the serialized key, in `write` and in repairs;
//!   - a fragmented sample is followed by HEARTBEAT_FRAG, which a reader missing fragments answers with
//!     NACK_FRAG, and the writer with the missing fragments, without any HEARTBEAT.

mod rtps_support;

use std::collections::BTreeSet;
use std::time::{Duration, Instant};

use dds_runtime::qos::*;
use dds_runtime::rtps::messages::{MessageBuilder, MessageIter, Submessage};
use dds_runtime::rtps::*;
use rtps_support::*;

/// One datagram on the simulated wire, from node `from` to node `to`.
struct Sent {
    from: usize,
    to: usize,
    payload: Vec<u8>,
}

/// A lossless network with a hook on every datagram (after routing, before delivery): the hook sees it and
/// may rewrite or drop it. Every datagram delivered is also kept in `log`.
struct Net {
    queue: Vec<(Instant, u64, Sent)>,
    seq: u64,
    log: Vec<Sent>,
}

type Hook<'a> = dyn FnMut(usize, usize, &[u8]) -> Option<Vec<u8>> + 'a;

impl Net {
    fn new() -> Self {
        Net {
            queue: Vec::new(),
            seq: 0,
            log: Vec::new(),
        }
    }

    fn receivers(sim: &Sim, l: &Locator) -> Vec<usize> {
        (0..sim.nodes.len())
            .filter(|&i| {
                let c = sim.nodes[i].p.config();
                c.default_unicast().contains(l)
                    || c.metatraffic_unicast().contains(l)
                    || c.default_multicast().contains(l)
                    || c.metatraffic_multicast().contains(l)
            })
            .collect()
    }

    /// Moves pending transmits through the hook into the queue, and events into the nodes' logs.
    fn pump(&mut self, sim: &mut Sim, hook: &mut Hook<'_>) {
        for i in 0..sim.nodes.len() {
            while let Some(t) = sim.nodes[i].p.poll_transmit(sim.now) {
                let mut to: Vec<usize> = t
                    .destinations
                    .iter()
                    .flat_map(|l| Self::receivers(sim, l))
                    .collect();
                to.sort();
                to.dedup();
                for j in to {
                    if let Some(payload) = hook(i, j, &t.datagram()) {
                        self.seq += 1;
                        let at = sim.now + Duration::from_micros(100);
                        let sent = Sent {
                            from: i,
                            to: j,
                            payload,
                        };
                        self.queue.push((at, self.seq, sent));
                    }
                }
            }
            while let Some(e) = sim.nodes[i].p.poll_event() {
                sim.nodes[i].events.push(e);
            }
        }
    }

    /// Runs until `cond` holds or `limit` passes; returns whether `cond` held.
    fn run_until(
        &mut self,
        sim: &mut Sim,
        limit: Duration,
        hook: &mut Hook<'_>,
        mut cond: impl FnMut(&mut Sim, &[Sent]) -> bool,
    ) -> bool {
        let end = sim.now + limit;
        loop {
            self.pump(sim, hook);
            if cond(sim, &self.log) {
                return true;
            }
            let next_dgram = self.queue.iter().map(|q| q.0).min();
            let next_timer = sim.nodes.iter().filter_map(|n| n.p.poll_timeout()).min();
            let Some(next) = [next_dgram, next_timer].into_iter().flatten().min() else {
                return false;
            };
            if next > end {
                sim.now = end;
                return cond(sim, &self.log);
            }
            sim.now = sim.now.max(next);
            self.queue.sort_by_key(|q| (q.0, q.1));
            while self.queue.first().is_some_and(|q| q.0 <= sim.now) {
                let (_, _, d) = self.queue.remove(0);
                sim.nodes[d.to].p.handle_datagram(sim.now, &d.payload);
                self.log.push(d);
            }
            for n in &mut sim.nodes {
                if n.p.poll_timeout().is_some_and(|t| t <= sim.now) {
                    n.p.handle_timeout(sim.now);
                }
            }
        }
    }
}

/// Re-encodes `msg` without the submessages `drop` selects (`None` if nothing is left but the header).
fn filter(msg: &[u8], mut drop: impl FnMut(&Submessage<'_>) -> bool) -> Option<Vec<u8>> {
    let (h, it) = MessageIter::parse(msg).expect("valid message");
    let mut b = MessageBuilder::new(&h);
    let mut kept = 0;
    for s in it {
        let s = s.expect("valid submessage");
        if drop(&s) {
            continue;
        }
        if !matches!(
            s,
            Submessage::InfoTs(_) | Submessage::InfoDst(_) | Submessage::InfoSrc(_)
        ) {
            kept += 1;
        }
        b.push(&s);
    }
    (kept > 0).then(|| b.finish())
}

/// The submessages of a datagram, owned enough to inspect.
fn submessages(msg: &[u8]) -> Vec<Submessage<'_>> {
    let (_, it) = MessageIter::parse(msg).expect("valid message");
    it.map(|s| s.expect("valid submessage")).collect()
}

fn pass(_: usize, _: usize, m: &[u8]) -> Option<Vec<u8>> {
    Some(m.to_vec())
}

fn reliable_reader() -> DataReaderQos {
    DataReaderQos::builder()
        .reliability(Reliability::RELIABLE)
        .history(History::KeepAll)
        .build()
}

fn wait_matched(sim: &mut Sim, w: EntityId, readers: &[(usize, EntityId)]) {
    let n = readers.len();
    let rs = readers.to_vec();
    assert!(sim.run_until(Duration::from_secs(5), |s| s.nodes[0]
        .p
        .writer_matches(w)
        .len()
        == n
        && rs
            .iter()
            .all(|&(i, r)| !s.nodes[i].p.reader_matches(r).is_empty())));
}

// ---------------------------------------------------------------------------------------------------------
// Key-only changes per reader vendor
// ---------------------------------------------------------------------------------------------------------

const KEY: [u8; 16] = [0, 0, 0, 7, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0];
/// The serialized key of KEY (CDR header + a long): what a key-only change carries as payload.
const SERIALIZED_KEY: [u8; 8] = [0, 1, 0, 0, 7, 0, 0, 0];

/// Writer on node 0; a Fast DDS participant (node 1) and one of ours (node 2), each with a keyed reader.
fn vendor_setup(reliable: bool) -> (Sim, EntityId, EntityId, EntityId) {
    let mut sim = Sim::new(11, Faults::NONE);
    sim.add(config(0));
    sim.add(config(1).vendor_id(VendorId::FASTDDS));
    sim.add(config(2));
    let now = sim.now;
    let wq = DataWriterQos::builder().history(History::KeepAll).build();
    let w = sim.nodes[0]
        .p
        .create_writer(now, WriterSpec::new("K", "M::K", true, wq))
        .unwrap();
    let rq = if reliable {
        reliable_reader()
    } else {
        DataReaderQos::default()
    };
    let r1 = sim.nodes[1]
        .p
        .create_reader(now, ReaderSpec::new("K", "M::K", true, rq.clone()))
        .unwrap();
    let r2 = sim.nodes[2]
        .p
        .create_reader(now, ReaderSpec::new("K", "M::K", true, rq))
        .unwrap();
    wait_matched(&mut sim, w, &[(1, r1), (2, r2)]);
    (sim, w, r1, r2)
}

/// The DATA submessages of writer `w` with sequence number `sn` delivered to node `to`.
fn data_to<'a>(log: &'a [Sent], to: usize, w: EntityId, sn: i64) -> Vec<Submessage<'a>> {
    log.iter()
        .filter(|d| d.to == to)
        .flat_map(|d| submessages(&d.payload))
        .filter(|s| matches!(s, Submessage::Data(d) if d.writer_id == w && d.writer_sn == SequenceNumber(sn)))
        .collect()
}

/// Checks one DATA's form: `serialized` = carries the serialized key with the K flag (else no payload, no
/// D/K flag); both forms carry the key hash and `status` as inline QoS.
fn check_key_only_form(s: &Submessage<'_>, serialized: bool, status: u8) {
    let Submessage::Data(d) = s else {
        panic!("not DATA: {s:?}")
    };
    let q = d.inline_qos.expect("inline QoS");
    assert_eq!(q.key_hash(), Some(KEY));
    assert_eq!(q.status_info(), Some(status));
    if serialized {
        assert!(d.key_flag, "K flag");
        assert_eq!(d.payload, Some(&SERIALIZED_KEY[..]));
    } else {
        assert!(!d.key_flag, "no K flag");
        assert_eq!(d.payload, None, "no payload (neither D nor K)");
    }
}

fn write_key_only(sim: &mut Sim, w: EntityId, kind: ChangeKind) {
    let now = sim.now;
    sim.nodes[0]
        .p
        .write(
            now,
            w,
            WriteChange::alive(SERIALIZED_KEY.to_vec())
                .with_key_hash(KEY)
                .with_kind(kind),
        )
        .unwrap();
}

#[test]
fn key_only_changes_take_each_readers_form() {
    for reliable in [false, true] {
        let (mut sim, w, r1, r2) = vendor_setup(reliable);
        let mut net = Net::new();
        let now = sim.now;
        sim.nodes[0]
            .p
            .write(
                now,
                w,
                WriteChange::alive(SERIALIZED_KEY.to_vec()).with_key_hash(KEY),
            )
            .unwrap();
        write_key_only(&mut sim, w, ChangeKind::Dispose);
        write_key_only(&mut sim, w, ChangeKind::Unregister);
        let mut got = (Vec::new(), Vec::new());
        assert!(
            net.run_until(&mut sim, Duration::from_secs(1), &mut pass, |s, _| {
                got.0.extend(s.take_samples(1, r1));
                got.1.extend(s.take_samples(2, r2));
                got.0.len() == 3 && got.1.len() == 3
            })
        );
        // Alive data: one shared datagram reaches both readers.
        let alive: Vec<&Sent> = net
            .log
            .iter()
            .filter(|d| d.from == 0 && !data_to(std::slice::from_ref(d), d.to, w, 1).is_empty())
            .collect();
        assert_eq!(alive.len(), 2);
        assert_eq!(alive[0].payload, alive[1].payload);
        for (sn, status) in [(2, 1), (3, 2)] {
            let fast = data_to(&net.log, 1, w, sn);
            let ours = data_to(&net.log, 2, w, sn);
            assert_eq!((fast.len(), ours.len()), (1, 1), "sn {sn}");
            check_key_only_form(&fast[0], false, status);
            check_key_only_form(&ours[0], true, status);
        }
        for (r, serialized) in [(&got.0, false), (&got.1, true)] {
            let kinds: Vec<ChangeKind> = r.iter().map(|s| s.kind).collect();
            assert_eq!(
                kinds,
                [
                    ChangeKind::Alive,
                    ChangeKind::Dispose,
                    ChangeKind::Unregister
                ]
            );
            assert!(r.iter().all(|s| s.key_hash == Some(KEY)));
            let key_payload: &[u8] = if serialized { &SERIALIZED_KEY } else { &[] };
            assert_eq!(&r[1].payload[..], key_payload);
        }
    }
}

#[test]
fn repaired_key_only_changes_keep_each_readers_form() {
    let (mut sim, w, r1, r2) = vendor_setup(true);
    let mut net = Net::new();
    write_key_only(&mut sim, w, ChangeKind::Dispose);
    // The first transmission of the dispose is lost to both readers: both get it from repairs addressed to
    // them alone.
    let mut first = BTreeSet::new();
    let mut hook = |from: usize, to: usize, m: &[u8]| {
        if from == 0 && first.insert(to) {
            return filter(m, |s| matches!(s, Submessage::Data(d) if d.writer_id == w));
        }
        Some(m.to_vec())
    };
    let mut got = (Vec::new(), Vec::new());
    assert!(
        net.run_until(&mut sim, Duration::from_secs(2), &mut hook, |s, _| {
            got.0.extend(s.take_samples(1, r1));
            got.1.extend(s.take_samples(2, r2));
            !got.0.is_empty() && !got.1.is_empty()
        })
    );
    let fast = data_to(&net.log, 1, w, 1);
    let ours = data_to(&net.log, 2, w, 1);
    assert_eq!((fast.len(), ours.len()), (1, 1));
    check_key_only_form(&fast[0], false, 1);
    check_key_only_form(&ours[0], true, 1);
    for d in [&fast[0], &ours[0]] {
        let Submessage::Data(d) = d else { panic!() };
        assert_ne!(d.reader_id, EntityId::UNKNOWN, "a repair is addressed");
    }
    assert_eq!(got.0[0].kind, ChangeKind::Dispose);
    assert_eq!(got.1[0].kind, ChangeKind::Dispose);
    assert!(got.0[0].payload.is_empty());
    assert_eq!(&got.1[0].payload[..], &SERIALIZED_KEY);
}

// ---------------------------------------------------------------------------------------------------------
// HEARTBEAT_FRAG / NACK_FRAG
// ---------------------------------------------------------------------------------------------------------

/// 40000 bytes in 1344-byte fragments: 30 fragments (more than half a datagram: not sent whole), ten to
/// a DATA_FRAG with the default datagram size (14 720 bytes): DATA_FRAGs starting at fragments 1, 11 and 21.
const BIG: usize = 40_000;
const FRAGS: u32 = 30;

fn big_sample() -> Vec<u8> {
    let mut v: Vec<u8> = (0..BIG).map(|i| (i * 7 % 251) as u8).collect();
    v[..4].copy_from_slice(&[0, 1, 0, 0]);
    v
}

fn frag_setup() -> (Sim, EntityId, EntityId) {
    let mut sim = Sim::with_participants(5, Faults::NONE, 2);
    let now = sim.now;
    let wq = DataWriterQos::builder().history(History::KeepAll).build();
    let w = sim.nodes[0]
        .p
        .create_writer(now, WriterSpec::new("F", "M::F", false, wq))
        .unwrap();
    let r = sim.nodes[1]
        .p
        .create_reader(now, ReaderSpec::new("F", "M::F", false, reliable_reader()))
        .unwrap();
    wait_matched(&mut sim, w, &[(1, r)]);
    // Let the matching handshake (pre-emptive ACKNACK, first heartbeats) settle.
    sim.run_for(Duration::from_millis(300));
    sim.take_samples(1, r);
    (sim, w, r)
}

fn is_heartbeat_of(s: &Submessage<'_>, w: EntityId) -> bool {
    matches!(s, Submessage::Heartbeat(h) if h.writer_id == w)
}

/// Every submessage delivered from `from` to `to`, in order.
fn subs_between(log: &[Sent], from: usize, to: usize) -> Vec<Submessage<'_>> {
    log.iter()
        .filter(|d| d.from == from && d.to == to)
        .flat_map(|d| submessages(&d.payload))
        .collect()
}

#[test]
fn heartbeat_frag_repairs_missing_fragments_without_heartbeat() {
    let (mut sim, w, r) = frag_setup();
    let mut net = Net::new();
    let start = sim.now;
    let now = sim.now;
    let sn = sim.nodes[0]
        .p
        .write(now, w, WriteChange::alive(big_sample()))
        .unwrap();
    // The DATA_FRAGs of fragments 1-10 and 21-30 are lost once; every HEARTBEAT of the writer is lost, so
    // only HEARTBEAT_FRAG can prompt the repair.
    let mut lost: BTreeSet<u32> = [1, 21].into();
    let mut hook = |from: usize, _: usize, m: &[u8]| {
        if from != 0 {
            return Some(m.to_vec());
        }
        filter(m, |s| match s {
            Submessage::DataFrag(d) if d.writer_id == w => lost.remove(&d.fragment_starting_num),
            s => is_heartbeat_of(s, w),
        })
    };
    let mut got = Vec::new();
    assert!(
        net.run_until(&mut sim, Duration::from_secs(1), &mut hook, |s, _| {
            got.extend(s.take_samples(1, r));
            !got.is_empty()
        })
    );
    assert_eq!(&got[0].payload[..], &big_sample()[..]);
    // Well before the periodic heartbeat (100 ms), which is lost anyway.
    assert!(
        sim.now - start < Duration::from_millis(50),
        "{:?}",
        sim.now - start
    );

    let from_w = subs_between(&net.log, 0, 1);
    let hbfrags: Vec<_> = from_w
        .iter()
        .filter_map(|s| match s {
            Submessage::HeartbeatFrag(h) => Some(*h),
            _ => None,
        })
        .collect();
    assert!(!hbfrags.is_empty());
    assert!(hbfrags
        .iter()
        .all(|h| h.writer_id == w && h.writer_sn == sn && h.last_fragment_num == FRAGS));
    assert!(hbfrags.windows(2).all(|p| p[1].count > p[0].count));
    assert!(!from_w.iter().any(|s| is_heartbeat_of(s, w)));

    let from_r = subs_between(&net.log, 1, 0);
    let nackfrags: Vec<_> = from_r
        .iter()
        .filter_map(|s| match s {
            Submessage::NackFrag(n) => Some(*n),
            _ => None,
        })
        .collect();
    assert_eq!(nackfrags.len(), 1, "{nackfrags:?}");
    assert_eq!(nackfrags[0].writer_sn, sn);
    assert_eq!(
        nackfrags[0]
            .fragment_number_state
            .iter()
            .collect::<Vec<_>>(),
        (1..=10).chain(21..=30).collect::<Vec<u32>>()
    );
    // Only the missing fragments were sent again.
    let mut frags: Vec<(u32, u16)> = from_w
        .iter()
        .filter_map(|s| match s {
            Submessage::DataFrag(d) if d.writer_id == w => {
                Some((d.fragment_starting_num, d.fragments_in_submessage))
            }
            _ => None,
        })
        .collect();
    frags.sort();
    assert_eq!(frags, [(1, 10), (11, 10), (21, 10)]);
}

/// A user sample of which two fit one datagram goes whole, as one DATA (no DATA_FRAG, no HEARTBEAT_FRAG),
/// even when it is larger than the fragment size; the reader gets it intact.
#[test]
fn a_sample_that_fits_a_datagram_goes_whole() {
    let (mut sim, w, r) = frag_setup();
    let mut net = Net::new();
    let sample: Vec<u8> = big_sample()[..6000].to_vec();
    let now = sim.now;
    let sn = sim.nodes[0]
        .p
        .write(now, w, WriteChange::alive(sample.clone()))
        .unwrap();
    let mut hook = |_: usize, _: usize, m: &[u8]| Some(m.to_vec());
    let mut got = Vec::new();
    assert!(
        net.run_until(&mut sim, Duration::from_secs(1), &mut hook, |s, _| {
            got.extend(s.take_samples(1, r));
            !got.is_empty()
        })
    );
    assert_eq!(&got[0].payload[..], &sample[..]);
    let from_w = subs_between(&net.log, 0, 1);
    assert!(from_w.iter().any(
        |s| matches!(s, Submessage::Data(d) if d.writer_id == w && d.writer_sn == sn && d.payload.map(<[u8]>::len) == Some(6000))
    ));
    assert!(!from_w
        .iter()
        .any(|s| matches!(s, Submessage::DataFrag(_) | Submessage::HeartbeatFrag(_))));
}

#[test]
fn heartbeat_frag_ignored_for_complete_or_unknown_samples() {
    let (mut sim, w, r) = frag_setup();
    let mut net = Net::new();
    // Sample 1 arrives whole; sample 2 loses all its fragments once. HEARTBEATs are lost until `hb_ok`.
    let now = sim.now;
    for _ in 0..2 {
        sim.nodes[0]
            .p
            .write(now, w, WriteChange::alive(big_sample()))
            .unwrap();
    }
    let hb_ok = std::cell::Cell::new(false);
    let mut lost: BTreeSet<u32> = (1..=FRAGS).collect();
    let mut hook = |from: usize, _: usize, m: &[u8]| {
        if from != 0 {
            return Some(m.to_vec());
        }
        filter(m, |s| match s {
            Submessage::DataFrag(d) if d.writer_id == w && d.writer_sn == SequenceNumber(2) => {
                lost.remove(&d.fragment_starting_num)
            }
            s => !hb_ok.get() && is_heartbeat_of(s, w),
        })
    };
    let mut got = Vec::new();
    assert!(
        !net.run_until(&mut sim, Duration::from_millis(80), &mut hook, |s, _| {
            got.extend(s.take_samples(1, r));
            got.len() == 2
        })
    );
    assert_eq!(got.len(), 1);
    // The HEARTBEAT_FRAGs of both samples came; neither is answered: sample 1 is complete, and of sample 2
    // the reader holds nothing (whole samples are the HEARTBEAT's business).
    let hbfrag_sns: BTreeSet<i64> = subs_between(&net.log, 0, 1)
        .iter()
        .filter_map(|s| match s {
            Submessage::HeartbeatFrag(h) => Some(h.writer_sn.0),
            _ => None,
        })
        .collect();
    assert_eq!(hbfrag_sns, [1, 2].into());
    let answered = |log: &[Sent]| {
        subs_between(log, 1, 0)
            .iter()
            .filter(|s| matches!(s, Submessage::NackFrag(_) | Submessage::AckNack(_)))
            .count()
    };
    assert_eq!(answered(&net.log), 0);
    // Once HEARTBEATs get through, the ACKNACK path recovers sample 2.
    hb_ok.set(true);
    assert!(
        net.run_until(&mut sim, Duration::from_secs(1), &mut hook, |s, _| {
            got.extend(s.take_samples(1, r));
            got.len() == 2
        })
    );
    assert!(answered(&net.log) > 0);
}
