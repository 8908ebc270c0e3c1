//! `dds-perf`: throughput and latency tool compatible with Cyclone DDS's `ddsperf` on the wire and on the
//! terminal. Same topics ("DDSPerfRDataKS", "DDSPerfRPingKS", "DDSPerfRPongKS", ...), types, QoS,
//! participant user data (`DDSPerf:<has_reader>:<pid>:<host>`) and ping/pong protocol:
//! - the least significant bit of the source timestamp marks a sample that wants an answer;
//! - a pong goes out on a writer in the pinging participant's partition (its GUID as text), echoing the
//!   sample with the ping's timestamp (lsb set for pings, cleared for pinged data samples);
//! - the pinger reports half the round trip.
//!
//! Exit status: 0 fine, 1 loss or too few samples/round trips, 2 DDS failure, 3 bad arguments.

use std::process::ExitCode;
use std::sync::atomic::{AtomicBool, AtomicU32, Ordering};
use std::sync::{Arc, Mutex, RwLock};
use std::thread;
use std::time::{Duration, Instant, SystemTime, UNIX_EPOCH};

use dds_examples::perf_args::{self, PerfCommand, PerfOptions, TopicSel, TriggerMode};
use dds_examples::perf_sample::PerfSample;
use dds_examples::perf_stats::{self, LatencyStat, SeqCheck, SubStats, WriteHist};
use dds_examples::shutdown;
use dds_examples::topic_types::{
    Keyed256, Keyed32, KeyedSeq, OneULong, Struct16, Struct256, Struct32k, Struct4k,
};
use dds_runtime::prelude::*;

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let prog = std::env::args().next().unwrap_or_else(|| "dds-perf".into());
    let o = match perf_args::parse(&args) {
        Ok(PerfCommand::Run(o)) => o,
        Ok(PerfCommand::Usage { requested }) => {
            print!("{}", perf_args::usage(&prog));
            return ExitCode::from(if requested { 0 } else { 3 });
        }
        Err(e) => {
            println!("{e}");
            return ExitCode::from(3);
        }
    };
    shutdown::install();
    let r = match o.topic {
        TopicSel::Ks => run::<KeyedSeq>(&o),
        TopicSel::K32 => run::<Keyed32>(&o),
        TopicSel::K256 => run::<Keyed256>(&o),
        TopicSel::Ou => run::<OneULong>(&o),
        TopicSel::S16 => run::<Struct16>(&o),
        TopicSel::S256 => run::<Struct256>(&o),
        TopicSel::S4k => run::<Struct4k>(&o),
        TopicSel::S32k => run::<Struct32k>(&o),
    };
    match r {
        Ok(code) => ExitCode::from(code),
        Err(e) => {
            println!("[{}] error: {e}", std::process::id());
            ExitCode::from(2)
        }
    }
}

fn now_ns() -> i64 {
    SystemTime::now()
        .duration_since(UNIX_EPOCH)
        .map(|d| d.as_nanos() as i64)
        .unwrap_or(0)
}

fn ts(ns: i64) -> SystemTime {
    UNIX_EPOCH + Duration::from_nanos(ns.max(0) as u64)
}

fn ns_of(t: SystemTime) -> i64 {
    t.duration_since(UNIX_EPOCH)
        .map(|d| d.as_nanos() as i64)
        .unwrap_or(0)
}

/// ddsperf's partition name for a participant: its GUID as 4 groups of 8 hex digits.
fn guid_string(prefix: &[u8; 12]) -> String {
    let mut g = [0u8; 16];
    g[..12].copy_from_slice(prefix);
    g[12..].copy_from_slice(&[0, 0, 1, 0xc1]);
    g.chunks(4)
        .map(|c| c.iter().map(|b| format!("{b:02x}")).collect::<String>())
        .collect::<Vec<_>>()
        .join("_")
}

fn hostname() -> String {
    let mut buf = [0u8; 256];
    // SAFETY: the buffer is valid for its length; gethostname NUL-terminates on success.
    let rc = unsafe { libc::gethostname(buf.as_mut_ptr().cast(), buf.len()) };
    if rc != 0 {
        return "?".into();
    }
    let end = buf.iter().position(|&b| b == 0).unwrap_or(buf.len());
    String::from_utf8_lossy(&buf[..end]).into_owned()
}

