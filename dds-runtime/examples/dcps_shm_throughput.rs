//! DDS-to-DDS throughput between two processes on this host: the same writer/reader pair with shared
//! memory on and off (loopback UDP), interleaved in one run. A benchmark, not a test; run it inside
//! `scripts/isolated`:
//!
//! ```text
//! cargo build --release -p dds-runtime -F shm --example dcps_shm_throughput
//! scripts/isolated target/release/examples/dcps_shm_throughput [SIZE_BYTES] [SECONDS] [ROUNDS]
//! ```
//!
//! Each measurement: this program runs itself again as the subscriber (a second process), both with
//! `Config::shm` on or off; the publisher writes samples of SIZE bytes (reliable, KEEP_ALL) for SECONDS;
//! the subscriber takes them (each is decoded into a `Vec<u8>`) and reports samples/s from its first to
//! its last sample.

use std::io::{BufRead, BufReader};
use std::process::{Command, Stdio};
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

/// Marks the end of a measurement.
const LAST: u64 = u64::MAX;

fn participant(domain: u32, shm: bool) -> DdsResult<DomainParticipant> {
    let c = Config {
        domain_id: domain,
        interface: InterfaceSelection::Name("lo".into()),
        spdp_interval: Duration::from_millis(200),
        shm,
        ..Config::default()
    };
    DomainParticipant::builder().config(c).build()
}

fn qos() -> (DataWriterQos, DataReaderQos) {
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
    (wq, rq)
}

/// The subscriber process: prints "ready", then "N SECONDS" once the end marker arrived.
fn subscriber(domain: u32, shm: bool) -> Result<(), Box<dyn std::error::Error>> {
    let p = participant(domain, shm)?;
    let topic = p.create_topic::<Payload>("ShmBench", &TopicQos::default())?;
    let r = p
        .create_subscriber(&SubscriberQos::default())?
        .create_datareader(&topic, &qos().1)?;
    println!("ready");
    let (mut got, mut first, mut last) = (0u64, None, Instant::now());
    loop {
        if !r.wait_for_data(Duration::from_secs(30))? {
            return Err("no data for 30 s".into());
        }
        let mut end = false;
        for s in r.take()? {
            let Some(d) = s.data else { continue };
            if d.seq == LAST {
                end = true;
                continue;
            }
            first.get_or_insert_with(Instant::now);
            last = Instant::now();
            got += 1;
        }
        if end {
            break;
        }
    }
    let secs = first.map_or(0.0, |f| last.duration_since(f).as_secs_f64());
    println!("{got} {secs}");
    Ok(())
}

/// One measurement: samples/s seen by the subscriber.
fn measure(
    domain: u32,
    shm: bool,
    size: usize,
    secs: f64,
) -> Result<f64, Box<dyn std::error::Error>> {
    let mut child = Command::new(std::env::current_exe()?)
        .args(["sub", &domain.to_string(), if shm { "shm" } else { "udp" }])
        .stdout(Stdio::piped())
        .spawn()?;
    let mut out = BufReader::new(child.stdout.take().ok_or("no stdout")?);
    let mut line = String::new();
    out.read_line(&mut line)?;
    let p = participant(domain, shm)?;
    let topic = p.create_topic::<Payload>("ShmBench", &TopicQos::default())?;
    let w = p
        .create_publisher(&PublisherQos::default())?
        .create_datawriter(&topic, &qos().0)?;
    while w.publication_matched_status().current_count == 0 {
        std::thread::sleep(Duration::from_millis(10));
    }
    let mut sample = Payload {
        seq: 0,
        data: vec![0x5a; size],
    };
    let end = Instant::now() + Duration::from_secs_f64(secs);
    while Instant::now() < end {
        w.write(&sample)?;
        sample.seq += 1;
    }
    sample.seq = LAST;
    sample.data.clear();
    w.write(&sample)?;
    line.clear();
    out.read_line(&mut line)?;
    child.wait()?;
    let mut f = line.split_whitespace();
    let got: f64 = f.next().ok_or("no count")?.parse()?;
    let took: f64 = f.next().ok_or("no time")?.parse()?;
    Ok(if took > 0.0 { got / took } else { 0.0 })
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if args.first().map(String::as_str) == Some("sub") {
        return subscriber(args[1].parse()?, args[2] == "shm");
    }
    let size: usize = args.first().map_or(Ok(1 << 20), |s| s.parse())?;
    let secs: f64 = args.get(1).map_or(Ok(5.0), |s| s.parse())?;
    let rounds: u32 = args.get(2).map_or(Ok(2), |s| s.parse())?;
    let (mut shm_rates, mut udp_rates) = (Vec::new(), Vec::new());
    for round in 0..rounds {
        for shm in [true, false] {
            let domain = 130 + round * 2 + u32::from(shm);
            let rate = measure(domain, shm, size, secs)?;
            let mbps = rate * size as f64 * 8.0 / 1e9;
            println!(
                "round {round} {:>13} size {size} B: {rate:.0} samples/s ({mbps:.2} Gb/s)",
                if shm { "shared memory" } else { "loopback UDP" }
            );
            if shm {
                shm_rates.push(rate);
            } else {
                udp_rates.push(rate);
            }
        }
    }
    let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len().max(1) as f64;
    println!(
        "size {size} B: shared memory {:.0} samples/s, loopback UDP {:.0} samples/s, ratio {:.1}x",
        mean(&shm_rates),
        mean(&udp_rates),
        mean(&shm_rates) / mean(&udp_rates).max(f64::MIN_POSITIVE)
    );
    Ok(())
}
