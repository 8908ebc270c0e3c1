//! A deterministic network simulator for the sans-I/O core: a clock we advance, a queue of datagrams with
//! seeded loss, duplication and reordering (random delay), and several participants wired through it.
#![allow(dead_code)]

use std::cmp::Reverse;
use std::collections::BinaryHeap;
use std::time::{Duration, Instant};

use dds_runtime::rtps::*;

/// xorshift64*: small, seeded, deterministic.
#[derive(Debug, Clone)]
pub(crate) struct Rng(u64);

impl Rng {
    pub(crate) fn new(seed: u64) -> Self {
        Rng(seed.wrapping_mul(0x9e37_79b9_7f4a_7c15) | 1)
    }
    pub(crate) fn next_u64(&mut self) -> u64 {
        let mut x = self.0;
        x ^= x >> 12;
        x ^= x << 25;
        x ^= x >> 27;
        self.0 = x;
        x.wrapping_mul(0x2545_f491_4f6c_dd1d)
    }
    /// Uniform in [0, 1).
    pub(crate) fn unit(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }
    pub(crate) fn below(&mut self, n: u64) -> u64 {
        self.next_u64() % n.max(1)
    }
}

#[derive(Debug, Clone, Copy)]
pub(crate) struct Faults {
    pub(crate) loss: f64,
    pub(crate) duplicate: f64,
    /// Each datagram gets a delay uniform in [latency, latency + jitter]: jitter reorders.
    pub(crate) latency: Duration,
    pub(crate) jitter: Duration,
}

impl Faults {
    pub(crate) const NONE: Faults = Faults {
        loss: 0.0,
        duplicate: 0.0,
        latency: Duration::from_micros(100),
        jitter: Duration::ZERO,
    };
    pub(crate) fn lossy(loss: f64) -> Faults {
        Faults {
            loss,
            duplicate: 0.1,
            latency: Duration::from_micros(100),
            jitter: Duration::from_millis(2),
        }
    }
}

pub(crate) struct Node {
    pub(crate) p: Participant,
    pub(crate) events: Vec<Event>,
    /// Whether this node is connected: false = it neither receives nor gets anything out (crashed or cut off).
    pub(crate) up: bool,
}

#[derive(PartialEq, Eq, PartialOrd, Ord)]
struct InFlight {
    at: Instant,
    seq: u64,
    to: usize,
    payload: Vec<u8>,
}

pub(crate) struct Sim {
    pub(crate) start: Instant,
    pub(crate) now: Instant,
    pub(crate) nodes: Vec<Node>,
    pub(crate) rng: Rng,
    pub(crate) faults: Faults,
    queue: BinaryHeap<Reverse<InFlight>>,
    seq: u64,
    pub(crate) datagrams_sent: u64,
    /// Faults apply only to user traffic when set (discovery then completes quickly).
    pub(crate) faults_on_discovery: bool,
    /// When `Some`, every datagram sent is logged here.
    pub(crate) trace: Option<Vec<Sent>>,
    /// When `Some((node, d))`, the next user datagram that node sends arrives `d` late (once): a datagram
    /// overtaken by those sent after it.
    pub(crate) delay_next_user: Option<(usize, Duration)>,
}

/// A datagram as sent: (sending node, destinations, payload).
pub(crate) type Sent = (usize, Vec<Locator>, Vec<u8>);

pub(crate) fn prefix(i: usize) -> GuidPrefix {
    let mut p = [0u8; 12];
    p[0] = 0xaa;
    p[11] = i as u8 + 1;
    GuidPrefix(p)
}

pub(crate) fn config(i: usize) -> ParticipantConfigBuilder {
    ParticipantConfig::builder(0, 0, prefix(i), [10, 0, 0, i as u8 + 1])
        .unwrap()
        .spdp_interval(Duration::from_millis(500))
        .lease_duration(Duration::from_secs(3))
}

impl Sim {
    pub(crate) fn new(seed: u64, faults: Faults) -> Self {
        let start = Instant::now();
        Sim {
            start,
            now: start,
            nodes: Vec::new(),
            rng: Rng::new(seed),
            faults,
            queue: BinaryHeap::new(),
            seq: 0,
            datagrams_sent: 0,
            faults_on_discovery: true,
            trace: None,
            delay_next_user: None,
        }
    }

    pub(crate) fn add(&mut self, config: impl Into<ParticipantConfig>) -> usize {
        let mut p = Participant::new(config.into(), self.now);
        // As the DCPS driver does: large fragments travel as shares of the sample, not copies.
        p.gather_sends(Some(2048));
        self.nodes.push(Node {
            p,
            events: Vec::new(),
            up: true,
        });
        self.nodes.len() - 1
    }

    pub(crate) fn with_participants(seed: u64, faults: Faults, n: usize) -> Self {
        let mut s = Sim::new(seed, faults);
        for i in 0..n {
            s.add(config(i));
        }
        s
    }