fn prefix_of(guid: &[u8; 16]) -> [u8; 12] {
    let mut p = [0u8; 12];
    p.copy_from_slice(&guid[..12]);
    p
}

/// State shared by the threads.
struct Ctx<T: PerfSample> {
    o: PerfOptions,
    pid: u32,
    own_prefix: [u8; 12],
    participant: DomainParticipant,
    pong_topic: Topic<T>,
    pingpong_qos: DataWriterQos,
    /// One pong writer per remote participant, in that participant's partition, by GUID prefix (searched
    /// in order: a handful of participants, and no hashing of the prefix per ping).
    pong_writers: RwLock<Vec<([u8; 12], DataWriter<T>)>>,
    ping_writer: DataWriter<T>,
    ping: Mutex<PingState>,
    pong_stats: Mutex<Vec<([u8; 16], LatencyStat)>>,
    /// The samples of one take of pings or pongs, kept between takes (no vector allocated per take);
    /// a take nested in another (a ping answered on the thread that sent it) uses its own.
    batch: Mutex<Vec<Sample<T>>>,
    sub_stats: Mutex<SubStats>,
    sub_latency: Mutex<LatencyStat>,
    pub_hist: Mutex<WriteHist>,
    write_timeouts: AtomicU32,
    /// See [`Ctx::pongs_expected`].
    expected: AtomicU32,
    stop: AtomicBool,
}

#[derive(Default)]
struct PingState {
    seq: u32,
    sent_at: Option<Instant>,
    seen: u32,
    timeouts: u32,
    warn_after: Option<Instant>,
}

impl<T: PerfSample> Ctx<T> {
    fn stopping(&self) -> bool {
        self.stop.load(Ordering::Relaxed) || shutdown::requested()
    }

    fn is_local(&self, guid: &[u8; 16]) -> bool {
        prefix_of(guid) == self.own_prefix
    }

    /// Pongs expected per ping, as last counted by [`count_pongs_expected`](Self::count_pongs_expected)
    /// (every 50 ms by the discovery loop): read per pong, where counting would read every pong writer's
    /// matched status.
    fn pongs_expected(&self) -> u32 {
        self.expected.load(Ordering::Relaxed)
    }

    /// Counts the pongs expected per ping (remote participants whose pong reader matched our pong writer for
    /// them) and keeps the count for [`pongs_expected`](Self::pongs_expected).
    fn count_pongs_expected(&self) -> u32 {
        let n = self.count_matched_pong_writers();
        self.expected.store(n, Ordering::Relaxed);
        n
    }

    fn count_matched_pong_writers(&self) -> u32 {
        let w = self.pong_writers.read().expect("pong writers");
        w.iter()
            .filter(|(_, w)| w.publication_matched_status().current_count > 0)
            .count() as u32
    }

    /// Writes `sample` with `stamp` on the pong writer for the participant of `guid`, if there is one, and
    /// flushes it (the writer is used in place: no clone of it per pong).
    fn pong(&self, guid: &[u8; 16], sample: &T, stamp: SystemTime) {
        let prefix = prefix_of(guid);
        let writers = self.pong_writers.read().expect("pong writers");
        if let Some((_, w)) = writers.iter().find(|(p, _)| *p == prefix) {
            let _ = w.write_w_timestamp(sample, stamp);
            w.flush();
        }
    }

    /// Creates pong writers for newly discovered participants (and ourselves with -L).
    fn refresh_pong_writers(&self) -> DdsResult<()> {
        let mut prefixes: Vec<[u8; 12]> = self
            .participant
            .discovered_participants()
            .into_iter()
            .map(|p| p.guid_prefix.0)
            .collect();
        if self.o.match_local {
            prefixes.push(self.own_prefix);
        }
        for prefix in prefixes {
            if prefix == self.own_prefix && !self.o.match_local {
                continue;
            }
            if self
                .pong_writers
                .read()
                .expect("pong writers")
                .iter()
                .any(|(p, _)| *p == prefix)
            {
                continue;
            }
            let publ = self.participant.create_publisher(
                &PublisherQos::builder()
                    .partition(Partition::new([guid_string(&prefix)]))
                    .build(),
            )?;
            let w = publ.create_datawriter(&self.pong_topic, &self.pingpong_qos)?;
            self.pong_writers
                .write()
                .expect("pong writers")
                .push((prefix, w));
        }
        Ok(())
    }

