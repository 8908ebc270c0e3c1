//! `dds`: a command line that looks at a DDS domain. `dds ls` lists participants, topics, types, writers,
//! readers and their QoS; `dds ps` lists applications. `typeof`, `subscribe` and `publish` need XTypes
//! dynamic types and are not there yet. See docs/dds-cli.md.

mod ls;
mod observer;
mod ps;
mod render;
mod snapshot;

use std::io::Write;
use std::process::ExitCode;
use std::time::Duration;

use clap::{Args, Parser, Subcommand};

use crate::observer::Observer;
use crate::render::Style;
use crate::snapshot::Snapshot;

/// Command line of `dds`.
#[derive(Parser)]
#[command(
    name = "dds",
    about = "Look at a DDS domain: participants, topics, writers, readers"
)]
struct Cli {
    /// Domain id (default: `DDS_DOMAIN_ID`, else 0).
    #[arg(short = 'd', long, global = true)]
    domain: Option<u32>,
    #[command(subcommand)]
    command: Command,
}

/// The subcommands.
#[derive(Subcommand)]
enum Command {
    /// List participants, topics with their types, and every writer and reader with its QoS.
    Ls(View),
    /// List applications: host, pid, program, and how many writers and readers each has.
    Ps(View),
    /// Print a topic's type as IDL (not yet: needs XTypes dynamic types).
    Typeof {
        /// Topic name.
        topic: String,
    },
    /// Print a topic's samples (not yet: needs XTypes dynamic types).
    Subscribe {
        /// Topic name.
        topic: String,
    },
    /// Write samples given as JSON (not yet: needs XTypes dynamic types).
    Publish {
        /// Topic name.
        topic: String,
        /// The sample, as JSON.
        json: String,
    },
}

/// Options shared by `ls` and `ps`.
#[derive(Args)]
struct View {
    /// Seconds to wait for discovery before printing.
    #[arg(short, long, default_value_t = 2.0)]
    wait: f64,
    /// Keep watching and reprint every `--interval` seconds (until interrupted).
    #[arg(long)]
    watch: bool,
    /// Seconds between updates with `--watch`.
    #[arg(long, default_value_t = 1.0)]
    interval: f64,
    /// Print JSON (one document per update with `--watch`).
    #[arg(long)]
    json: bool,
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    match cli.command {
        Command::Ls(v) => watch(cli.domain, &v, |s, style| {
            if v.json {
                s.to_json().to_string()
            } else {
                ls::text(s, style)
            }
        }),
        Command::Ps(v) => watch(cli.domain, &v, |s, style| {
            if v.json {
                ps::json(s).to_string()
            } else {
                ps::text(s, style)
            }
        }),
        Command::Typeof { .. } | Command::Subscribe { .. } | Command::Publish { .. } => {
            eprintln!("dds: not yet: needs XTypes dynamic types");
            ExitCode::from(2)
        }
    }
}

/// Joins the domain, waits for discovery, prints once, or again every interval with `--watch`.
fn watch(domain: Option<u32>, v: &View, show: impl Fn(&Snapshot, Style) -> String) -> ExitCode {
    let observer = match Observer::join(domain) {
        Ok(o) => o,
        Err(e) => {
            eprintln!("dds: cannot join the domain: {e}");
            return ExitCode::FAILURE;
        }
    };
    let style = Style::detect();
    let clear = style.interactive() && !v.json;
    observer.run_for(seconds(v.wait));
    loop {
        let text = show(&observer.snapshot(), style);
        let mut out = std::io::stdout().lock();
        let shown = if clear {
            write!(out, "\x1b[2J\x1b[H")
        } else {
            Ok(())
        }
        .and_then(|()| writeln!(out, "{}", text.trim_end()))
        .and_then(|()| out.flush());
        // A closed pipe (`dds ls --watch | head`) ends the command quietly.
        if shown.is_err() || !v.watch {
            return ExitCode::SUCCESS;
        }
        drop(out);
        observer.run_for(seconds(v.interval));
    }
}

/// A non-negative, finite number of seconds.
fn seconds(s: f64) -> Duration {
    Duration::try_from_secs_f64(s).unwrap_or(Duration::ZERO)
}
