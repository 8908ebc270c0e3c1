//! Write batching: with a batch delay, writes drained one by one (as the DCPS layer drains them) still share
//! datagrams, which leave when full, on flush, with other traffic, or when the delay runs out.

mod rtps_support;

use std::time::Duration;

use dds_runtime::qos::*;
use dds_runtime::rtps::messages::{MessageIter, Submessage};
use dds_runtime::rtps::*;
use rtps_support::*;

const DELAY: Duration = Duration::from_millis(1);

/// A writer on node 0 matched with a reliable reader on node 1; node 0 batches when `batch`.
fn matched(batch: Option<Duration>) -> (Sim, EntityId, EntityId) {
    matched_with(7, Faults::NONE, batch)
}

fn matched_with(seed: u64, faults: Faults, batch: Option<Duration>) -> (Sim, EntityId, EntityId) {
    let mut sim = Sim::new(seed, faults);
    sim.faults_on_discovery = false;
    sim.add(config(0).write_batch_delay(batch));
    sim.add(config(1));
    let now = sim.now;
    let keep_all = History::KeepAll;
    let w = sim.nodes[0]
        .p
        .create_writer(
            now,
            WriterSpec::new(
                "T",
                "M::T",
                false,
                DataWriterQos::builder().history(keep_all).build(),
            ),
        )
        .unwrap();
    let r = sim.nodes[1]
        .p
        .create_reader(
            now,
            ReaderSpec::new(
                "T",
                "M::T",
                false,
                DataReaderQos::builder()
                    .reliability(Reliability::RELIABLE)
                    .history(keep_all)
                    .build(),
            ),
        )
        .unwrap();
    assert!(sim.run_until(Duration::from_secs(5), |s| {
        !s.nodes[0].p.writer_matches(w).is_empty() && !s.nodes[1].p.reader_matches(r).is_empty()
    }));
    // Let discovery's own traffic settle so that only user data is in flight.
    sim.run_for(Duration::from_millis(50));
    (sim, w, r)
}

fn payload(i: u32, len: usize) -> Vec<u8> {
    let mut v = vec![0u8; len];
    v[..4].copy_from_slice(&[0, 1, 0, 0]);
    v[4..8].copy_from_slice(&i.to_le_bytes());
    v
}

/// Writes one sample and drains the participant, the way every DCPS `write` does.
fn write_and_drain(sim: &mut Sim, w: EntityId, i: u32, len: usize) -> Vec<Transmit> {
    let now = sim.now;
    let p = &mut sim.nodes[0].p;
    p.write(now, w, WriteChange::alive(payload(i, len)))
        .unwrap();
    std::iter::from_fn(|| p.poll_transmit(now)).collect()
}