    fn receivers(&self, l: &Locator) -> Vec<usize> {
        self.nodes
            .iter()
            .enumerate()
            .filter(|(_, n)| {
                let c = n.p.config();
                if l.is_multicast() {
                    c.metatraffic_multicast().contains(l) || c.default_multicast().contains(l)
                } else {
                    c.metatraffic_unicast().contains(l) || c.default_unicast().contains(l)
                }
            })
            .map(|(i, _)| i)
            .collect()
    }

    /// Moves every pending transmit into the network and every event into the nodes' logs.
    pub(crate) fn pump(&mut self) {
        for i in 0..self.nodes.len() {
            while let Some(t) = self.nodes[i].p.poll_transmit(self.now) {
                self.datagrams_sent += 1;
                let mut targets: Vec<usize> = t
                    .destinations
                    .iter()
                    .flat_map(|l| self.receivers(l))
                    .collect();
                targets.sort();
                targets.dedup();
                let bytes = t.datagram().into_owned();
                let user = is_user_traffic(&bytes);
                if let Some(log) = &mut self.trace {
                    log.push((i, t.destinations.clone(), bytes.clone()));
                }
                if !self.nodes[i].up {
                    targets.clear();
                }
                let late = match self.delay_next_user {
                    Some((from, d)) if from == i && user => {
                        self.delay_next_user = None;
                        d
                    }
                    _ => Duration::ZERO,
                };
                for to in targets {
                    let f = if user || self.faults_on_discovery {
                        self.faults
                    } else {
                        Faults::NONE
                    };
                    if self.rng.unit() < f.loss {
                        continue;
                    }
                    let copies = if self.rng.unit() < f.duplicate { 2 } else { 1 };
                    for _ in 0..copies {
                        let jitter = if f.jitter.is_zero() {
                            0
                        } else {
                            self.rng.below(f.jitter.as_nanos() as u64)
                        };
                        let at = self.now + f.latency + late + Duration::from_nanos(jitter);
                        self.seq += 1;
                        self.queue.push(Reverse(InFlight {
                            at,
                            seq: self.seq,
                            to,
                            payload: bytes.clone(),
                        }));
                    }
                }
                self.nodes[i].p.recycle_transmit(t);
            }
            while let Some(e) = self.nodes[i].p.poll_event() {
                self.nodes[i].events.push(e);
            }
        }
    }

    /// Advances to the next datagram or timeout; returns false when nothing is scheduled.
    pub(crate) fn step(&mut self) -> bool {
        self.step_until(None)
    }

    /// Like `step`, but never moves the clock past `cap`.
    pub(crate) fn step_until(&mut self, cap: Option<Instant>) -> bool {
        self.pump();
        let next_dgram = self.queue.peek().map(|r| r.0.at);
        let next_timer = self.nodes.iter().filter_map(|n| n.p.poll_timeout()).min();
        let next = match (next_dgram, next_timer) {
            (Some(a), Some(b)) => a.min(b),
            (a, b) => match a.or(b) {
                Some(x) => x,
                None => return false,
            },
        };
        let next = cap.map_or(next, |c| next.min(c));
        if next > self.now {
            self.now = next;
        }
        while let Some(r) = self.queue.peek() {
            if r.0.at > self.now {
                break;
            }
            let Reverse(d) = self.queue.pop().unwrap();
            if self.nodes[d.to].up {
                self.nodes[d.to].p.handle_datagram(self.now, &d.payload);
            }
        }
        for n in &mut self.nodes {
            if n.p.poll_timeout().is_some_and(|t| t <= self.now) {
                n.p.handle_timeout(self.now);
            }
        }
        self.pump();
        true
    }

    /// Runs until `cond` holds or `limit` of simulated time passes; returns whether `cond` held.
    pub(crate) fn run_until(
        &mut self,
        limit: Duration,
        mut cond: impl FnMut(&mut Sim) -> bool,
    ) -> bool {
        let end = self.now + limit;
        loop {
            self.pump();
            if cond(self) {
                return true;
            }
            if self.now >= end || !self.step_until(Some(end)) {
                return cond(self);
            }
        }
    }

    pub(crate) fn run_for(&mut self, d: Duration) {
        let end = self.now + d;
        self.run_until(d, |s| s.now >= end);
    }

    /// Two participants (without faults on discovery) with an unkeyed writer of "T" on node 0 and a reader on
    /// node 1, once each has matched the other (panics after 5 simulated seconds).
    pub(crate) fn writer_and_reader(
        seed: u64,
        faults: Faults,
        wq: dds_runtime::qos::DataWriterQos,
        rq: dds_runtime::qos::DataReaderQos,
    ) -> (Sim, EntityId, EntityId) {
        let mut sim = Sim::with_participants(seed, faults, 2);
        let (w, r) = sim.matched_pair(wq, rq);
        (sim, w, r)
    }