    /// Sends ping number `seq` (timestamp lsb set).
    fn send_ping(&self, seq: u32) {
        let mut s = T::make(seq, self.o.baggage);
        s.set_seq(seq);
        if let Err(e) = self.ping_writer.write_w_timestamp(&s, ts(now_ns() | 1)) {
            if !matches!(e, DdsError::Timeout) {
                println!("[{}] ping write failed: {e}", self.pid);
            }
        }
        self.ping_writer.flush();
    }
}

/// Like ddsperf (which sets it on its participant): our endpoints ignore each other, so the ping end's own
/// ping reader does not get every ping; `-L` matches them. `DDS_PERF_IGNORE_LOCAL=none` matches them too
/// without `-L`'s switch of the ping/pong readers to a waitset (to measure the difference).
fn ignore_local(o: &PerfOptions) -> IgnoreLocal {
    let none = std::env::var("DDS_PERF_IGNORE_LOCAL").is_ok_and(|v| v == "none");
    if o.match_local || none {
        IgnoreLocal::None
    } else {
        IgnoreLocal::Participant
    }
}

fn data_qos_reader(o: &PerfOptions) -> DataReaderQos {
    let mut q = DataReaderQos::builder()
        .ignore_local(ignore_local(o))
        .reliability(reliability(o))
        .history(if o.history_depth == 0 {
            History::KeepAll
        } else {
            History::KeepLast(o.history_depth)
        })
        .resource_limits(ResourceLimits {
            max_samples: Some(10_000),
            max_instances: None,
            max_samples_per_instance: None,
        });
    if !o.reliable {
        q = q.reliability(Reliability::BestEffort);
    }
    q.build()
}

fn data_qos_writer(o: &PerfOptions) -> DataWriterQos {
    DataWriterQos::builder()
        .ignore_local(ignore_local(o))
        .reliability(reliability(o))
        .history(if o.history_depth == 0 {
            History::KeepAll
        } else {
            History::KeepLast(o.history_depth)
        })
        .resource_limits(ResourceLimits {
            max_samples: Some(10_000),
            max_instances: None,
            max_samples_per_instance: None,
        })
        .build()
}

fn reliability(o: &PerfOptions) -> Reliability {
    if o.reliable {
        Reliability::Reliable {
            max_blocking_time: Duration::from_secs(10),
        }
    } else {
        Reliability::BestEffort
    }
}

