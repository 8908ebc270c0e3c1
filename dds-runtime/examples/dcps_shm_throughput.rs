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
//! the subscriber takes them and reports samples/s from its first to its last sample. Modes, interleaved
//! in each round: `loan` (shared memory, a plain-data sample of SIZE bytes written in place through
//! `DataWriter::loan_unzeroed`, read in place; SIZE 1048576 or 4194304 only), `shm` (shared memory, a
//! `{seq, Vec<u8>}` sample serialized and copied into the channel) and `udp` (the `Vec<u8>` sample over
//! loopback UDP); `loanv` is `loan` with a reader that decodes each sample by value.
//!
//! What the writer writes per sample: in the plain modes only the sequence number, as `dds-perf`'s writer
//! (which sets `seq` and `keyval` and leaves its payload alone): the `shm` and `udp` writers keep one
//! `Vec` and the `loan` writer writes the `seq` into a loan that holds an earlier sample's bytes. In the
//! `-fill` modes (`loan-fill`, `shm-fill`, `udp-fill`) every writer writes every byte of each sample
//! (into the loan, or into its `Vec`): an application that produces SIZE new bytes per sample. Without a
//! mode list, SIZE 1048576 or 4194304 runs `loan,shm,udp,loan-fill,shm-fill,udp-fill`; every mode's ratio
//! is to the `udp` mode with the same writes, and the summary gives the medians of the per-round ratios
//! of `loan`, `shm` to `udp` and of `loan-fill`, `shm-fill` to `udp-fill`. Each line also gives the load
//! average at its start (`/proc/loadavg`).

use std::io::{BufRead, BufReader};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use dds_runtime::config::InterfaceSelection;
use dds_runtime::dcps::InPlace;
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

/// A plain-data sample of 1 MiB: its encoding is its memory image, so it can be loaned.
#[derive(DdsType, Clone, Copy)]
#[dds(name = "bench::Plain1M", final)]
#[repr(C)]
struct Plain1M {
    seq: u64,
    data: [u8; (1 << 20) - 8],
}

/// A plain-data sample of 4 MiB.
#[derive(DdsType, Clone, Copy)]
#[dds(name = "bench::Plain4M", final)]
#[repr(C)]
struct Plain4M {
    seq: u64,
    data: [u8; (4 << 20) - 8],
}

// SAFETY: `repr(C)`: a `u64` then bytes, a multiple of 8 long: no padding; every bit pattern is valid.
unsafe impl bytemuck::Zeroable for Plain1M {}
// SAFETY: as above.
unsafe impl bytemuck::Pod for Plain1M {}
// SAFETY: as above.
unsafe impl bytemuck::Zeroable for Plain4M {}
// SAFETY: as above.
unsafe impl bytemuck::Pod for Plain4M {}

/// What the benchmark needs of a sample type.
trait Bench: DdsType {
    fn seq(&self) -> u64;
}

impl Bench for Payload {
    fn seq(&self) -> u64 {
        self.seq
    }
}

impl Bench for Plain1M {
    fn seq(&self) -> u64 {
        self.seq
    }
}

impl Bench for Plain4M {
    fn seq(&self) -> u64 {
        self.seq
    }
}

impl<T: Bench + bytemuck::Pod> Bench for InPlace<T> {
    fn seq(&self) -> u64 {
        (**self).seq()
    }
}

/// A plain sample type that can be loaned.
trait Loanable: Bench + bytemuck::Pod {
    /// Writes the sequence number, and every other byte too when `all`.
    fn fill(&mut self, seq: u64, all: bool);
}

impl Loanable for Plain1M {
    fn fill(&mut self, seq: u64, all: bool) {
        self.seq = seq;
        if all {
            self.data.fill(seq as u8);
        }
    }
}

impl Loanable for Plain4M {
    fn fill(&mut self, seq: u64, all: bool) {
        self.seq = seq;
        if all {
            self.data.fill(seq as u8);
        }
    }
}

/// The way a measurement's samples go.
#[derive(Clone, Copy, PartialEq, Eq, Debug)]
enum Path {
    /// Loaned and written in place; the reader reads in place (`InPlace<T>`).
    Loan,
    /// Loaned and written in place; the reader decodes each sample by value (a copy of `T`).
    LoanCopy,
    Shm,
    Udp,
}

/// How a measurement sends its samples.
#[derive(Clone, Copy, PartialEq, Eq, Debug)]
struct Mode {
    path: Path,
    /// The writer writes every byte of each sample, not only its sequence number.
    fill: bool,
}

impl Mode {
    fn name(self) -> String {
        let path = match self.path {
            Path::Loan => "loan",
            Path::LoanCopy => "loanv",
            Path::Shm => "shm",
            Path::Udp => "udp",
        };
        if self.fill {
            format!("{path}-fill")
        } else {
            path.to_owned()
        }
    }