    /// An unkeyed writer of "T" on node 0 and a reader on node 1, once each has matched the other (without
    /// faults on discovery from then on; panics after 5 simulated seconds).
    pub(crate) fn matched_pair(
        &mut self,
        wq: dds_runtime::qos::DataWriterQos,
        rq: dds_runtime::qos::DataReaderQos,
    ) -> (EntityId, EntityId) {
        self.faults_on_discovery = false;
        let now = self.now;
        let w = self.nodes[0]
            .p
            .create_writer(now, WriterSpec::new("T", "M::T", false, wq))
            .unwrap();
        let r = self.nodes[1]
            .p
            .create_reader(now, ReaderSpec::new("T", "M::T", false, rq))
            .unwrap();
        assert!(self.run_until(Duration::from_secs(5), |s| !s.nodes[0]
            .p
            .writer_matches(w)
            .is_empty()
            && !s.nodes[1].p.reader_matches(r).is_empty()));
        (w, r)
    }

    pub(crate) fn elapsed(&self) -> Duration {
        self.now - self.start
    }

    pub(crate) fn guid(&self, node: usize, id: EntityId) -> Guid {
        Guid::new(self.nodes[node].p.guid_prefix(), id)
    }

    /// Takes the samples delivered to `reader` at `node` so far.
    pub(crate) fn take_samples(&mut self, node: usize, reader: EntityId) -> Vec<ReceivedSample> {
        let mut out = Vec::new();
        self.nodes[node].events.retain(|e| match e {
            Event::Sample(s) if s.reader == reader => {
                out.push(s.clone());
                false
            }
            _ => true,
        });
        out
    }

    pub(crate) fn has_event(&self, node: usize, f: impl Fn(&Event) -> bool) -> bool {
        self.nodes[node].events.iter().any(f)
    }
}

/// User traffic: a message that carries a submessage from/to a user entity. Checked crudely by scanning the
/// entity ids in DATA/HEARTBEAT/ACKNACK/GAP submessages' fixed positions is overkill; instead we treat messages
/// whose every writer/reader id is builtin as discovery.
fn is_user_traffic(msg: &[u8]) -> bool {
    use dds_runtime::rtps::messages::{MessageIter, Submessage};
    let Ok((_, it)) = MessageIter::parse(msg) else {
        return true;
    };
    for s in it.flatten() {
        let ids = match s {
            Submessage::Data(d) => [d.reader_id, d.writer_id],
            Submessage::DataFrag(d) => [d.reader_id, d.writer_id],
            Submessage::Heartbeat(h) => [h.reader_id, h.writer_id],
            Submessage::AckNack(a) => [a.reader_id, a.writer_id],
            Submessage::Gap(g) => [g.reader_id, g.writer_id],
            Submessage::NackFrag(n) => [n.reader_id, n.writer_id],
            Submessage::HeartbeatFrag(h) => [h.reader_id, h.writer_id],
            _ => continue,
        };
        if ids
            .iter()
            .any(|e| *e != EntityId::UNKNOWN && !e.is_builtin())
        {
            return true;
        }
    }
    false
}

/// A payload holding index `i` (a little-endian CDR encapsulation header first), for tests that track
/// which change arrived.
pub(crate) fn indexed_payload(i: u32) -> Vec<u8> {
    let mut v = vec![0, 1, 0, 0];
    v.extend_from_slice(&i.to_le_bytes());
    v
}

/// The index an [`indexed_payload`] holds.
pub(crate) fn payload_index(p: &[u8]) -> u32 {
    u32::from_le_bytes([p[4], p[5], p[6], p[7]])
}

/// Calls `f` (a write, an end of a coherent set) until flow control stops refusing it, running the network
/// between attempts; panics on any other error.
pub(crate) fn until_accepted<T>(
    sim: &mut Sim,
    mut f: impl FnMut(&mut Sim) -> Result<T, WriteError>,
) -> T {
    loop {
        match f(sim) {
            Ok(v) => return v,
            Err(WriteError::WouldBlock) => {
                sim.step();
            }
            Err(e) => panic!("{e}"),
        }
    }
}

/// Writes [`indexed_payload`]`(i)` with node 0's writer `w`, waiting out flow control.
pub(crate) fn write_indexed(sim: &mut Sim, w: EntityId, i: u32) {
    until_accepted(sim, |sim| {
        let now = sim.now;
        sim.nodes[0]
            .p
            .write(now, w, WriteChange::alive(indexed_payload(i)))
    });
}

/// Ends node 0's writer `w`'s coherent set, waiting out flow control.
pub(crate) fn end_coherent(sim: &mut Sim, w: EntityId) {
    until_accepted(sim, |sim| {
        let now = sim.now;
        sim.nodes[0].p.end_coherent_set(now, w)
    });
}

/// KEEP_ALL writer and reader QoS, the reader reliable or best effort.
pub(crate) fn keep_all_qos(
    reliable: bool,
) -> (
    dds_runtime::qos::DataWriterQos,
    dds_runtime::qos::DataReaderQos,
) {
    use dds_runtime::qos::*;
    let wq = DataWriterQos::builder().history(History::KeepAll).build();
    let rel = if reliable {
        Reliability::RELIABLE
    } else {
        Reliability::BestEffort
    };
    let rq = DataReaderQos::builder()
        .reliability(rel)
        .history(History::KeepAll)
        .build();
    (wq, rq)
}