fn run<T: PerfSample>(o: &PerfOptions) -> DdsResult<u8> {
    let pid = std::process::id();
    let has_reader = o.sub.is_some();
    let user_data = format!("DDSPerf:{}:{}:{}", u8::from(has_reader), pid, hostname()).into_bytes();
    let mut builder = DomainParticipant::builder().user_data(user_data);
    // Like ddsperf: a publisher packs its data samples into datagrams; pings and pongs are flushed at once.
    if o.pub_rate.is_some_and(|r| r > 0.0) && std::env::var_os("DDS_WRITE_BATCH").is_none() {
        builder = builder.write_batching(WriteBatching::Delay(
            dds_runtime::config::DEFAULT_WRITE_BATCH_DELAY,
        ));
    }
    if let Some(d) = o.domain_id {
        builder = builder.domain_id(d);
    }
    let participant = builder.build()?;
    let own_prefix = participant.guid_prefix().0;
    let rel = if o.reliable { 'R' } else { 'U' };
    let suffix = T::TOPIC.suffix();
    let tq = TopicQos::default();
    let data_topic = participant.create_topic::<T>(&format!("DDSPerf{rel}Data{suffix}"), &tq)?;
    let ping_topic = participant.create_topic::<T>(&format!("DDSPerf{rel}Ping{suffix}"), &tq)?;
    let pong_topic = participant.create_topic::<T>(&format!("DDSPerf{rel}Pong{suffix}"), &tq)?;

    let publ = participant.create_publisher(&PublisherQos::default())?;
    let subs = participant.create_subscriber(&SubscriberQos::default())?;
    let pingpong_w = DataWriterQos::builder()
        .ignore_local(ignore_local(o))
        .reliability(reliability(o))
        .history(History::KeepLast(1))
        .build();
    let pingpong_r = DataReaderQos::builder()
        .ignore_local(ignore_local(o))
        .reliability(reliability(o))
        .history(History::KeepLast(1))
        .build();
    let ping_reader = subs.create_datareader(&ping_topic, &pingpong_r)?;
    let ping_writer = publ.create_datawriter(&ping_topic, &pingpong_w)?;
    let data_reader = match o.sub {
        Some(_) => Some(subs.create_datareader(&data_topic, &data_qos_reader(o))?),
        None => None,
    };
    let data_writer = publ.create_datawriter(&data_topic, &data_qos_writer(o))?;
    // Pongs for us arrive in our own partition.
    let pong_sub = participant.create_subscriber(
        &SubscriberQos::builder()
            .partition(Partition::new([guid_string(&own_prefix)]))
            .build(),
    )?;
    let pong_reader = pong_sub.create_datareader(&pong_topic, &pingpong_r)?;

    let ctx = Arc::new(Ctx {
        o: o.clone(),
        pid,
        own_prefix,
        participant: participant.clone(),
        pong_topic,
        pingpong_qos: pingpong_w,
        pong_writers: RwLock::new(Vec::new()),
        batch: Mutex::new(Vec::new()),
        ping_writer,
        ping: Mutex::new(PingState::default()),
        pong_stats: Mutex::new(Vec::new()),
        sub_stats: Mutex::new(SubStats::new(o.nkeyvals)),
        sub_latency: Mutex::new(LatencyStat::new()),
        pub_hist: Mutex::new(WriteHist::default()),
        write_timeouts: AtomicU32::new(0),
        expected: AtomicU32::new(0),
        stop: AtomicBool::new(false),
    });
    ctx.refresh_pong_writers()?;

    let mut threads = Vec::new();
    {
        let c = ctx.clone();
        threads.push(thread::spawn(move || discovery_loop(&c)));
    }
    let pp = o.pingpong_trigger;
    let mut listened = vec![
        service_reader(&ctx, ping_reader, pp, answer_pings, &mut threads),
        service_reader(&ctx, pong_reader, pp, receive_pongs, &mut threads),
    ];
    if let (Some(r), Some(mode)) = (data_reader, o.sub) {
        listened.push(service_reader(&ctx, r, mode, receive_data, &mut threads));
    }
    if o.pub_rate.is_some_and(|r| r > 0.0) {
        let c = ctx.clone();
        let w = data_writer.clone();
        threads.push(thread::spawn(move || publisher(&c, &w)));
    }

    let code = main_loop(&ctx);
    ctx.stop.store(true, Ordering::SeqCst);
    for t in threads {
        let _ = t.join();
    }
    drop(listened);
    Ok(code)
}

/// Prints the per-second lines, drives the ping timer, and decides the exit status.
fn main_loop<T: PerfSample>(ctx: &Ctx<T>) -> u8 {
    let o = &ctx.o;
    let start = Instant::now();
    let stop_at = o.duration.map(|d| start + d);
    let mut next = start + Duration::from_secs(1);
    let mut last = start;
    let mut next_ping = match o.ping_interval {
        None => None,
        Some(d) if d.is_zero() => Some(start + Duration::from_secs(1)),
        Some(d) => Some(start + d),
    };
    while !ctx.stopping() {
        let now = Instant::now();
        if stop_at.is_some_and(|t| now >= t) {
            break;
        }
        if now >= next {
            print_stats(ctx, start, now, last);
            last = now;
            next = if now > next + Duration::from_millis(500) {
                now + Duration::from_secs(1)
            } else {
                next + Duration::from_secs(1)
            };
        }
        if let Some(np) = next_ping {
            if now >= np {
                next_ping = Some(ping_timer(ctx, now));
            }
        }
        let mut wake = next;
        if let Some(t) = stop_at {
            wake = wake.min(t);
        }
        if let Some(t) = next_ping {
            wake = wake.min(t);
        }
        thread::sleep(
            wake.saturating_duration_since(Instant::now())
                .min(Duration::from_millis(20)),
        );
    }
    ctx.stop.store(true, Ordering::SeqCst);

    let mut ok = true;
    let stats = ctx.sub_stats.lock().expect("sub stats");
    let lost = stats.total_lost();
    if lost > 0 && o.reliable && o.history_depth == 0 {
        println!("[{}] error: {lost} samples lost", ctx.pid);
        ok = false;
    }
    if o.min_samples > 0 && stats.min_received_per_writer() < o.min_samples {
        println!(
            "[{}] error: too few samples received from some peers",
            ctx.pid
        );
        ok = false;
    }
    drop(stats);
    if o.min_roundtrips > 0 {
        let ps = ctx.pong_stats.lock().expect("pong stats");
        if ps.is_empty() || ps.iter().any(|(_, s)| s.total < o.min_roundtrips) {
            println!("[{}] error: too few roundtrips for some peers", ctx.pid);
            ok = false;
        }
    }
    if o.min_match > 0 && ctx.count_pongs_expected() < o.min_match {
        println!(
            "[{}] error: too few matching participants ({})",
            ctx.pid,
            ctx.pongs_expected()
        );
        ok = false;
    }
    u8::from(!ok)
}

