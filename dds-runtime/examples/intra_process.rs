//! Throughput of one writer and one reader of the same participant: intra-process delivery against the same
//! exchange over loopback UDP. A benchmark, not a test; run it inside `scripts/isolated`:
//!
//! ```text
//! scripts/isolated cargo run --release -p dds-runtime --example intra_process -- [SIZE] [COUNT] [local|owned|udp]
//! ```
//!
//! `local` writes one sample by reference (`write(&T)`: serialized, and decoded by the reader); `owned`
//! builds a fresh sample per write and hands it over (`write_owned(T)`: the reader gets it itself, no
//! serialization); `udp` is `local` with intra-process delivery off.
//! Prints samples/s, ns/sample and MB/s from the first write to the last take (reliable, KEEP_ALL).

use std::time::{Duration, Instant};

use dds_runtime::config::InterfaceSelection;
use dds_runtime::prelude::*;

/// A keyless sample with a payload of SIZE bytes.
#[derive(DdsType, Debug, Clone, PartialEq, Default)]
#[dds(name = "bench::Payload", final)]
struct Payload {
    seq: u64,
    data: Vec<u8>,
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let size: usize = args.next().map_or(Ok(16), |s| s.parse())?;
    let count: u64 = args.next().map_or(Ok(200_000), |s| s.parse())?;
    let mode = args.next().unwrap_or_else(|| "local".into());
    let local = mode != "udp";
    let owned = mode == "owned";
    let c = Config {
        domain_id: 120,
        interface: InterfaceSelection::Name("lo".into()),
        intra_process: local,
        ..Config::default()
    };
    let p = DomainParticipant::builder().config(c).build()?;
    let topic = p.create_topic::<Payload>("IntraBench", &TopicQos::default())?;
    let reliable = Reliability::Reliable {
        max_blocking_time: Duration::from_secs(10),
    };
    let wq = DataWriterQos::builder()
        .reliability(reliable)
        .history(History::KeepAll)
        .build();
    let rq = DataReaderQos::builder()
        .reliability(reliable)
        .history(History::KeepAll)
        .build();
    let w = p
        .create_publisher(&PublisherQos::default())?
        .create_datawriter(&topic, &wq)?;
    let r = p
        .create_subscriber(&SubscriberQos::default())?
        .create_datareader(&topic, &rq)?;
    while r.subscription_matched_status().current_count == 0 {
        std::thread::sleep(Duration::from_millis(10));
    }
    let reader = std::thread::spawn(move || -> Result<(u64, Instant), DdsError> {
        let mut got = 0;
        while got < count {
            if r.wait_for_data(Duration::from_secs(10))? {
                got += r.take()?.len() as u64;
            } else {
                break;
            }
        }
        Ok((got, Instant::now()))
    });
    let mut sample = Payload {
        seq: 0,
        data: vec![0x5a; size],
    };
    let start = Instant::now();
    for i in 0..count {
        if owned {
            w.write_owned(Payload {
                seq: i,
                data: vec![0x5a; size],
            })?;
        } else {
            sample.seq = i;
            w.write(&sample)?;
        }
    }
    let (got, end) = reader.join().expect("reader thread")?;
    let secs = end.duration_since(start).as_secs_f64();
    println!(
        "{} size {size} B: {got}/{count} samples in {secs:.3} s: {:.0} samples/s, {:.0} ns/sample, {:.1} MB/s",
        match (local, owned) {
            (_, true) => "intra-process, write_owned",
            (true, false) => "intra-process, write",
            (false, _) => "loopback UDP",
        },
        got as f64 / secs,
        secs * 1e9 / got.max(1) as f64,
        got as f64 * size as f64 / secs / 1e6
    );
    Ok(())
}
