//! Reliable and best-effort data paths through a lossy, reordering, duplicating simulated network.

mod rtps_support;

use std::time::Duration;

use dds_runtime::qos::*;
use dds_runtime::rtps::*;
use rtps_support::*;

/// A payload that encodes its index, 4-aligned, of `len` bytes.
fn sample(i: u32, len: usize) -> Vec<u8> {
    let mut v = vec![0u8; len.max(8)];
    v[..4].copy_from_slice(&[0, 1, 0, 0]);
    v[4..8].copy_from_slice(&i.to_le_bytes());
    for (k, b) in v.iter_mut().enumerate().skip(8) {
        *b = (k as u32 ^ i) as u8;
    }
    v
}

fn index_of(p: &[u8]) -> u32 {
    u32::from_le_bytes([p[4], p[5], p[6], p[7]])
}

struct Setup {
    sim: Sim,
    w: EntityId,
    r: EntityId,
}

fn setup(seed: u64, faults: Faults, wq: DataWriterQos, rq: DataReaderQos) -> Setup {
    let (sim, w, r) = Sim::writer_and_reader(seed, faults, wq, rq);
    Setup { sim, w, r }
}

/// Writes `n` samples (retrying on WouldBlock while the network runs), then runs until all arrive.
fn stream(s: &mut Setup, n: u32, len: usize, limit: Duration) -> Vec<ReceivedSample> {
    stream_paced(s, n, len, limit, Duration::ZERO)
}

/// Like `stream`, letting `pace` of simulated time pass after each write.
fn stream_paced(
    s: &mut Setup,
    n: u32,
    len: usize,
    limit: Duration,
    pace: Duration,
) -> Vec<ReceivedSample> {
    let mut got = Vec::new();
    let mut i = 0;
    let end = s.sim.now + limit;
    while i < n && s.sim.now < end {
        let now = s.sim.now;
        match s.sim.nodes[0]
            .p
            .write(now, s.w, WriteChange::alive(sample(i, len)))
        {
            Ok(_) => {
                i += 1;
                if !pace.is_zero() {
                    s.sim.run_for(pace);
                }
            }
            Err(WriteError::WouldBlock) => {
                s.sim.step();
            }
            Err(e) => panic!("write failed: {e}"),
        }
        if i % 16 == 0 {
            s.sim.pump();
        }
        got.extend(s.sim.take_samples(1, s.r));
    }
    let r = s.r;
    let mut count = got.len();
    let mut acc = std::mem::take(&mut got);
    s.sim
        .run_until(end.saturating_duration_since(s.sim.now), |sim| {
            let new = sim.take_samples(1, r);
            count += new.len();
            acc.extend(new);
            count >= n as usize
        });
    acc
}

fn check_complete_in_order(got: &[ReceivedSample], n: u32, len: usize) {
    if got.len() != n as usize {
        eprintln!("{:?}", got.iter().map(|s| s.sequence.0).collect::<Vec<_>>());
    }
    assert_eq!(got.len(), n as usize, "received {} of {n}", got.len());
    for (k, s) in got.iter().enumerate() {
        assert_eq!(s.sequence, SequenceNumber(k as i64 + 1));
        assert_eq!(index_of(&s.payload), k as u32, "out of order at {k}");
        assert_eq!(&s.payload[..], &sample(k as u32, len)[..]);
    }
}

#[test]
fn reliable_lossless_stream() {
    let mut s = setup(
        1,
        Faults::NONE,
        DataWriterQos::builder().history(History::KeepAll).build(),
        DataReaderQos::builder()
            .reliability(Reliability::RELIABLE)
            .history(History::KeepAll)
            .build(),
    );
    let got = stream(&mut s, 2000, 100, Duration::from_secs(10));
    check_complete_in_order(&got, 2000, 100);
    assert!(s.sim.run_until(Duration::from_secs(1), |sim| sim.nodes[0]
        .p
        .is_acknowledged(EntityId([0, 0, 1, 3]))));
}

#[test]
fn reliable_stream_30pct_loss_1000_seeds() {
    let wq = DataWriterQos::builder().history(History::KeepAll).build();
    let rq = DataReaderQos::builder()
        .reliability(Reliability::RELIABLE)
        .history(History::KeepAll)
        .build();
    for seed in 0..1000u64 {
        let mut s = setup(seed, Faults::lossy(0.3), wq.clone(), rq.clone());
        let got = stream(&mut s, 50, 64, Duration::from_secs(60));
        assert_eq!(got.len(), 50, "seed {seed}: received {}", got.len());
        check_complete_in_order(&got, 50, 64);
        let w = s.w;
        assert!(
            s.sim.run_until(Duration::from_secs(30), |sim| sim.nodes[0]
                .p
                .is_acknowledged(w)),
            "seed {seed}: not acknowledged"
        );
    }
}