/// A new ping when the interval elapsed; in as-fast-as-possible mode a ping older than 1 s means a
/// lost ping or pong: count a timeout and start over.
fn ping_timer<T: PerfSample>(ctx: &Ctx<T>, now: Instant) -> Instant {
    let interval = ctx.o.ping_interval.unwrap_or(Duration::ZERO);
    let mut st = ctx.ping.lock().expect("ping state");
    if interval.is_zero() {
        if let Some(t) = st.sent_at {
            if now < t + Duration::from_secs(1) {
                return t + Duration::from_secs(1);
            }
        }
    }
    let expected = ctx.pongs_expected();
    if st.sent_at.is_some() && st.seen < expected {
        st.timeouts += 1;
        if st.warn_after.is_none_or(|w| now > w) {
            println!(
                "[{}] ping timed out (total {} times) ... sending new ping",
                ctx.pid, st.timeouts
            );
            st.warn_after = Some(now + Duration::from_secs(1));
        }
    }
    st.seen = 0;
    st.seq = st.seq.wrapping_add(1);
    st.sent_at = Some(now);
    let seq = st.seq;
    drop(st);
    ctx.send_ping(seq);
    if interval.is_zero() {
        now + Duration::from_secs(1)
    } else {
        now + interval
    }
}

fn print_stats<T: PerfSample>(ctx: &Ctx<T>, start: Instant, now: Instant, last: Instant) {
    let o = &ctx.o;
    let prefix = perf_stats::prefix(ctx.pid, (now - start).as_secs_f64());
    let dt = (now - last).as_nanos() as f64;
    if o.pub_rate.is_some_and(|r| r > 0.0) {
        println!(
            "{}",
            ctx.pub_hist
                .lock()
                .expect("pub hist")
                .take_line(&prefix, dt)
        );
    }
    if o.sub.is_some() {
        if let Some(l) = ctx.sub_stats.lock().expect("sub stats").second_line(
            &prefix,
            dt,
            o.substat_every_second,
        ) {
            println!("{l}");
        }
        if o.sublatency {
            if let Some(s) = ctx.sub_latency.lock().expect("sub latency").take_summary() {
                println!(
                    "{}",
                    perf_stats::latency_line(
                        &prefix,
                        " sublat",
                        "all",
                        T::TOPIC.payload_size(o.baggage),
                        &s
                    )
                );
            }
        }
    }
    let mut ps = ctx.pong_stats.lock().expect("pong stats");
    for (guid, stat) in ps.iter_mut() {
        if let Some(s) = stat.take_summary() {
            let peer: String = guid[..12].iter().map(|b| format!("{b:02x}")).collect();
            println!(
                "{}",
                perf_stats::latency_line(&prefix, "", &peer, T::TOPIC.payload_size(o.baggage), &s)
            );
        }
    }
}

fn discovery_loop<T: PerfSample>(ctx: &Ctx<T>) {
    while !ctx.stopping() {
        if let Err(e) = ctx.refresh_pong_writers() {
            println!("[{}] creating a pong writer failed: {e}", ctx.pid);
        }
        ctx.count_pongs_expected();
        thread::sleep(Duration::from_millis(50));
    }
}

