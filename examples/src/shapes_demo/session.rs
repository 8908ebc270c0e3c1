//! The demo's DDS entities: a publishing participant with one writer per topic, a subscribing participant with
//! one reader per topic (separate participants, so every sample crosses the stack's sockets), and the shapes
//! this process publishes. Both sides are created on first use.

use std::collections::HashMap;
use std::time::{Duration, Instant};

use dds_runtime::prelude::*;

use crate::shape_motion::Motion;
use crate::topic_types::ShapeType;

use super::origin::WriterId;

/// What the session is set up with.
#[derive(Debug, Clone)]
pub struct SessionConfig {
    /// DDS domain of both participants.
    pub domain: u32,
    /// Writes XCDR2 instead of XCDR1 (readers accept both).
    pub xcdr2: bool,
    /// Samples per second of every published shape.
    pub rate_hz: f64,
}

/// One shape this process publishes.
#[derive(Debug, Clone)]
pub struct Publication {
    /// Its topic.
    pub topic: String,
    /// Its current sample (`color` is the instance key).
    pub shape: ShapeType,
    motion: Motion,
}

/// What a reader delivered.
#[derive(Debug, Clone)]
pub struct Received {
    /// The topic it came on.
    pub topic: String,
    /// The writer that sent it.
    pub writer: WriterId,
    /// Data or the end of an instance.
    pub event: ReceivedEvent,
}

/// The content of a [`Received`].
#[derive(Debug, Clone)]
pub enum ReceivedEvent {
    /// A new position, with the time from its source timestamp to its reception.
    Data {
        /// The sample.
        shape: ShapeType,
        /// Source timestamp to reception.
        latency: Duration,
    },
    /// The instance of this colour was disposed or lost its writers.
    Gone {
        /// The instance's key.
        color: String,
    },
}

/// Matching state of one topic, for display.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct TopicStatus {
    /// Topic name.
    pub name: String,
    /// Writers matched by our reader (`None`: not subscribed).
    pub matched_writers: Option<usize>,
    /// Readers matched by our writer (`None`: not publishing).
    pub matched_readers: Option<usize>,
}

struct PubSide {
    participant: DomainParticipant,
    publisher: Publisher,
    writers: Vec<(String, DataWriter<ShapeType>)>,
}

struct SubSide {
    participant: DomainParticipant,
    subscriber: Subscriber,
    readers: Vec<(String, DataReader<ShapeType>)>,
    /// The colour of each instance seen with data, to name it when it goes away.
    colors: HashMap<(usize, InstanceHandle), String>,
}

/// The demo's participants, writers, readers and published shapes.
pub struct Session {
    cfg: SessionConfig,
    pub_side: Option<PubSide>,
    sub_side: Option<SubSide>,
    publications: Vec<Publication>,
    next_write: Instant,
    written: u64,
}

impl Session {
    /// A session with no entities yet.
    pub fn new(cfg: SessionConfig) -> Self {
        Session {
            cfg,
            pub_side: None,
            sub_side: None,
            publications: Vec::new(),
            next_write: Instant::now(),
            written: 0,
        }
    }

    /// Time between two writes of a shape.
    pub fn period(&self) -> Duration {
        Duration::from_secs_f64(1.0 / self.cfg.rate_hz)
    }

    /// Samples per second of each published shape.
    pub fn rate_hz(&self) -> f64 {
        self.cfg.rate_hz
    }

    /// When the next round of writes is due.
    pub fn next_write(&self) -> Instant {
        self.next_write
    }

    /// Samples written so far.
    pub fn written(&self) -> u64 {
        self.written
    }

    /// The shapes this process publishes.
    pub fn publications(&self) -> &[Publication] {
        &self.publications
    }

    /// The topics with a reader, in subscription order.
    pub fn subscribed_topics(&self) -> Vec<&str> {
        self.sub_side
            .iter()
            .flat_map(|s| s.readers.iter().map(|(t, _)| t.as_str()))
            .collect()
    }