#[test]
fn fragmented_samples_with_loss() {
    let wq = DataWriterQos::builder().history(History::KeepAll).build();
    let rq = DataReaderQos::builder()
        .reliability(Reliability::RELIABLE)
        .history(History::KeepAll)
        .build();
    for seed in 0..50u64 {
        let mut s = setup(seed, Faults::lossy(0.2), wq.clone(), rq.clone());
        // 10000 bytes with 1344-byte fragments: 8 fragments per sample.
        let got = stream(&mut s, 20, 10_000, Duration::from_secs(60));
        check_complete_in_order(&got, 20, 10_000);
    }
}

#[test]
fn best_effort_delivers_in_order_without_duplicates() {
    let wq = DataWriterQos::builder()
        .reliability(Reliability::BestEffort)
        .build();
    let rq = DataReaderQos::default();
    let mut s = setup(3, Faults::NONE, wq.clone(), rq.clone());
    let got = stream_paced(
        &mut s,
        100,
        32,
        Duration::from_secs(2),
        Duration::from_millis(1),
    );
    check_complete_in_order(&got, 100, 32);

    let mut s = setup(3, Faults::lossy(0.3), wq, rq);
    let got = stream_paced(
        &mut s,
        500,
        32,
        Duration::from_secs(2),
        Duration::from_millis(1),
    );
    assert!(got.len() > 200 && got.len() < 500, "got {}", got.len());
    for w in got.windows(2) {
        assert!(w[0].sequence < w[1].sequence);
    }
    let lost: u64 = s.sim.nodes[1]
        .events
        .iter()
        .map(|e| {
            if let Event::SampleLost { count, .. } = e {
                *count
            } else {
                0
            }
        })
        .sum();
    assert!(lost > 0);
}

#[test]
fn transient_local_late_joiner_gets_history() {
    for seed in 0..20u64 {
        let faults = if seed == 0 {
            Faults::NONE
        } else {
            Faults::lossy(0.2)
        };
        let mut sim = Sim::with_participants(seed, faults, 2);
        let now = sim.now;
        let wq = DataWriterQos::builder()
            .durability(Durability::TransientLocal)
            .history(History::KeepLast(3))
            .build();
        let w = sim.nodes[0]
            .p
            .create_writer(now, WriterSpec::new("TL", "T", true, wq))
            .unwrap();
        // Two instances, five changes each: KEEP_LAST(3) per instance keeps the last 3 of each.
        for i in 0..10u32 {
            let now = sim.now;
            let key = [(i % 2) as u8; 16];
            sim.nodes[0]
                .p
                .write(now, w, WriteChange::alive(sample(i, 16)).with_key_hash(key))
                .unwrap();
        }
        sim.run_for(Duration::from_millis(200));
        let now = sim.now;
        let rq = DataReaderQos::builder()
            .reliability(Reliability::RELIABLE)
            .durability(Durability::TransientLocal)
            .history(History::KeepAll)
            .build();
        let r = sim.nodes[1]
            .p
            .create_reader(now, ReaderSpec::new("TL", "T", true, rq))
            .unwrap();
        let mut got = Vec::new();
        assert!(
            sim.run_until(Duration::from_secs(20), |s| {
                got.extend(s.take_samples(1, r));
                got.len() >= 6
            }),
            "seed {seed}: got {} {:?}",
            got.len(),
            sim.nodes[1].events
        );
        let idx: Vec<u32> = got.iter().map(|s| index_of(&s.payload)).collect();
        assert_eq!(idx, vec![4, 5, 6, 7, 8, 9], "seed {seed}");
        // A volatile reader joining now gets nothing old.
        let now = sim.now;
        let r2 = sim.nodes[1]
            .p
            .create_reader(
                now,
                ReaderSpec::new(
                    "TL",
                    "T",
                    true,
                    DataReaderQos::builder()
                        .reliability(Reliability::RELIABLE)
                        .build(),
                ),
            )
            .unwrap();
        sim.run_for(Duration::from_secs(2));
        assert!(sim.take_samples(1, r2).is_empty());
        assert_eq!(sim.nodes[1].p.reader_matches(r2).len(), 1);
    }
}