/// Runs `handle` whenever `reader` has data, the way `mode` says: a listener on the receive thread, a
/// waiting thread, or a thread polling at 1 kHz. Threads are pushed onto `threads`; a reader served by a
/// listener is returned, for the caller to keep alive.
fn service_reader<T: PerfSample>(
    ctx: &Arc<Ctx<T>>,
    reader: DataReader<T>,
    mode: TriggerMode,
    handle: fn(&Ctx<T>, &DataReader<T>),
    threads: &mut Vec<thread::JoinHandle<()>>,
) -> Option<DataReader<T>> {
    match mode {
        TriggerMode::Listener => {
            reader.set_listener(Box::new(OnData {
                ctx: Arc::downgrade(ctx),
                handle,
            }));
            Some(reader)
        }
        TriggerMode::Waitset | TriggerMode::Polling => {
            let c = ctx.clone();
            threads.push(thread::spawn(move || {
                while !c.stopping() {
                    let ready = if mode == TriggerMode::Polling {
                        thread::sleep(Duration::from_millis(1));
                        true
                    } else {
                        reader
                            .wait_for_data(Duration::from_millis(100))
                            .unwrap_or(false)
                    };
                    if ready {
                        handle(&c, &reader);
                    }
                }
            }));
            None
        }
    }
}

/// A data-available listener calling a handler (weak: the readers live in the context).
struct OnData<T: PerfSample> {
    ctx: std::sync::Weak<Ctx<T>>,
    handle: fn(&Ctx<T>, &DataReader<T>),
}

impl<T: PerfSample> DataReaderListener<T> for OnData<T> {
    fn on_data_available(&self, reader: &DataReader<T>) {
        if let Some(c) = self.ctx.upgrade() {
            if !c.stopping() {
                (self.handle)(&c, reader);
            }
        }
    }
}

/// Answers pings: echo on the pinging participant's pong writer with the timestamp's lsb set.
fn answer_pings<T: PerfSample>(ctx: &Ctx<T>, reader: &DataReader<T>) {
    // A pong written from here may come back to this thread (-L): then the batch is in use.
    let mut kept = ctx.batch.try_lock().ok();
    let mut own = Vec::new();
    let samples = kept.as_deref_mut().unwrap_or(&mut own);
    if reader.take_into(samples).is_err() {
        return;
    }
    for s in samples.iter() {
        let Some(d) = &s.data else { continue };
        if ctx.is_local(&s.info.publication_guid.to_bytes()) && !ctx.o.match_local {
            continue;
        }
        let stamp = ts(ns_of(s.info.source_timestamp) | 1);
        ctx.pong(&s.info.publication_guid.to_bytes(), d, stamp);
    }
    // As ddsperf reuses its sample buffers: large samples are then decoded into warm memory.
    reader.recycle(samples.drain(..));
}

/// Receives pongs: half the round trip per answering writer; the next ping once all answered.
fn receive_pongs<T: PerfSample>(ctx: &Ctx<T>, reader: &DataReader<T>) {
    // A pong written from here may come back to this thread (-L): then the batch is in use.
    let mut kept = ctx.batch.try_lock().ok();
    let mut own = Vec::new();
    let samples = kept.as_deref_mut().unwrap_or(&mut own);
    if reader.take_into(samples).is_err() {
        return;
    }
    let now = now_ns();
    for s in samples.iter() {
        let Some(d) = &s.data else { continue };
        let sent = ns_of(s.info.source_timestamp);
        let isping = sent & 1 == 1;
        let half_rtt = (now - sent) / 2;
        {
            let mut ps = ctx.pong_stats.lock().expect("pong stats");
            let g = s.info.publication_guid.to_bytes();
            match ps.iter_mut().find(|(k, _)| *k == g) {
                Some((_, st)) => st.record(half_rtt),
                None => {
                    let mut st = LatencyStat::new();
                    st.record(half_rtt);
                    ps.push((g, st));
                }
            }
        }
        if !isping {
            continue;
        }
        let next = {
            let mut st = ctx.ping.lock().expect("ping state");
            if d.seq() != st.seq {
                None
            } else {
                st.seen += 1;
                let all = st.seen >= ctx.pongs_expected();
                if all && ctx.o.ping_interval == Some(Duration::ZERO) {
                    st.seen = 0;
                    st.seq = st.seq.wrapping_add(1);
                    st.sent_at = Some(Instant::now());
                    Some(st.seq)
                } else {
                    None
                }
            }
        };
        if let Some(seq) = next {
            ctx.send_ping(seq);
        }
    }
    reader.recycle(samples.drain(..));
}

