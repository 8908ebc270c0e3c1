//! `dds-durability`: the standalone durability service. It keeps a domain's TRANSIENT and PERSISTENT data
//! while applications come and go, and serves it to late-joining readers; with `--store` it keeps PERSISTENT
//! data in a redb database and restores it when restarted. docs/durability.md has the details.
//!
//! ```sh
//! dds-durability --domain 0 --store /var/lib/dds/domain0.redb
//! ```

use std::path::PathBuf;
use std::time::{Duration, Instant};

use clap::Parser;
use dds_examples::shutdown;
use dds_runtime::prelude::*;

/// The standalone DDS durability service of one domain.
#[derive(Parser, Debug)]
#[command(name = "dds-durability", version)]
struct Args {
    /// Domain id (default: DDS_DOMAIN_ID, else 0).
    #[arg(short, long)]
    domain: Option<u32>,
    /// redb database for PERSISTENT data (created when missing, restored at start). Without it, PERSISTENT
    /// data is kept in memory like TRANSIENT data.
    #[arg(short, long)]
    store: Option<PathBuf>,
    /// Most changes kept per original writer, whatever its DURABILITY_SERVICE QoS allows.
    #[arg(long, default_value_t = DurabilityServiceConfig::DEFAULT_MAX_CHANGES_PER_WRITER)]
    max_changes_per_writer: usize,
    /// Stop after this many seconds (default: run until SIGINT/SIGTERM).
    #[arg(long)]
    duration: Option<f64>,
}

fn main() {
    let args = Args::parse();
    shutdown::install();
    if let Err(e) = run(&args) {
        eprintln!("dds-durability: {e}");
        std::process::exit(1);
    }
}

fn run(args: &Args) -> DdsResult<()> {
    let mut service =
        DurabilityServiceConfig::domain().max_changes_per_writer(args.max_changes_per_writer);
    if let Some(p) = &args.store {
        service = service.persistent_store(p);
    }
    let mut builder = DomainParticipant::builder()
        .durability_service(service)
        .name("dds-durability");
    if let Some(d) = args.domain {
        builder = builder.domain_id(d);
    }
    let participant = builder.build()?;
    println!(
        "dds-durability: domain {}, store {}, ready",
        participant.domain_id(),
        args.store
            .as_ref()
            .map_or("none (memory only)".to_string(), |p| p
                .display()
                .to_string())
    );
    let end = args
        .duration
        .map(|s| Instant::now() + Duration::from_secs_f64(s.max(0.0)));
    while !shutdown::requested() && end.is_none_or(|e| Instant::now() < e) {
        shutdown::sleep(Duration::from_millis(200));
    }
    println!("dds-durability: stopped");
    Ok(())
}