#[test]
fn flow_control_blocks_until_acknowledged() {
    let mut sim = Sim::with_participants(5, Faults::NONE, 2);
    let now = sim.now;
    let w = sim.nodes[0]
        .p
        .create_writer(
            now,
            WriterSpec::new(
                "F",
                "T",
                false,
                DataWriterQos::builder().history(History::KeepAll).build(),
            ),
        )
        .unwrap();
    let r = sim.nodes[1]
        .p
        .create_reader(
            now,
            ReaderSpec::new(
                "F",
                "T",
                false,
                DataReaderQos::builder()
                    .reliability(Reliability::RELIABLE)
                    .build(),
            ),
        )
        .unwrap();
    assert!(sim.run_until(Duration::from_secs(2), |s| !s.nodes[0]
        .p
        .writer_matches(w)
        .is_empty()
        && !s.nodes[1].p.reader_matches(r).is_empty()));
    // The reader goes silent: nothing it sends (acknowledgements) arrives.
    sim.nodes[1].up = false;
    let high = sim.nodes[0].p.config().whc_high_watermark();
    let mut written = 0usize;
    let err = loop {
        let now = sim.now;
        match sim.nodes[0]
            .p
            .write(now, w, WriteChange::alive(sample(written as u32, 1024)))
        {
            Ok(_) => written += 1,
            Err(e) => break e,
        }
        assert!(written * 1024 <= high + 1024, "flow control never engaged");
    };
    assert_eq!(err, WriteError::WouldBlock);
    assert!(written * 1024 >= high - 1024);
    assert!(sim.nodes[0].p.unacknowledged_bytes(w) > high - 1024);
    // Still blocked while nothing is acknowledged.
    sim.run_for(Duration::from_millis(300));
    let now = sim.now;
    assert_eq!(
        sim.nodes[0]
            .p
            .write(now, w, WriteChange::alive(sample(0, 1024))),
        Err(WriteError::WouldBlock)
    );
    // The reader comes back (it lost everything meanwhile): repairs flow, acknowledgements release the writer.
    sim.nodes[1].up = true;
    assert!(sim.run_until(Duration::from_secs(10), |s| s
        .has_event(0, |e| *e == Event::WriterUnblocked { writer: w })));
    let now = sim.now;
    assert!(sim.nodes[0]
        .p
        .write(now, w, WriteChange::alive(sample(written as u32, 1024)))
        .is_ok());
    written += 1;
    let mut got = Vec::new();
    assert!(sim.run_until(Duration::from_secs(10), |s| {
        got.extend(s.take_samples(1, r));
        got.len() == written
    }));
    check_complete_in_order(&got, written as u32, 1024);
}

#[test]
fn dispose_and_unregister_carry_key_hash_and_status() {
    let mut s = setup(
        9,
        Faults::NONE,
        DataWriterQos::default(),
        DataReaderQos::builder()
            .reliability(Reliability::RELIABLE)
            .build(),
    );
    // The setup writer is keyless; make a keyed pair.
    let now = s.sim.now;
    let w = s.sim.nodes[0]
        .p
        .create_writer(
            now,
            WriterSpec::new("K", "T", true, DataWriterQos::default()),
        )
        .unwrap();
    let r = s.sim.nodes[1]
        .p
        .create_reader(
            now,
            ReaderSpec::new(
                "K",
                "T",
                true,
                DataReaderQos::builder()
                    .reliability(Reliability::RELIABLE)
                    .build(),
            ),
        )
        .unwrap();
    assert!(s.sim.run_until(Duration::from_secs(2), |sim| !sim.nodes[0]
        .p
        .writer_matches(w)
        .is_empty()));
    assert_eq!(
        s.sim.nodes[0]
            .p
            .write(now, w, WriteChange::alive(sample(1, 8))),
        Err(WriteError::MissingKeyHash)
    );
    let key = [5u8; 16];
    let now = s.sim.now;
    let p = &mut s.sim.nodes[0].p;
    p.write(now, w, WriteChange::alive(sample(1, 8)).with_key_hash(key))
        .unwrap();
    p.write(
        now,
        w,
        WriteChange::alive(vec![0, 1, 0, 0, 5, 5, 5, 5])
            .with_key_hash(key)
            .with_kind(ChangeKind::Dispose),
    )
    .unwrap();
    p.write(
        now,
        w,
        WriteChange::alive(Vec::new())
            .with_key_hash(key)
            .with_kind(ChangeKind::Unregister),
    )
    .unwrap();
    let ts = Time {
        seconds: 1000,
        fraction: 7,
    };
    p.write(
        now,
        w,
        WriteChange::alive(sample(2, 8))
            .with_key_hash(key)
            .with_timestamp(ts),
    )
    .unwrap();
    let mut got = Vec::new();
    assert!(s.sim.run_until(Duration::from_secs(2), |sim| {
        got.extend(sim.take_samples(1, r));
        got.len() == 4
    }));
    assert_eq!(
        got.iter().map(|s| s.kind).collect::<Vec<_>>(),
        vec![
            ChangeKind::Alive,
            ChangeKind::Dispose,
            ChangeKind::Unregister,
            ChangeKind::Alive
        ]
    );
    assert!(got.iter().all(|s| s.key_hash == Some(key)));
    assert_eq!(&got[1].payload[..], &[0, 1, 0, 0, 5, 5, 5, 5]);
    assert!(got[2].payload.is_empty());
    assert_eq!(got[3].source_timestamp, Some(ts));
    assert_eq!(got[0].source_timestamp, None);
}

