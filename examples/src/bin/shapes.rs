//! `shapes`: the friendly demo. One process runs a publisher of bouncing shapes and a subscriber, each in
//! its own domain participant, so every sample crosses real RTPS over UDP (loopback inside
//! `scripts/isolated`). Positions are printed live; after `--duration` seconds (default 10) or `--count`
//! received samples it prints a summary and exits 0 (1 when a subscriber received nothing).
//!
//!     scripts/isolated cargo run --release --bin shapes
//!     shapes --pub-only --color RED --color GREEN        # interoperates with any shape_main subscriber
//!     shapes --sub-only --topic Circle --duration 30

use std::collections::BTreeMap;
use std::process::ExitCode;
use std::time::{Duration, Instant, SystemTime};

use dds_examples::shutdown;
use dds_examples::topic_types::ShapeType;
use dds_runtime::prelude::*;

#[derive(Debug, Clone)]
struct Args {
    publish: bool,
    subscribe: bool,
    topic: String,
    colors: Vec<String>,
    domain: u32,
    duration: Duration,
    count: Option<u64>,
    rate_hz: f64,
    quiet: bool,
    /// Data representation written: XCDR1 by default, like the OMG suite's shape_main (`-x 1`).
    xcdr2: bool,
}

const USAGE: &str =
    "usage: shapes [--pub-only | --sub-only] [-t|--topic NAME] [-c|--color COLOR]...
              [-d|--domain ID] [--duration SECS] [--count N] [--rate HZ] [-x|--xcdr 1|2] [-q|--quiet]

  Runs a publisher of bouncing shapes and a subscriber in one process (two participants, real RTPS)
  and prints what the subscriber receives. Defaults: topic Square, colors BLUE and RED, domain 0,
  10 samples/s per color, stops after 10 s (or after N received samples with --count) and prints a
  summary. Samples are written in XCDR1 (-x 2: XCDR2), as shape_main does; the subscriber accepts
  both. --quiet prints only the summary.";

fn parse_args(argv: &[String]) -> Result<Option<Args>, String> {
    let mut a = Args {
        publish: true,
        subscribe: true,
        topic: "Square".into(),
        colors: Vec::new(),
        domain: 0,
        duration: Duration::from_secs(10),
        count: None,
        rate_hz: 10.0,
        quiet: false,
        xcdr2: false,
    };
    let mut it = argv.iter();
    while let Some(arg) = it.next() {
        let (name, inline) = match arg.split_once('=') {
            Some((n, v)) if n.starts_with("--") => (n, Some(v.to_string())),
            _ => (arg.as_str(), None),
        };
        let mut value = |what: &str| -> Result<String, String> {
            inline
                .clone()
                .or_else(|| it.next().cloned())
                .ok_or_else(|| format!("{what} needs a value"))
        };
        match name {
            "-h" | "--help" => return Ok(None),
            "--pub-only" | "--pub" => a.subscribe = false,
            "--sub-only" | "--sub" => a.publish = false,
            "-q" | "--quiet" => a.quiet = true,
            "-x" | "--xcdr" => {
                a.xcdr2 = match value("--xcdr")?.as_str() {
                    "1" => false,
                    "2" => true,
                    _ => return Err("--xcdr must be 1 or 2".into()),
                }
            }
            "-t" | "--topic" => a.topic = value("--topic")?,
            "-c" | "--color" => a.colors.push(value("--color")?),
            "-d" | "--domain" => {
                a.domain = value("--domain")?
                    .parse()
                    .map_err(|_| "bad --domain".to_string())?
            }
            "--duration" => {
                let s: f64 = value("--duration")?
                    .parse()
                    .map_err(|_| "bad --duration".to_string())?;
                if !(s > 0.0 && s.is_finite()) {
                    return Err("--duration must be > 0".into());
                }
                a.duration = Duration::from_secs_f64(s);
            }
            "--count" => {
                a.count = Some(
                    value("--count")?
                        .parse()
                        .map_err(|_| "bad --count".to_string())?,
                )
            }
            "--rate" => {
                a.rate_hz = value("--rate")?
                    .parse()
                    .map_err(|_| "bad --rate".to_string())?;
                if !(a.rate_hz > 0.0 && a.rate_hz <= 10_000.0) {
                    return Err("--rate must be in (0, 10000]".into());
                }
            }
            other => return Err(format!("unknown argument {other}")),
        }
    }
    if !a.publish && !a.subscribe {
        return Err("--pub-only and --sub-only exclude each other".into());
    }
    if a.colors.is_empty() {
        a.colors = if a.publish {
            vec!["BLUE".into(), "RED".into()]
        } else {
            Vec::new()
        };
    }
    Ok(Some(a))
}

fn main() -> ExitCode {
    let argv: Vec<String> = std::env::args().skip(1).collect();
    let args = match parse_args(&argv) {
        Ok(Some(a)) => a,
        Ok(None) => {
            println!("{USAGE}");
            return ExitCode::SUCCESS;
        }
        Err(e) => {
            eprintln!("shapes: {e}\n{USAGE}");
            return ExitCode::from(2);
        }
    };
    shutdown::install();
    match run(&args) {
        Ok(code) => ExitCode::from(code),
        Err(e) => {
            eprintln!("shapes: {e}");
            ExitCode::from(2)
        }
    }
}

/// A shape bouncing inside the suite's 240 x 270 area.
struct Bouncer {
    shape: ShapeType,
    dx: i32,
    dy: i32,
}

impl Bouncer {
    fn new(color: &str, i: usize) -> Self {
        let i = i as i32;
        Bouncer {
            shape: ShapeType {
                color: color.into(),
                x: 20 + 37 * i % 200,
                y: 30 + 53 * i % 230,
                shapesize: 30,
                ..Default::default()
            },
            dx: 3 + i % 3,
            dy: 2 + (i + 1) % 4,
        }
    }