    fn parse(s: &str) -> Mode {
        let (path, fill) = match s.strip_suffix("-fill") {
            Some(p) => (p, true),
            None => (s, false),
        };
        let path = match path {
            "loan" => Path::Loan,
            "loanv" => Path::LoanCopy,
            "shm" => Path::Shm,
            _ => Path::Udp,
        };
        Mode { path, fill }
    }

    fn shm(self) -> bool {
        self.path != Path::Udp
    }
}

fn loadavg() -> String {
    std::fs::read_to_string("/proc/loadavg")
        .ok()
        .and_then(|s| s.split_whitespace().next().map(str::to_owned))
        .unwrap_or_default()
}

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
fn subscriber<T: Bench>(domain: u32, shm: bool) -> Result<(), Box<dyn std::error::Error>> {
    let p = participant(domain, shm)?;
    let topic = p.create_topic::<T>("ShmBench", &TopicQos::default())?;
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
        let samples = r.take()?;
        for s in &samples {
            let Some(d) = &s.data else { continue };
            if d.seq() == LAST {
                end = true;
                continue;
            }
            first.get_or_insert_with(Instant::now);
            last = Instant::now();
            got += 1;
        }
        // Later samples are decoded into these (a sample read in place goes back to its writer).
        r.recycle(samples);
        if end {
            break;
        }
    }
    let secs = first.map_or(0.0, |f| last.duration_since(f).as_secs_f64());
    println!("{got} {secs}");
    Ok(())
}

/// A matched writer of `T` in a participant with shared memory on or off.
fn matched_writer<T: DdsType>(
    p: &DomainParticipant,
) -> Result<DataWriter<T>, Box<dyn std::error::Error>> {
    let topic = p.create_topic::<T>("ShmBench", &TopicQos::default())?;
    let w = p
        .create_publisher(&PublisherQos::default())?
        .create_datawriter(&topic, &qos().0)?;
    while w.publication_matched_status().current_count == 0 {
        std::thread::sleep(Duration::from_millis(10));
    }
    Ok(w)
}

/// Writes `{seq, Vec<u8>}` samples of `size` bytes until `end` (rewriting every byte of the `Vec` per
/// sample when `fill`), then the end marker.
fn write_vec(w: &DataWriter<Payload>, size: usize, end: Instant, fill: bool) -> DdsResult<()> {
    let mut sample = Payload {
        seq: 0,
        data: vec![0x5a; size],
    };
    while Instant::now() < end {
        if fill {
            sample.data.fill(sample.seq as u8);
        }
        w.write(&sample)?;
        sample.seq += 1;
    }
    sample.seq = LAST;
    sample.data.clear();
    w.write(&sample)
}

/// Loans (unzeroed: the buffer holds an earlier sample's bytes), fills (the `seq`, or every byte when
/// `fill`) and writes plain samples until `end`, then the end marker.
fn write_loaned<T: Loanable>(
    w: &DataWriter<T>,
    end: Instant,
    fill: bool,
) -> Result<(), Box<dyn std::error::Error>> {
    let mut seq = 0;
    while Instant::now() < end {
        let mut loan = w.loan_unzeroed()?;
        loan.fill(seq, fill);
        loan.write()?;
        seq += 1;
    }
    let mut loan = w.loan_unzeroed()?;
    loan.fill(LAST, false);
    loan.write()?;
    Ok(())
}

