//! A fast stream of small samples whose datagrams arrive out of order once: the reader must catch up at
//! the stream's rate, not settle at the rate of repair rounds.
//!
//! In `dds-perf pub size 16` → `sub` (session 23), a datagram of 82 samples left the publisher 1 464 samples
//! late (two threads sending what one core produced). The reader held 1 024 samples out of order and
//! dropped the rest, so it lacked a span as long as the writer's window; the writer then repaired it at
//! one repair budget (256 KiB) per NACK response delay (5 ms), while every new sample landed beyond the
//! reader's reorder window and was dropped in turn. The stream stayed at that rate, 620 kS/s, for good.

mod rtps_support;

use std::time::Duration;

use dds_runtime::qos::*;
use dds_runtime::rtps::*;
use rtps_support::*;

/// Samples offered per simulated millisecond (200 kS/s).
const PER_MS: u32 = 200;

/// What one run delivered.
struct Outcome {
    offered: u64,
    delivered: u64,
    /// Delivered in the last 100 ms.
    delivered_late: u64,
}

/// A 20-byte sample (CDR header, index, padding), the size `dds-perf pub size 16` writes.
fn small_payload(i: u32) -> Vec<u8> {
    let mut v = indexed_payload(i);
    v.resize(20, 0);
    v
}

/// dds-perf's QoS: KEEP_ALL with a 10 000-sample history on both sides.
fn perf_qos() -> (DataWriterQos, DataReaderQos) {
    let limits = ResourceLimits {
        max_samples: Some(10_000),
        ..ResourceLimits::default()
    };
    let wq = DataWriterQos::builder()
        .history(History::KeepAll)
        .resource_limits(limits)
        .build();
    let rq = DataReaderQos::builder()
        .reliability(Reliability::RELIABLE)
        .history(History::KeepAll)
        .build();
    (wq, rq)
}

/// Node 0 writes `PER_MS` small samples every simulated millisecond for `ms` milliseconds (batched into
/// datagrams, as dds-perf's publisher does), retrying what flow control refuses; at `late_at` ms its next
/// datagram arrives `late` behind the others. The repair budget is scaled down with the rate (16 KiB
/// per round instead of 256 KiB), so that a reader stuck behind shows within a short run. The reader holds
/// `reorder_max` samples out of order.
fn stream(ms: u32, late_at: u32, late: Duration, reorder_max: usize) -> Outcome {
    let mut sim = Sim::new(7, Faults::NONE);
    sim.add(
        config(0)
            .write_batch_delay(Some(Duration::from_millis(1)))
            .max_repair_bytes(16usize << 10),
    );
    sim.add(config(1).reorder_max_samples(reorder_max));
    let (wq, rq) = perf_qos();
    let (w, r) = sim.matched_pair(wq, rq);
    let (mut written, mut delivered, mut delivered_late) = (0u32, 0u64, 0u64);
    let start = sim.now;
    for tick in 0..ms {
        if tick == late_at {
            sim.delay_next_user = Some((0, late));
        }
        let offered = (tick + 1) * PER_MS;
        while written < offered {
            let now = sim.now;
            match sim.nodes[0]
                .p
                .write(now, w, WriteChange::alive(small_payload(written)))
            {
                Ok(_) => written += 1,
                Err(WriteError::WouldBlock) => break,
                Err(e) => panic!("write failed: {e}"),
            }
        }
        let next = start + Duration::from_millis(u64::from(tick) + 1);
        while sim.now < next {
            sim.step_until(Some(next));
        }
        for s in sim.take_samples(1, r) {
            assert_eq!(
                payload_index(&s.payload),
                delivered as u32,
                "in order, once"
            );
            delivered += 1;
            if tick + 100 >= ms {
                delivered_late += 1;
            }
        }
    }
    Outcome {
        offered: u64::from(ms * PER_MS),
        delivered,
        delivered_late,
    }
}

/// The reader holds the default number of samples out of order (32 768).
const REORDER_DEFAULT: usize = 32 * 1024;

/// Runs the stream with a datagram 10 ms late at 50 ms (2 000 samples at 200 kS/s) and checks that the
/// reader keeps up in the last 100 ms.
fn keeps_rate_after_late_datagram(reorder_max: usize) {
    let o = stream(200, 50, Duration::from_millis(10), reorder_max);
    eprintln!(
        "late datagram, reorder window {reorder_max}: offered {} delivered {} (last 100 ms {})",
        o.offered, o.delivered, o.delivered_late
    );
    assert!(
        o.delivered_late * 100 >= u64::from(100 * PER_MS) * 95,
        "the reader fell behind for good: {} delivered in the last 100 ms, {} offered",
        o.delivered_late,
        100 * PER_MS
    );
    assert!(o.delivered * 100 >= o.offered * 90);
}

#[test]
fn a_small_stream_keeps_up_undisturbed() {
    let calm = stream(200, u32::MAX, Duration::ZERO, REORDER_DEFAULT);
    eprintln!(
        "calm: offered {} delivered {} (last 100 ms {})",
        calm.offered, calm.delivered, calm.delivered_late
    );
    assert!(calm.delivered * 100 >= calm.offered * 95);
}

/// The reader holds everything after the hole (its default window exceeds the writer's 10 000 samples),
/// and the late datagram fills it. Before the default grew from 1 024, the reader delivered 4 784 of
/// 20 000 in the last 100 ms.
#[test]
fn a_small_stream_keeps_its_rate_after_a_late_datagram() {
    keeps_rate_after_late_datagram(REORDER_DEFAULT);
}

/// A reader whose reorder window is smaller than the hole (1 024 samples, the old default) drops what the
/// writer sends beyond it until the repairs reach it: the writer must repair faster than it writes, or
/// the reader never catches up.
#[test]
fn a_reader_with_a_small_reorder_window_catches_up() {
    keeps_rate_after_late_datagram(1024);
}