    fn step(&mut self) {
        let s = &mut self.shape;
        s.x += self.dx;
        s.y += self.dy;
        if !(0..=240).contains(&s.x) {
            self.dx = -self.dx;
            s.x = s.x.clamp(0, 240);
        }
        if !(0..=270).contains(&s.y) {
            self.dy = -self.dy;
            s.y = s.y.clamp(0, 270);
        }
    }
}

#[derive(Default)]
struct Received {
    samples: u64,
    per_color: BTreeMap<String, u64>,
    latency_sum: Duration,
    latency_max: Duration,
}

fn run(a: &Args) -> DdsResult<u8> {
    let reliable = DataWriterQos::builder()
        .reliability(Reliability::RELIABLE)
        .history(History::KeepLast(1))
        .data_representation(if a.xcdr2 {
            DataRepresentation::xcdr2()
        } else {
            DataRepresentation::xcdr1()
        })
        .build();
    let both = DataRepresentation::accept_both();
    let reader_qos = DataReaderQos::builder()
        .reliability(Reliability::RELIABLE)
        .history(History::KeepLast(8))
        .data_representation(both)
        .build();

    // Separate participants: what the subscriber prints has gone through the stack's sockets.
    let sub_side = if a.subscribe {
        let p = DomainParticipant::builder().domain_id(a.domain).build()?;
        let topic = p.create_topic::<ShapeType>(&a.topic, &TopicQos::default())?;
        let reader = p
            .create_subscriber(&SubscriberQos::default())?
            .create_datareader(&topic, &reader_qos)?;
        Some((p, reader))
    } else {
        None
    };
    let pub_side = if a.publish {
        let p = DomainParticipant::builder().domain_id(a.domain).build()?;
        let topic = p.create_topic::<ShapeType>(&a.topic, &TopicQos::default())?;
        let writer = p
            .create_publisher(&PublisherQos::default())?
            .create_datawriter(&topic, &reliable)?;
        Some((p, writer))
    } else {
        None
    };
    let role = match (a.publish, a.subscribe) {
        (true, true) => "publishing and subscribing",
        (true, false) => "publishing",
        _ => "subscribing",
    };
    println!(
        "shapes: {role} on topic '{}' in domain {} for {:.1} s{}",
        a.topic,
        a.domain,
        a.duration.as_secs_f64(),
        if a.publish {
            format!(", colors {}", a.colors.join(" "))
        } else {
            String::new()
        }
    );

    let mut bouncers: Vec<Bouncer> = a
        .colors
        .iter()
        .enumerate()
        .map(|(i, c)| Bouncer::new(c, i))
        .collect();
    let period = Duration::from_secs_f64(1.0 / a.rate_hz);
    let start = Instant::now();
    let mut next_write = start;
    let mut written = 0u64;
    let mut got = Received::default();
    while !shutdown::requested()
        && start.elapsed() < a.duration
        && a.count.is_none_or(|n| got.samples < n)
    {
        if let Some((_, w)) = &pub_side {
            if Instant::now() >= next_write {
                for b in &mut bouncers {
                    b.step();
                    match w.write(&b.shape) {
                        Ok(()) => written += 1,
                        Err(DdsError::Timeout) => {}
                        Err(e) => return Err(e),
                    }
                    if !a.subscribe && !a.quiet {
                        println!(
                            "sent     {:<10} {:<8} x={:3} y={:3}",
                            a.topic, b.shape.color, b.shape.x, b.shape.y
                        );
                    }
                }
                next_write += period;
            }
        }
        let wait = next_write
            .saturating_duration_since(Instant::now())
            .min(Duration::from_millis(50));
        if let Some((_, r)) = &sub_side {
            if r.wait_for_data(wait)? {
                for s in r.take()? {
                    let Some(d) = s.data else { continue };
                    let latency = SystemTime::now()
                        .duration_since(s.info.source_timestamp)
                        .unwrap_or_default();
                    got.samples += 1;
                    *got.per_color.entry(d.color.clone()).or_default() += 1;
                    got.latency_sum += latency;
                    got.latency_max = got.latency_max.max(latency);
                    if !a.quiet {
                        println!(
                            "received {:<10} {:<8} x={:3} y={:3} size={:2}  ({:.0} us)",
                            a.topic,
                            d.color,
                            d.x,
                            d.y,
                            d.shapesize,
                            latency.as_secs_f64() * 1e6
                        );
                    }
                }
            }
        } else {
            std::thread::sleep(wait);
        }
    }

    // Last samples and acknowledgments before the summary.
    if let Some((_, w)) = &pub_side {
        let _ = w.wait_for_acknowledgments(Duration::from_secs(1));
    }
    let elapsed = start.elapsed().as_secs_f64();
    println!("---- summary after {elapsed:.1} s ----");
    if a.publish {
        println!(
            "wrote    {written} samples ({} colors at {} Hz)",
            a.colors.len(),
            a.rate_hz
        );
    }
    if a.subscribe {
        let mean = if got.samples > 0 {
            got.latency_sum.as_secs_f64() * 1e6 / got.samples as f64
        } else {
            0.0
        };
        let colors: Vec<String> = got
            .per_color
            .iter()
            .map(|(c, n)| format!("{c}: {n}"))
            .collect();
        println!("received {} samples [{}]", got.samples, colors.join(", "));
        println!(
            "latency  mean {mean:.0} us, max {:.0} us",
            got.latency_max.as_secs_f64() * 1e6
        );
    }
    Ok(if a.subscribe && got.samples == 0 {
        1
    } else {
        0
    })
}