    /// Whether a topic has a reader.
    pub fn is_subscribed(&self, topic: &str) -> bool {
        self.subscribed_topics().contains(&topic)
    }

    /// Whether `writer` belongs to this session's publishing participant.
    pub fn is_ours(&self, writer: &WriterId) -> bool {
        self.pub_side
            .as_ref()
            .is_some_and(|p| writer.prefix() == p.participant.guid_prefix().0)
    }

    /// Creates a reader on `topic` (nothing when there is one already).
    pub fn subscribe(&mut self, topic: &str) -> DdsResult<()> {
        if self.is_subscribed(topic) {
            return Ok(());
        }
        let side = match &mut self.sub_side {
            Some(s) => s,
            None => {
                let participant = new_participant(self.cfg.domain)?;
                let subscriber = participant.create_subscriber(&SubscriberQos::default())?;
                self.sub_side.insert(SubSide {
                    participant,
                    subscriber,
                    readers: Vec::new(),
                    colors: HashMap::new(),
                })
            }
        };
        let t = side
            .participant
            .create_topic::<ShapeType>(topic, &TopicQos::default())?;
        let reader = side.subscriber.create_datareader(&t, &reader_qos())?;
        side.readers.push((topic.to_string(), reader));
        Ok(())
    }

    /// Starts publishing a shape of `color` on `topic`, the `index`-th shape of the run (it sets the start
    /// position and velocity, so that shapes do not move in lockstep).
    pub fn publish(&mut self, topic: &str, color: &str, index: usize) -> DdsResult<()> {
        self.ensure_writer(topic)?;
        // The pattern repeats; the modulo keeps the arithmetic small for any index.
        let i = (index % 1000) as i32;
        self.publications.push(Publication {
            topic: topic.to_string(),
            shape: ShapeType {
                color: color.into(),
                x: 20 + 37 * i % 200,
                y: 30 + 53 * i % 230,
                shapesize: 30,
                ..Default::default()
            },
            motion: Motion {
                dx: 3 + i % 3,
                dy: 2 + (i + 1) % 4,
            },
        });
        Ok(())
    }

    /// When a round of writes is due at `now`: moves every published shape one step and writes it; returns
    /// the shapes written. A write that flow control times out is skipped.
    pub fn tick(&mut self, now: Instant) -> DdsResult<Vec<Publication>> {
        if now < self.next_write {
            return Ok(Vec::new());
        }
        self.next_write += self.period();
        let Some(side) = &self.pub_side else {
            return Ok(Vec::new());
        };
        let mut out = Vec::with_capacity(self.publications.len());
        for p in &mut self.publications {
            p.motion.step(&mut p.shape);
            let Some((_, w)) = side.writers.iter().find(|(t, _)| *t == p.topic) else {
                continue;
            };
            match w.write(&p.shape) {
                Ok(()) => self.written += 1,
                Err(DdsError::Timeout) => {}
                Err(e) => return Err(e),
            }
            out.push(p.clone());
        }
        Ok(out)
    }

    /// Skips the writes due until `now` (pausing): the next round is one period after `now`.
    pub fn hold(&mut self, now: Instant) {
        self.next_write = now + self.period();
    }

    /// Waits up to `wait` for data on the first reader (or just sleeps without one).
    pub fn wait_for_data(&self, wait: Duration) -> DdsResult<()> {
        match self.sub_side.as_ref().and_then(|s| s.readers.first()) {
            Some((_, r)) => r.wait_for_data(wait).map(|_| ()),
            None => {
                std::thread::sleep(wait);
                Ok(())
            }
        }
    }

