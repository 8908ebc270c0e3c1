//! Shared helpers of the `dcps_*` socket tests. They must run inside `scripts/isolated` (loopback only).
#![allow(dead_code)]

use std::time::{Duration, Instant};

use dds_runtime::prelude::*;

/// The shapes demo type (@appendable, keyed on color), as the OMG interop suite uses it.
#[derive(DdsType, Debug, Clone, PartialEq, Default)]
#[dds(name = "ShapeType", appendable)]
pub(crate) struct ShapeType {
    #[dds(key)]
    pub color: String,
    pub x: i32,
    pub y: i32,
    pub shapesize: i32,
}

pub(crate) fn shape(color: &str, x: i32) -> ShapeType {
    ShapeType {
        color: color.into(),
        x,
        y: 2 * x,
        shapesize: 30,
    }
}

/// A @final keyed type with a large unbounded member (fragmentation).
#[derive(DdsType, Debug, Clone, PartialEq, Default)]
#[dds(name = "test::Blob", final)]
pub(crate) struct Blob {
    #[dds(key)]
    pub id: u32,
    pub data: Vec<u8>,
}

/// Refuses to open sockets outside the private network namespace.
pub(crate) fn require_netns() {
    assert_eq!(
        std::env::var("DDS_IN_NETNS").as_deref(),
        Ok("1"),
        "socket tests must run inside scripts/isolated (loopback-only network namespace)"
    );
}

pub(crate) fn init_tracing() {
    let _ = tracing_subscriber::fmt()
        .with_env_filter(tracing_subscriber::EnvFilter::from_env("DDS_LOG"))
        .with_test_writer()
        .try_init();
}

/// A participant on `lo` in `domain`, with fast discovery.
pub(crate) fn participant(domain: u32) -> DomainParticipant {
    require_netns();
    init_tracing();
    DomainParticipant::builder()
        .domain_id(domain)
        .interface("lo")
        .spdp_interval(Duration::from_millis(200))
        .lease_duration(Duration::from_secs(5))
        .build()
        .expect("participant")
}

/// A participant with configuration `c` (environment ignored) on `domain`, with quick SPDP and a short lease.
pub(crate) fn participant_with(domain: u32, c: dds_runtime::config::Config) -> DomainParticipant {
    require_netns();
    init_tracing();
    DomainParticipant::builder()
        .config(dds_runtime::config::Config {
            domain_id: domain,
            spdp_interval: Duration::from_millis(200),
            lease_duration: Duration::from_secs(5),
            ..c
        })
        .build()
        .expect("participant")
}

/// Takes shapes from `r` until `n` have arrived or `timeout` passes; their x values in arrival order.
pub(crate) fn take_xs(r: &DataReader<ShapeType>, n: usize, timeout: Duration) -> Vec<i32> {
    let mut got = Vec::new();
    wait_until(timeout, || {
        got.extend(
            r.take()
                .unwrap()
                .into_iter()
                .filter_map(|s| s.data)
                .map(|d| d.x),
        );
        got.len() >= n
    });
    got
}

/// Polls `f` until it holds or `timeout` passes.
pub(crate) fn wait_until(timeout: Duration, mut f: impl FnMut() -> bool) -> bool {
    let end = Instant::now() + timeout;
    while Instant::now() < end {
        if f() {
            return true;
        }
        std::thread::sleep(Duration::from_millis(10));
    }
    f()
}

pub(crate) fn reliable() -> Reliability {
    Reliability::Reliable {
        max_blocking_time: Duration::from_secs(1),
    }
}

pub(crate) const MATCH_TIMEOUT: Duration = Duration::from_secs(10);

/// Reliable (max_blocking_time 1 s) KEEP_ALL QoS for a writer and for a reader.
pub(crate) fn reliable_keep_all() -> (DataWriterQos, DataReaderQos) {
    let wq = DataWriterQos::builder()
        .reliability(reliable())
        .history(History::KeepAll)
        .build();
    let rq = DataReaderQos::builder()
        .reliability(reliable())
        .history(History::KeepAll)
        .build();
    (wq, rq)
}

