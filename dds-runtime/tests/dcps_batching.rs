//! Write batching over real sockets: a burst of writes shares datagrams, and `flush` sends a partial batch.
mod dcps_util;

use std::sync::atomic::Ordering;
use std::time::Duration;

use dcps_util::*;
use dds_runtime::prelude::*;

#[test]
fn batched_burst_shares_datagrams_and_flush_sends_the_rest() {
    require_netns();
    init_tracing();
    let domain = 91;
    let batching = DomainParticipant::builder()
        .domain_id(domain)
        .interface("lo")
        .spdp_interval(Duration::from_millis(200))
        .write_batching(WriteBatching::Delay(Duration::from_secs(10)))
        .build()
        .unwrap();
    let plain = participant(domain);
    let (qos_w, qos_r) = reliable_keep_all();
    let (w, r) = matched::<ShapeType>(&batching, &plain, "Batched", &qos_w, &qos_r);

    let sent = || batching.transport().stats().sent.load(Ordering::Relaxed);
    let before = sent();
    let n = 300;
    for i in 0..n {
        w.write(&shape("BLUE", i)).unwrap();
    }
    w.flush();
    let datagrams = sent() - before;
    // ~40-byte samples: a few hundred per datagram; discovery and heartbeats may add a few datagrams.
    assert!(
        datagrams < n as u64 / 10,
        "{datagrams} datagrams for {n} writes"
    );
    let mut xs = Vec::new();
    assert!(wait_until(Duration::from_secs(10), || {
        xs.extend(
            r.take()
                .unwrap()
                .into_iter()
                .filter_map(|s| s.data)
                .map(|d| d.x),
        );
        xs.len() >= n as usize
    }));
    assert_eq!(xs, (0..n).collect::<Vec<_>>());
}