#[test]
fn samples_are_packed_into_datagrams() {
    let mut s = setup(
        2,
        Faults::NONE,
        DataWriterQos::builder().history(History::KeepAll).build(),
        DataReaderQos::builder()
            .reliability(Reliability::RELIABLE)
            .history(History::KeepAll)
            .build(),
    );
    let now = s.sim.now;
    for i in 0..100 {
        s.sim.nodes[0]
            .p
            .write(now, s.w, WriteChange::alive(sample(i, 200)))
            .unwrap();
    }
    let max = s.sim.nodes[0].p.config().max_message_size();
    let mut datagrams = Vec::new();
    while let Some(t) = s.sim.nodes[0].p.poll_transmit(now) {
        datagrams.push(t);
    }
    // 100 × ~250 bytes in datagrams of at most 14720 bytes: 2 of them, each within the limit.
    assert!(datagrams.len() <= 3, "{} datagrams", datagrams.len());
    assert!(datagrams.iter().all(|t| t.len() <= max));
    for t in datagrams {
        s.sim.nodes[1].p.handle_datagram(now, &t.datagram());
    }
    s.sim.pump();
    let got = s.sim.take_samples(1, s.r);
    check_complete_in_order(&got, 100, 200);
}

#[test]
fn deleted_writer_lingers_until_acknowledged() {
    let mut s = setup(
        4,
        Faults::lossy(0.3),
        DataWriterQos::builder().history(History::KeepAll).build(),
        DataReaderQos::builder()
            .reliability(Reliability::RELIABLE)
            .history(History::KeepAll)
            .build(),
    );
    let now = s.sim.now;
    for i in 0..20 {
        s.sim.nodes[0]
            .p
            .write(now, s.w, WriteChange::alive(sample(i, 64)))
            .unwrap();
    }
    s.sim.nodes[0].p.delete_writer(now, s.w);
    assert_eq!(
        s.sim.nodes[0]
            .p
            .write(now, s.w, WriteChange::alive(sample(0, 64))),
        Err(WriteError::Deleted)
    );
    let (w, r) = (s.w, s.r);
    let mut got = Vec::new();
    assert!(s.sim.run_until(Duration::from_secs(5), |sim| {
        got.extend(sim.take_samples(1, r));
        sim.has_event(0, |e| *e == Event::WriterDeleted { writer: w })
    }));
    got.extend(s.sim.take_samples(1, r));
    // Lingering repaired everything before the writer went away, and the reader saw it go.
    check_complete_in_order(&got, 20, 64);
    let wg = s.sim.guid(0, w);
    assert!(s
        .sim
        .run_until(Duration::from_secs(5), |sim| sim.has_event(1, |e| *e
            == Event::SubscriptionMatched {
                reader: r,
                writer: wg,
                matched: false
            })));
}

#[test]
fn keep_last_writer_under_loss_converges_to_the_latest() {
    for seed in 0..100u64 {
        let wq = DataWriterQos::builder()
            .history(History::KeepLast(1))
            .build();
        let rq = DataReaderQos::builder()
            .reliability(Reliability::RELIABLE)
            .build();
        let mut s = setup(seed, Faults::lossy(0.3), wq, rq);
        let now = s.sim.now;
        for i in 0..30 {
            // All the same instance (keyless): only the last one must survive.
            s.sim.nodes[0]
                .p
                .write(now, s.w, WriteChange::alive(sample(i, 24)))
                .unwrap();
        }
        let (w, r) = (s.w, s.r);
        let mut got = Vec::new();
        assert!(
            s.sim.run_until(Duration::from_secs(30), |sim| {
                got.extend(sim.take_samples(1, r));
                sim.nodes[0].p.is_acknowledged(w)
            }),
            "seed {seed}"
        );
        got.extend(s.sim.take_samples(1, r));
        assert!(
            got.windows(2).all(|x| x[0].sequence < x[1].sequence),
            "seed {seed}"
        );
        assert_eq!(
            got.last().map(|x| index_of(&x.payload)),
            Some(29),
            "seed {seed}"
        );
    }
}