/// `sub` mode: sequence checking per writer and key, optional latency, and pongs for pinged data.
fn receive_data<T: PerfSample>(ctx: &Ctx<T>, reader: &DataReader<T>) {
    // A take gives credit back to the core, which may deliver more and call the data-available listener
    // again on this thread, inside the take: that nested call returns at once (the loop below takes what
    // it would have), and the statistics lock, held across each take, keeps the batches of different
    // threads counted in the order they were taken.
    thread_local!(static INSIDE: std::cell::Cell<bool> = const { std::cell::Cell::new(false) });
    if INSIDE.with(|i| i.replace(true)) {
        return;
    }
    while receive_batch(ctx, reader) {}
    INSIDE.with(|i| i.set(false));
}

/// Takes and accounts up to 1000 samples; false when there were none.
fn receive_batch<T: PerfSample>(ctx: &Ctx<T>, reader: &DataReader<T>) -> bool {
    let mut stats = ctx.sub_stats.lock().expect("sub stats");
    let samples = match reader.select().max_samples(1000).take() {
        Ok(s) if !s.is_empty() => s,
        _ => return false,
    };
    for s in &samples {
        let Some(d) = &s.data else { continue };
        if ctx.is_local(&s.info.publication_guid.to_bytes()) && !ctx.o.match_local {
            continue;
        }
        if stats.record(
            s.info.publication_guid.to_bytes(),
            d.seq(),
            d.keyval(),
            d.size(),
        ) == SeqCheck::BadKey
        {
            println!("received key {} >= nkeys {}", d.keyval(), ctx.o.nkeyvals);
            shutdown::request();
        }
        if ctx.o.sublatency {
            ctx.sub_latency
                .lock()
                .expect("sub latency")
                .record(now_ns() - ns_of(s.info.source_timestamp));
        }
    }
    drop(stats);
    for s in &samples {
        let sent = ns_of(s.info.source_timestamp);
        if sent & 1 == 1 {
            if let Some(d) = &s.data {
                ctx.pong(&s.info.publication_guid.to_bytes(), d, ts(sent - 1));
            }
        }
    }
    reader.recycle(samples);
    true
}

/// `pub` mode: bursts at the requested rate, key values round robin, write durations in a histogram.
fn publisher<T: PerfSample>(ctx: &Ctx<T>, w: &DataWriter<T>) {
    let o = &ctx.o;
    let rate = o.pub_rate.unwrap_or(f64::INFINITY);
    let mut sample = T::make(0, o.baggage);
    let nkeys = o.nkeyvals.max(1);
    let mut keyval = 0u32;
    let mut ntot: u64 = 0;
    let mut batch = 0u32;
    let start = Instant::now();
    // A cheap xorshift for the ping fraction.
    let mut rnd: u64 = 0x9e37_79b9_7f4a_7c15 ^ u64::from(ctx.pid);
    while !ctx.stopping() {
        let want_pong = o.ping_fraction > 0.0 && {
            rnd ^= rnd << 13;
            rnd ^= rnd >> 7;
            rnd ^= rnd << 17;
            (rnd >> 11) as f64 / (1u64 << 53) as f64 <= o.ping_fraction
        };
        // One clock read for the timestamp and one after the write give the write's duration.
        let t0 = now_ns();
        let stamp = (t0 & !1) | i64::from(want_pong);
        match w.write_w_timestamp(&sample, ts(stamp)) {
            Ok(()) => {}
            Err(DdsError::Timeout) => {
                ctx.write_timeouts.fetch_add(1, Ordering::Relaxed);
                println!("write error: timeout");
                continue;
            }
            Err(e) => {
                println!("write error: {e}");
                shutdown::request();
                return;
            }
        }
        ctx.pub_hist
            .lock()
            .expect("pub hist")
            .record((now_ns() - t0).max(0) as u64);
        ntot += 1;
        sample.set_seq(sample.seq().wrapping_add(1));
        keyval = (keyval + 1) % nkeys;
        sample.set_keyval(keyval);
        if rate.is_finite() {
            batch += 1;
            if batch >= o.burst {
                batch = 0;
                w.flush();
                while !ctx.stopping()
                    && (ntot / u64::from(o.burst)) as f64 / (start.elapsed().as_secs_f64() + 5e-3)
                        > rate
                {
                    thread::sleep(Duration::from_millis(1));
                }
            }
        }
    }
}
