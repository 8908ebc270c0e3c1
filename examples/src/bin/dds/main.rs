//! `dds`: a command line that looks at a DDS domain. `dds ls` lists participants, topics, types, writers,
//! readers and their QoS; `dds ps` lists applications; `dds typeof`, `dds subscribe` and `dds publish` print a
//! topic's type, read it and write it through dynamic types. See docs/dds-cli.md.

mod ls;
mod observer;
mod ps;
mod publish;
mod render;
mod resolve;
mod snapshot;
mod subscribe;

use std::io::Write;
use std::path::PathBuf;
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
    /// Print a topic's type as IDL.
    Typeof {
        /// Topic name.
        topic: String,
        #[command(flatten)]
        ty: TypeSource,
    },
    /// Print a topic's samples as they arrive.
    Subscribe {
        /// Topic name.
        topic: String,
        #[command(flatten)]
        ty: TypeSource,
        /// Output format.
        #[arg(short, long, value_enum, default_value_t = subscribe::Format::Table)]
        format: subscribe::Format,
        /// Shorthand for `--format json`.
        #[arg(long, conflicts_with = "format")]
        json: bool,
        /// Shorthand for `--format ndjson`.
        #[arg(long, conflicts_with_all = ["format", "json"])]
        ndjson: bool,
        /// Only samples matching this content-filter expression (e.g. "x > 10 AND color = 'RED'").
        #[arg(long)]
        filter: Option<String>,
        /// Stop after this many samples.
        #[arg(short = 'n', long)]
        count: Option<usize>,
        /// Stop after this many seconds.
        #[arg(long)]
        timeout: Option<f64>,
        /// A reliable reader (default: best effort, which matches every writer).
        #[arg(long)]
        reliable: bool,
    },
    /// Write samples given as JSON: one object, an array of objects, or `-` for NDJSON on stdin.
    Publish {
        /// Topic name.
        topic: String,
        /// The sample(s), as JSON.
        json: String,
        #[command(flatten)]
        ty: TypeSource,
        /// Write the samples this many times.
        #[arg(long, default_value_t = 1)]
        repeat: usize,
        /// Seconds between repetitions.
        #[arg(long, default_value_t = 1.0)]
        interval: f64,
    },
}

/// Where the topic's type comes from: an IDL file, else discovery.
#[derive(Args)]
struct TypeSource {
    /// Take the type from this IDL file.
    #[arg(long)]
    idl: Option<PathBuf>,
    /// The type's scoped name in the IDL file (default: the discovered type name, or the file's only type).
    #[arg(long = "type")]
    type_name: Option<String>,
    /// Seconds to wait for discovery (of the topic's type, or of readers before publishing).
    #[arg(short, long, default_value_t = 2.0)]
    wait: f64,
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
        Command::Typeof { topic, ty } => with_type(cli.domain, &topic, &ty, |_, r| {
            print!("{}", r.ty.to_idl());
            Ok(())
        }),
        Command::Subscribe {
            topic,
            ty,
            format,
            json,
            ndjson,
            filter,
            count,
            timeout,
            reliable,
        } => {
            let format = match (json, ndjson) {
                (true, _) => subscribe::Format::Json,
                (_, true) => subscribe::Format::Ndjson,
                _ => format,
            };
            let o = subscribe::Options {
                format,
                filter,
                count,
                timeout: timeout.map(seconds),
                reliable,
            };
            with_type(cli.domain, &topic, &ty, |p, r| {
                subscribe::run(p, &topic, r, &o)
            })
        }
        Command::Publish {
            topic,
            json,
            ty,
            repeat,
            interval,
        } => {
            let o = publish::Options {
                repeat,
                interval: seconds(interval),
                wait: seconds(ty.wait),
            };
            with_type(cli.domain, &topic, &ty, |p, r| {
                publish::run(p, &topic, r, &json, &o)
            })
        }
    }
}

/// Joins the domain, resolves the topic's type (from `--idl`, else discovery), then runs `f`. Exit codes: 1 when
/// the domain cannot be joined or `f` fails, 3 when the type cannot be resolved.
fn with_type(
    domain: Option<u32>,
    topic: &str,
    src: &TypeSource,
    f: impl FnOnce(&dds_runtime::prelude::DomainParticipant, resolve::Resolved) -> Result<(), String>,
) -> ExitCode {
    use resolve::TopicTypes;
    let observer = match Observer::join(domain) {
        Ok(o) => o,
        Err(e) => {
            eprintln!("dds: cannot join the domain: {e}");
            return ExitCode::FAILURE;
        }
    };
    let p = observer.participant();
    let discovery = resolve::DiscoveredTypes::new(p, seconds(src.wait));
    let resolved = match &src.idl {
        Some(path) => resolve::IdlTypes::load(path, src.type_name.clone(), discovery)
            .and_then(|t| t.resolve(topic)),
        None => discovery.resolve(topic),
    };
    let resolved = match resolved {
        Ok(r) => r,
        Err(e) => {
            eprintln!("dds: {e}");
            return ExitCode::from(3);
        }
    };
    match f(p, resolved) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("dds: {e}");
            ExitCode::FAILURE
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