/// Core-only throughput (no sockets, no serialization): `cargo test --release -p dds-runtime --test
/// rtps_reliability -- --ignored --nocapture core_throughput`.
#[test]
#[ignore = "measurement; run in release"]
fn core_throughput() {
    let mut s = setup(
        1,
        Faults::NONE,
        DataWriterQos::builder().history(History::KeepAll).build(),
        DataReaderQos::builder()
            .reliability(Reliability::RELIABLE)
            .history(History::KeepAll)
            .build(),
    );
    let (w, r) = (s.w, s.r);
    let payload = Payload::from(sample(0, 1024));
    let n = 1_000_000u64;
    let start = std::time::Instant::now();
    let (mut written, mut received) = (0u64, 0u64);
    let mut now = s.sim.now;
    while received < n {
        let [a, b] = &mut s.sim.nodes[..] else {
            unreachable!()
        };
        while written < n {
            match a.p.write(now, w, WriteChange::alive(payload.clone())) {
                Ok(_) => written += 1,
                Err(WriteError::WouldBlock) => break,
                Err(e) => panic!("{e}"),
            }
            if written % 64 == 0 {
                break;
            }
        }
        while let Some(t) = a.p.poll_transmit(now) {
            b.p.handle_datagram(now, &t.datagram());
            a.p.recycle_transmit(t);
        }
        while let Some(t) = b.p.poll_transmit(now) {
            a.p.handle_datagram(now, &t.datagram());
        }
        while let Some(e) = b.p.poll_event() {
            if let Event::Sample(x) = e {
                assert_eq!(x.reader, r);
                received += 1;
            }
        }
        while a.p.poll_event().is_some() {}
        now += Duration::from_micros(10);
        a.p.handle_timeout(now);
        b.p.handle_timeout(now);
    }
    let dt = start.elapsed();
    eprintln!(
        "{n} × 1 KiB reliable through the core: {:.0} samples/s",
        n as f64 / dt.as_secs_f64()
    );
}

/// Back-pressure: a reliable reader out of credit neither delivers nor acknowledges; the writer keeps the
/// samples and repairs them once credit comes back, so nothing is lost (even with loss on the network).
#[test]
fn reader_credit_holds_back_acknowledgement_until_space() {
    let mut s = setup(
        7,
        Faults::lossy(0.1),
        DataWriterQos::builder().history(History::KeepAll).build(),
        DataReaderQos::builder()
            .reliability(Reliability::RELIABLE)
            .history(History::KeepAll)
            .build(),
    );
    let (w, r) = (s.w, s.r);
    s.sim.nodes[1].p.set_reader_credit(r, Some(10));
    let n = 50u32;
    for i in 0..n {
        let now = s.sim.now;
        s.sim.nodes[0]
            .p
            .write(now, w, WriteChange::alive(sample(i, 100)))
            .expect("fits in the writer history");
    }
    s.sim.run_for(Duration::from_secs(3));
    let mut got = s.sim.take_samples(1, r);
    assert_eq!(got.len(), 10, "delivery stops at the credit");
    assert!(
        !s.sim.nodes[0].p.is_acknowledged(w),
        "undelivered samples must not be acknowledged"
    );
    assert!(s.sim.nodes[0].p.unacknowledged_bytes(w) >= 40 * 100);

    s.sim.nodes[1].p.set_reader_credit(r, Some(15));
    s.sim.run_for(Duration::from_secs(3));
    got.extend(s.sim.take_samples(1, r));
    assert_eq!(got.len(), 25);

    s.sim.nodes[1].p.set_reader_credit(r, None);
    let mut count = got.len();
    assert!(s.sim.run_until(Duration::from_secs(10), |sim| {
        let new = sim.take_samples(1, r);
        count += new.len();
        got.extend(new);
        count >= n as usize
    }));
    check_complete_in_order(&got, n, 100);
    assert!(s.sim.run_until(Duration::from_secs(5), |sim| sim.nodes[0]
        .p
        .is_acknowledged(w)));
}
