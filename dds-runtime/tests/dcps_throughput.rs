//! Rough throughput of the whole stack in one process (two participants over loopback). Ignored by default;
//! meaningful only in release: `scripts/isolated cargo test --release -p dds-runtime --test dcps_throughput
//! -- --ignored --nocapture`.
mod dcps_util;

use std::time::{Duration, Instant};

use dcps_util::*;
use dds_runtime::prelude::*;

#[derive(DdsType, Debug, Clone, PartialEq, Default)]
#[dds(name = "test::Payload", final)]
struct Payload {
    seq: u64,
    data: Vec<u8>,
}

#[test]
#[ignore = "measurement; run in release"]
fn reliable_keep_all_1k_throughput() {
    let (p1, p2) = (participant(81), participant(81));
    let (wq, rq) = reliable_keep_all_blocking(Duration::from_secs(10));
    let (w, r) = matched::<Payload>(&p1, &p2, "Throughput", &wq, &rq);
    let run = Duration::from_secs(3);
    let reader = std::thread::spawn(move || {
        let mut n = 0u64;
        let mut expect = 0u64;
        while r.wait_for_data(Duration::from_secs(2)).unwrap() {
            for s in r.take().unwrap() {
                assert_eq!(s.data.unwrap().seq, expect);
                expect += 1;
                n += 1;
            }
        }
        n
    });
    let sample = |seq| Payload {
        seq,
        data: vec![0x5a; 1024],
    };
    let start = Instant::now();
    let mut sent = 0u64;
    while start.elapsed() < run {
        for _ in 0..100 {
            w.write(&sample(sent)).unwrap();
            sent += 1;
        }
    }
    w.wait_for_acknowledgments(Duration::from_secs(20)).unwrap();
    let secs = start.elapsed().as_secs_f64();
    let got = reader.join().unwrap();
    assert_eq!(got, sent);
    eprintln!(
        "1 KiB reliable keep-all: {sent} samples in {secs:.2} s = {:.0} samples/s, {:.2} Gb/s",
        sent as f64 / secs,
        sent as f64 * 1024.0 * 8.0 / secs / 1e9
    );
}
