//! Throughput of a shared-memory channel between two processes on this host (feature `shm`): the publisher
//! loans each sample buffer, writes every byte in place and sends it; the subscriber reads every cache line
//! of each sample in place. A benchmark, not a test:
//!
//! ```text
//! cargo run --release -p dds-runtime --features shm --example shm_throughput -- [SIZE] [SECONDS]
//! ```
//!
//! Prints samples/s and Gb/s over the last SECONDS (after a 1 s warm-up). The publisher is this program run
//! again with `--pub`.

use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use dds_runtime::transport::shm::{ShmChannelConfig, ShmNode};

fn config(size: usize) -> ShmChannelConfig {
    ShmChannelConfig {
        initial_max_sample: size,
        queue_depth: 8,
        max_loans: 2,
        max_subscribers: 2,
        delivery_timeout: None,
        max_publishers: 2,
        latest_only: false,
    }
}

fn publish(channel: &str, size: usize) -> Result<(), Box<dyn std::error::Error>> {
    let node = ShmNode::new()?;
    let publisher = node.publisher(channel, &config(size))?;
    for n in 0u64.. {
        let mut loan = publisher.loan(size)?;
        loan.fill(n as u8);
        loan[..8].copy_from_slice(&n.to_le_bytes());
        loan.send()?;
    }
    Ok(())
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if args.first().map(String::as_str) == Some("--pub") {
        return publish(&args[1], args[2].parse()?);
    }
    let size: usize = args.first().map_or(Ok(1 << 20), |s| s.parse())?;
    let seconds: u64 = args.get(1).map_or(Ok(5), |s| s.parse())?;
    let channel = format!("dds-bench/shm/{}", std::process::id());
    let node = ShmNode::new()?;
    let sub = node.subscriber(&channel, &config(size))?;
    let mut child = Command::new(std::env::current_exe()?)
        .args(["--pub", &channel, &size.to_string()])
        .stdin(Stdio::null())
        .spawn()?;
    let warm = Instant::now() + Duration::from_secs(1);
    let end = warm + Duration::from_secs(seconds);
    let (mut count, mut sum, mut next) = (0u64, 0u64, None::<u64>);
    let mut lost = 0u64;
    let mut start = None;
    while Instant::now() < end {
        let Some(s) = sub.receive()? else {
            std::hint::spin_loop();
            continue;
        };
        let seq = u64::from_le_bytes(s[..8].try_into()?);
        if let Some(n) = next {
            lost += seq.saturating_sub(n);
        }
        next = Some(seq + 1);
        sum = s
            .iter()
            .step_by(64)
            .fold(sum, |a, b| a.wrapping_add(u64::from(*b)));
        if Instant::now() >= warm {
            start.get_or_insert_with(Instant::now);
            count += 1;
        }
    }
    child.kill()?;
    child.wait()?;
    let secs = start.map_or(0.0, |s| s.elapsed().as_secs_f64());
    println!(
        "shm size {size} B: {count} samples in {secs:.2} s: {:.0} samples/s, {:.2} Gb/s (lost {lost}, checksum {sum})",
        count as f64 / secs,
        count as f64 * size as f64 * 8.0 / secs / 1e9
    );
    Ok(())
}