    /// Takes what every reader holds, without waiting.
    pub fn receive(&mut self) -> DdsResult<Vec<Received>> {
        let Some(side) = &mut self.sub_side else {
            return Ok(Vec::new());
        };
        let mut out = Vec::new();
        for (i, (topic, r)) in side.readers.iter().enumerate() {
            for s in r.take()? {
                let writer = WriterId(s.info.publication_guid.to_bytes());
                let handle = s.info.instance_handle;
                if let Some(shape) = s.data {
                    // Measured to the reception, not to this take: the window takes once per frame.
                    let latency = s
                        .info
                        .reception_timestamp
                        .duration_since(s.info.source_timestamp)
                        .unwrap_or_default();
                    side.colors.insert((i, handle), shape.color.clone());
                    let event = ReceivedEvent::Data { shape, latency };
                    out.push(Received {
                        topic: topic.clone(),
                        writer,
                        event,
                    });
                } else if s.info.instance_state != InstanceState::Alive {
                    let color = side.colors.remove(&(i, handle)).unwrap_or_default();
                    let event = ReceivedEvent::Gone { color };
                    out.push(Received {
                        topic: topic.clone(),
                        writer,
                        event,
                    });
                }
            }
        }
        Ok(out)
    }

    /// Matching state of every topic we read or write, readers' topics first.
    pub fn topic_status(&self) -> Vec<TopicStatus> {
        let mut names: Vec<String> = self
            .subscribed_topics()
            .iter()
            .map(|t| t.to_string())
            .collect();
        for (t, _) in self.pub_side.iter().flat_map(|p| &p.writers) {
            if !names.contains(t) {
                names.push(t.clone());
            }
        }
        names
            .into_iter()
            .map(|name| {
                let reader = self
                    .sub_side
                    .as_ref()
                    .and_then(|s| s.readers.iter().find(|(t, _)| *t == name));
                let writer = self
                    .pub_side
                    .as_ref()
                    .and_then(|p| p.writers.iter().find(|(t, _)| *t == name));
                TopicStatus {
                    matched_writers: reader.map(|(_, r)| r.matched_publications().len()),
                    matched_readers: writer.map(|(_, w)| w.matched_subscriptions().len()),
                    name,
                }
            })
            .collect()
    }

    /// Waits (up to 1 s) until the matched readers acknowledged what was written.
    pub fn flush(&self) {
        for (_, w) in self.pub_side.iter().flat_map(|p| &p.writers) {
            let _ = w.wait_for_acknowledgments(Duration::from_secs(1));
        }
    }

    /// Creates the writer of `topic` (with the publishing participant) when missing.
    fn ensure_writer(&mut self, topic: &str) -> DdsResult<()> {
        if self.pub_side.is_none() {
            let participant = new_participant(self.cfg.domain)?;
            let publisher = participant.create_publisher(&PublisherQos::default())?;
            self.pub_side = Some(PubSide {
                participant,
                publisher,
                writers: Vec::new(),
            });
        }
        let Some(side) = &mut self.pub_side else {
            return Ok(());
        };
        if side.writers.iter().any(|(t, _)| t == topic) {
            return Ok(());
        }
        let t = side
            .participant
            .create_topic::<ShapeType>(topic, &TopicQos::default())?;
        let w = side
            .publisher
            .create_datawriter(&t, &writer_qos(self.cfg.xcdr2))?;
        side.writers.push((topic.to_string(), w));
        Ok(())
    }
}

fn new_participant(domain: u32) -> DdsResult<DomainParticipant> {
    DomainParticipant::builder().domain_id(domain).build()
}

/// Reliable, keep-last-1, XCDR1 unless asked for XCDR2 (as shape_main's `-x`).
fn writer_qos(xcdr2: bool) -> DataWriterQos {
    DataWriterQos::builder()
        .reliability(Reliability::RELIABLE)
        .history(History::KeepLast(1))
        .data_representation(if xcdr2 {
            DataRepresentation::xcdr2()
        } else {
            DataRepresentation::xcdr1()
        })
        .build()
}

/// Reliable, keep-last-8, accepting XCDR1 and XCDR2.
fn reader_qos() -> DataReaderQos {
    let both = DataRepresentation::accept_both();
    DataReaderQos::builder()
        .reliability(Reliability::RELIABLE)
        .history(History::KeepLast(8))
        .data_representation(both)
        .build()
}
