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
    let mut sim = Sim::with_participants(seed, faults, 2);
    sim.faults_on_discovery = false;
    let now = sim.now;
    let w = sim.nodes[0].p.create_writer(now, WriterSpec::new("T", "M::T", false, wq)).unwrap();
    let r = sim.nodes[1].p.create_reader(now, ReaderSpec::new("T", "M::T", false, rq)).unwrap();
    assert!(sim.run_until(Duration::from_secs(5), |s| !s.nodes[0].p.writer_matches(w).is_empty()
        && !s.nodes[1].p.reader_matches(r).is_empty()));
    Setup { sim, w, r }
}

/// Writes `n` samples (retrying on WouldBlock while the network runs), then runs until all arrive.
fn stream(s: &mut Setup, n: u32, len: usize, limit: Duration) -> Vec<ReceivedSample> {
    stream_paced(s, n, len, limit, Duration::ZERO)
}

/// Like `stream`, letting `pace` of simulated time pass after each write.
fn stream_paced(s: &mut Setup, n: u32, len: usize, limit: Duration, pace: Duration) -> Vec<ReceivedSample> {
    let mut got = Vec::new();
    let mut i = 0;
    let end = s.sim.now + limit;
    while i < n && s.sim.now < end {
        let now = s.sim.now;
        match s.sim.nodes[0].p.write(now, s.w, WriteChange::alive(sample(i, len))) {
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
    s.sim.run_until(end.saturating_duration_since(s.sim.now), |sim| {
        let new = sim.take_samples(1, r);
        count += new.len();
        acc.extend(new);
        count >= n as usize
    });
    acc
}

fn check_complete_in_order(got: &[ReceivedSample], n: u32, len: usize) {
    assert_eq!(got.len(), n as usize, "received {} of {n}", got.len());
    for (k, s) in got.iter().enumerate() {
        assert_eq!(s.sequence, SequenceNumber(k as i64 + 1));
        assert_eq!(index_of(&s.payload), k as u32, "out of order at {k}");
        assert_eq!(&s.payload[..], &sample(k as u32, len)[..]);
    }
}

#[test]
fn reliable_lossless_stream() {
    let mut s = setup(1, Faults::NONE, DataWriterQos::builder().history(History::KeepAll).build(),
        DataReaderQos::builder().reliability(Reliability::RELIABLE).history(History::KeepAll).build());
    let got = stream(&mut s, 2000, 100, Duration::from_secs(10));
    check_complete_in_order(&got, 2000, 100);
    assert!(s.sim.run_until(Duration::from_secs(1), |sim| sim.nodes[0].p.is_acknowledged(EntityId([0, 0, 1, 3]))));
}

#[test]
fn reliable_stream_30pct_loss_1000_seeds() {
    let wq = DataWriterQos::builder().history(History::KeepAll).build();
    let rq = DataReaderQos::builder().reliability(Reliability::RELIABLE).history(History::KeepAll).build();
    for seed in 0..1000u64 {
        let mut s = setup(seed, Faults::lossy(0.3), wq.clone(), rq.clone());
        let got = stream(&mut s, 50, 64, Duration::from_secs(60));
        assert_eq!(got.len(), 50, "seed {seed}: received {}", got.len());
        check_complete_in_order(&got, 50, 64);
        let w = s.w;
        assert!(s.sim.run_until(Duration::from_secs(30), |sim| sim.nodes[0].p.is_acknowledged(w)), "seed {seed}: not acknowledged");
    }
}

#[test]
fn fragmented_samples_with_loss() {
    let wq = DataWriterQos::builder().history(History::KeepAll).build();
    let rq = DataReaderQos::builder().reliability(Reliability::RELIABLE).history(History::KeepAll).build();
    for seed in 0..50u64 {
        let mut s = setup(seed, Faults::lossy(0.2), wq.clone(), rq.clone());
        // 10000 bytes with 1344-byte fragments: 8 fragments per sample.
        let got = stream(&mut s, 20, 10_000, Duration::from_secs(60));
        check_complete_in_order(&got, 20, 10_000);
    }
}

#[test]
fn best_effort_delivers_in_order_without_duplicates() {
    let wq = DataWriterQos::builder().reliability(Reliability::BestEffort).build();
    let rq = DataReaderQos::default();
    let mut s = setup(3, Faults::NONE, wq.clone(), rq.clone());
    let got = stream_paced(&mut s, 100, 32, Duration::from_secs(2), Duration::from_millis(1));
    check_complete_in_order(&got, 100, 32);

    let mut s = setup(3, Faults::lossy(0.3), wq, rq);
    let got = stream_paced(&mut s, 500, 32, Duration::from_secs(2), Duration::from_millis(1));
    assert!(got.len() > 200 && got.len() < 500, "got {}", got.len());
    for w in got.windows(2) {
        assert!(w[0].sequence < w[1].sequence);
    }
    let lost: u64 = s.sim.nodes[1]
        .events
        .iter()
        .map(|e| if let Event::SampleLost { count, .. } = e { *count } else { 0 })
        .sum();
    assert!(lost > 0);
}