/// [`reliable_keep_all`], with a writer that blocks up to `max_blocking_time` when flow control or the
/// reader's resource limits hold it back (a test that writes far ahead of its reader).
pub(crate) fn reliable_keep_all_blocking(
    max_blocking_time: Duration,
) -> (DataWriterQos, DataReaderQos) {
    let (mut wq, rq) = reliable_keep_all();
    wq.reliability = Reliability::Reliable { max_blocking_time };
    (wq, rq)
}

/// A writer of `topic` on `p`, with default topic and publisher QoS.
pub(crate) fn writer<T: DdsType>(
    p: &DomainParticipant,
    topic: &str,
    wq: &DataWriterQos,
) -> DataWriter<T> {
    let t = p
        .create_topic::<T>(topic, &TopicQos::default())
        .expect("writer's topic");
    p.create_publisher(&PublisherQos::default())
        .and_then(|publ| publ.create_datawriter(&t, wq))
        .expect("datawriter")
}

/// A reader of `topic` on `p`, with default topic and subscriber QoS.
pub(crate) fn reader<T: DdsType>(
    p: &DomainParticipant,
    topic: &str,
    rq: &DataReaderQos,
) -> DataReader<T> {
    let t = p
        .create_topic::<T>(topic, &TopicQos::default())
        .expect("reader's topic");
    p.create_subscriber(&SubscriberQos::default())
        .and_then(|sub| sub.create_datareader(&t, rq))
        .expect("datareader")
}

/// A writer on `pw` and a reader on `pr` of `topic` (default topic, publisher and subscriber QoS), once
/// each has matched the other (within [`MATCH_TIMEOUT`]; panics otherwise).
pub(crate) fn matched<T: DdsType>(
    pw: &DomainParticipant,
    pr: &DomainParticipant,
    topic: &str,
    wq: &DataWriterQos,
    rq: &DataReaderQos,
) -> (DataWriter<T>, DataReader<T>) {
    let w = writer::<T>(pw, topic, wq);
    let r = reader::<T>(pr, topic, rq);
    assert!(
        wait_until(MATCH_TIMEOUT, || w.publication_matched_status().current_count == 1),
        "writer of {topic:?} did not match one reader within {MATCH_TIMEOUT:?}: {:?}, incompatible: {:?}",
        w.publication_matched_status(),
        w.offered_incompatible_qos_status()
    );
    assert!(
        wait_until(MATCH_TIMEOUT, || r.subscription_matched_status().current_count == 1),
        "reader of {topic:?} did not match one writer within {MATCH_TIMEOUT:?}: {:?}, incompatible: {:?}",
        r.subscription_matched_status(),
        r.requested_incompatible_qos_status()
    );
    (w, r)
}

/// Takes from `r` until `n` samples arrived (or [`MATCH_TIMEOUT`] passed); what arrived.
pub(crate) fn take_n(r: &DataReader<ShapeType>, n: usize) -> Vec<Sample<ShapeType>> {
    let mut got = Vec::new();
    wait_until(MATCH_TIMEOUT, || {
        got.extend(r.take().unwrap());
        got.len() >= n
    });
    got
}

/// What the Cyclone subscriber of `cyclone_shapes.py` printed, once it exited successfully: the `x` of each
/// RED sample in order, and whether it saw the instance disposed.
pub(crate) fn cyclone_sub_result(child: &mut std::process::Child) -> (Vec<i64>, bool, Vec<String>) {
    use std::io::{BufRead, BufReader};
    let out = BufReader::new(child.stdout.take().expect("piped stdout"));
    let lines: Vec<String> = out.lines().map_while(Result::ok).collect();
    assert!(
        child.wait().unwrap().success(),
        "cyclone sub failed: {lines:?}"
    );
    let xs = lines
        .iter()
        .filter(|l| l.contains("\"RED\""))
        .filter_map(|l| l.split("\"x\": ").nth(1)?.split(',').next()?.parse().ok())
        .collect();
    let disposed = lines.iter().any(|l| l.contains("\"disposed\": true"));
    (xs, disposed, lines)
}