fn count(t: &Transmit, pred: impl Fn(&Submessage<'_>) -> bool) -> usize {
    MessageIter::parse(&t.datagram())
        .unwrap()
        .1
        .filter(|s| s.as_ref().is_ok_and(&pred))
        .count()
}

fn is_data(s: &Submessage<'_>) -> bool {
    matches!(s, Submessage::Data(_))
}

fn deliver(sim: &mut Sim, grams: &[Transmit]) {
    let now = sim.now;
    for t in grams {
        sim.nodes[1].p.handle_datagram(now, &t.datagram());
    }
}

fn received(sim: &mut Sim, r: EntityId) -> Vec<u32> {
    sim.pump();
    sim.take_samples(1, r)
        .iter()
        .map(|s| u32::from_le_bytes([s.payload[4], s.payload[5], s.payload[6], s.payload[7]]))
        .collect()
}

#[test]
fn unbatched_writes_leave_one_datagram_each() {
    let (mut sim, w, r) = matched(None);
    for i in 0..5 {
        let grams = write_and_drain(&mut sim, w, i, 100);
        assert_eq!(grams.len(), 1, "write {i}");
        assert_eq!(count(&grams[0], is_data), 1);
        deliver(&mut sim, &grams);
    }
    assert_eq!(received(&mut sim, r), (0..5).collect::<Vec<_>>());
}

#[test]
fn batched_writes_leave_when_the_delay_runs_out() {
    let (mut sim, w, r) = matched(Some(DELAY));
    let start = sim.now;
    for i in 0..10 {
        assert!(
            write_and_drain(&mut sim, w, i, 100).is_empty(),
            "write {i} left early"
        );
    }
    let due = sim.nodes[0].p.poll_timeout().unwrap();
    assert!(
        due <= start + DELAY,
        "batch deadline {:?} late",
        due - start
    );
    // Not before the delay …
    assert!(sim.nodes[0].p.poll_transmit(start).is_none());
    // … and at it, all ten in one datagram.
    let grams: Vec<Transmit> =
        std::iter::from_fn(|| sim.nodes[0].p.poll_transmit(start + DELAY)).collect();
    assert_eq!(grams.len(), 1);
    assert_eq!(count(&grams[0], is_data), 10);
    deliver(&mut sim, &grams);
    assert_eq!(received(&mut sim, r), (0..10).collect::<Vec<_>>());
}

#[test]
fn flush_sends_a_partial_batch_at_once() {
    let (mut sim, w, r) = matched(Some(Duration::from_secs(1)));
    for i in 0..3 {
        assert!(write_and_drain(&mut sim, w, i, 100).is_empty());
    }
    let now = sim.now;
    sim.nodes[0].p.flush();
    let grams: Vec<Transmit> = std::iter::from_fn(|| sim.nodes[0].p.poll_transmit(now)).collect();
    assert_eq!(grams.len(), 1);
    assert_eq!(count(&grams[0], is_data), 3);
    deliver(&mut sim, &grams);
    assert_eq!(received(&mut sim, r), vec![0, 1, 2]);
}

#[test]
fn full_datagrams_leave_without_waiting_and_carry_few_heartbeats() {
    let (mut sim, w, r) = matched(Some(Duration::from_secs(1)));
    let max = sim.nodes[0].p.config().max_message_size();
    let mut grams = Vec::new();
    for i in 0..200 {
        grams.extend(write_and_drain(&mut sim, w, i, 1024));
    }
    // 200 KiB in datagrams of at most max_message_size: the full ones left during the writes.
    assert!(grams.len() >= 200 * 1024 / max, "{} datagrams", grams.len());
    assert!(grams.iter().all(|t| t.len() <= max));
    let data: usize = grams.iter().map(|t| count(t, is_data)).sum();
    let heartbeats: usize = grams
        .iter()
        .map(|t| count(t, |s| matches!(s, Submessage::Heartbeat(_))))
        .sum();
    assert!(data >= 190, "only {data} samples sent so far");
    // About one piggy-backed heartbeat per datagram, not one per sample.
    assert!(
        heartbeats <= 2 * grams.len(),
        "{heartbeats} heartbeats in {} datagrams",
        grams.len()
    );
    deliver(&mut sim, &grams);
    sim.nodes[0].p.flush();
    sim.run_for(Duration::from_millis(200));
    assert_eq!(received(&mut sim, r), (0..200).collect::<Vec<_>>());
}

#[test]
fn other_traffic_takes_held_samples_along() {
    let (mut sim, w, _r) = matched(Some(Duration::from_secs(1)));
    assert!(write_and_drain(&mut sim, w, 0, 100).is_empty());
    // A periodic heartbeat (unbatched) is due within the heartbeat period; it closes the batch with it.
    let hb_at = sim.nodes[0].p.config().heartbeat_period();
    let t = sim.now + hb_at;
    sim.nodes[0].p.handle_timeout(t);
    let grams: Vec<Transmit> = std::iter::from_fn(|| sim.nodes[0].p.poll_transmit(t)).collect();
    let data: usize = grams.iter().map(|g| count(g, is_data)).sum();
    assert_eq!(data, 1, "the held sample left with the heartbeat");
}

/// Batched writes over a network that loses 30%, duplicates 10% and reorders: every sample arrives, in order,
/// once, for 200 seeds.
#[test]
fn batched_stream_survives_loss_reordering_and_duplication() {
    let n = 300u32;
    for seed in 0..200 {
        let (mut sim, w, r) = matched_with(seed, Faults::lossy(0.3), Some(DELAY));
        let mut got: Vec<u32> = Vec::new();
        let mut i = 0;
        let end = sim.now + Duration::from_secs(60);
        while i < n && sim.now < end {
            let now = sim.now;
            match sim.nodes[0]
                .p
                .write(now, w, WriteChange::alive(payload(i, 200)))
            {
                Ok(_) => i += 1,
                Err(WriteError::WouldBlock) => {
                    sim.step();
                }
                Err(e) => panic!("seed {seed}: write failed: {e}"),
            }
            // Drained after every write, as DCPS does: batching must hold the samples anyway.
            sim.pump();
            got.extend(received(&mut sim, r));
        }
        let left = end.saturating_duration_since(sim.now);
        sim.run_until(left, |s| {
            got.extend(s.take_samples(1, r).iter().map(|x| {
                u32::from_le_bytes([x.payload[4], x.payload[5], x.payload[6], x.payload[7]])
            }));
            got.len() >= n as usize
        });
        assert_eq!(got, (0..n).collect::<Vec<_>>(), "seed {seed}");
    }
}