/// One measurement: samples/s seen by the subscriber.
fn measure(
    domain: u32,
    mode: Mode,
    size: usize,
    secs: f64,
) -> Result<f64, Box<dyn std::error::Error>> {
    let mut child = Command::new(std::env::current_exe()?)
        .args(["sub", &domain.to_string(), &mode.name(), &size.to_string()])
        .stdout(Stdio::piped())
        .spawn()?;
    let mut out = BufReader::new(child.stdout.take().ok_or("no stdout")?);
    let mut line = String::new();
    out.read_line(&mut line)?;
    let p = participant(domain, mode.shm())?;
    let end = |_| Instant::now() + Duration::from_secs_f64(secs);
    match (mode.path, size) {
        (Path::Loan | Path::LoanCopy, 1048576) => {
            let w = matched_writer::<Plain1M>(&p)?;
            write_loaned(&w, end(()), mode.fill)?;
        }
        (Path::Loan | Path::LoanCopy, 4194304) => {
            let w = matched_writer::<Plain4M>(&p)?;
            write_loaned(&w, end(()), mode.fill)?;
        }
        (Path::Loan | Path::LoanCopy, _) => {
            return Err("loan modes: SIZE 1048576 or 4194304".into())
        }
        _ => {
            let w = matched_writer::<Payload>(&p)?;
            write_vec(&w, size, end(()), mode.fill)?;
        }
    }
    line.clear();
    out.read_line(&mut line)?;
    child.wait()?;
    let mut f = line.split_whitespace();
    let got: f64 = f.next().ok_or("no count")?.parse()?;
    let took: f64 = f.next().ok_or("no time")?.parse()?;
    Ok(if took > 0.0 { got / took } else { 0.0 })
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    if std::env::var_os("RUST_LOG").is_some() {
        tracing_subscriber::fmt()
            .with_env_filter(tracing_subscriber::EnvFilter::from_default_env())
            .with_writer(std::io::stderr)
            .init();
    }
    let args: Vec<String> = std::env::args().skip(1).collect();
    if args.first().map(String::as_str) == Some("sub") {
        let (domain, mode, size): (u32, Mode, usize) =
            (args[1].parse()?, Mode::parse(&args[2]), args[3].parse()?);
        // `loanv` decodes plain samples by value: a stack for a few copies of 4 MiB.
        let sub = std::thread::Builder::new().stack_size(256 << 20).spawn(
            move || -> Result<(), String> {
                let shm = mode.shm();
                let r = match (mode.path, size) {
                    (Path::Loan, 1048576) => subscriber::<InPlace<Plain1M>>(domain, shm),
                    (Path::Loan, _) => subscriber::<InPlace<Plain4M>>(domain, shm),
                    (Path::LoanCopy, 1048576) => subscriber::<Plain1M>(domain, shm),
                    (Path::LoanCopy, _) => subscriber::<Plain4M>(domain, shm),
                    _ => subscriber::<Payload>(domain, shm),
                };
                r.map_err(|e| e.to_string())
            },
        )?;
        return sub
            .join()
            .map_err(|_| "subscriber panicked")?
            .map_err(Into::into);
    }
    let size: usize = args.first().map_or(Ok(1 << 20), |s| s.parse())?;
    let secs: f64 = args.get(1).map_or(Ok(5.0), |s| s.parse())?;
    let rounds: u32 = args.get(2).map_or(Ok(2), |s| s.parse())?;
    let modes: Vec<Mode> = match args.get(3) {
        Some(m) => m.split(',').map(Mode::parse).collect(),
        None if matches!(size, 1048576 | 4194304) => "loan,shm,udp,loan-fill,shm-fill,udp-fill"
            .split(',')
            .map(Mode::parse)
            .collect(),
        None => vec![Mode::parse("shm"), Mode::parse("udp")],
    };
    let mut rates: Vec<Vec<f64>> = vec![Vec::new(); modes.len()];
    for round in 0..rounds {
        for (i, mode) in modes.iter().enumerate() {
            let domain = 130 + round * modes.len() as u32 + i as u32;
            let load = loadavg();
            let rate = measure(domain, *mode, size, secs)?;
            let mbps = rate * size as f64 * 8.0 / 1e9;
            println!(
                "round {round} {:>9} size {size} B: {rate:.0} samples/s ({mbps:.2} Gb/s), load {load}",
                mode.name()
            );
            rates[i].push(rate);
        }
    }
    summary(size, &modes, &rates);
    Ok(())
}

/// Each mode's mean rate and its per-round ratios to the `udp` mode with the same writes, then the
/// medians of those ratios.
fn summary(size: usize, modes: &[Mode], rates: &[Vec<f64>]) {
    let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len().max(1) as f64;
    let udp = |fill| {
        modes.iter().position(|m| {
            *m == Mode {
                path: Path::Udp,
                fill,
            }
        })
    };
    let mut medians = Vec::new();
    for (mode, r) in modes.iter().zip(rates) {
        let ratio = udp(mode.fill).map_or(String::new(), |u| {
            let mut per_round: Vec<f64> = r
                .iter()
                .zip(&rates[u])
                .map(|(x, y)| x / y.max(f64::MIN_POSITIVE))
                .collect();
            let shown: Vec<String> = per_round.iter().map(|x| format!("{x:.1}")).collect();
            per_round.sort_by(f64::total_cmp);
            if mode.path != Path::Udp {
                let udp = Mode {
                    path: Path::Udp,
                    ..*mode
                };
                let median = per_round[per_round.len() / 2];
                medians.push(format!("{} / {}: {median:.1}x", mode.name(), udp.name()));
            }
            format!(", per round {} x {}", shown.join(" / "), modes[u].name())
        });
        println!(
            "size {size} B {:>9}: mean {:.0} samples/s{ratio}",
            mode.name(),
            mean(r)
        );
    }
    if !medians.is_empty() {
        println!(
            "size {size} B medians of per-round ratios: {}",
            medians.join(", ")
        );
    }
}
