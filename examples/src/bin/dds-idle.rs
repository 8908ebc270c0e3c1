//! A participant that only takes part in discovery: the "bare participant" of `scripts/bench-footprint.sh`.
//!
//! It joins a domain, creates no endpoint, prints `ready` once it is up and then sleeps until it is signalled or
//! `--seconds` pass. Its resident memory, sampled from outside, is the cost of what it discovers.

use std::sync::mpsc;
use std::time::Duration;

use clap::Parser;
use dds_runtime::prelude::*;

/// Command line of `dds-idle`.
#[derive(Parser)]
#[command(about = "Join a domain with no endpoints and idle (footprint probe)")]
struct Args {
    /// Domain id.
    #[arg(short = 'd', long, default_value_t = 0)]
    domain: u32,
    /// Exit after this many seconds.
    #[arg(long, default_value_t = 3600)]
    seconds: u64,
}

fn main() -> DdsResult<()> {
    let args = Args::parse();
    let _participant = DomainParticipant::new(args.domain)?;
    println!("ready pid {}", std::process::id());
    let (tx, rx) = mpsc::channel();
    ctrlc::set_handler(move || {
        let _ = tx.send(());
    })
    .expect("signal handler");
    let _ = rx.recv_timeout(Duration::from_secs(args.seconds));
    Ok(())
}
