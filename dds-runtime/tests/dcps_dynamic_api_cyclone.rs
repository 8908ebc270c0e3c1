//! The dynamic writer's instance, liveliness and QoS operations, and the dynamic endpoints' statuses going
//! up to their publisher's, subscriber's and participant's listeners, against Cyclone DDS 11 peers (python
//! `cyclonedds`, `dcps_util/cyclone_dynapi.py`).
//! Ignored by default (needs python3 + cyclonedds); the nextest profile `interop` runs it, or
//! `scripts/isolated cargo nextest run -p dds-runtime --features idl --test dcps_dynamic_api_cyclone
//! --run-ignored ignored-only`. Domains 38 and 39.
mod dcps_util;

use std::io::{BufRead, BufReader};
use std::process::{Child, ChildStdin, Command, Stdio};
use std::sync::mpsc::{channel, Receiver};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use dcps_util::*;
use dds_runtime::prelude::*;
use dds_runtime::xtypes::dynamic::{types_from_idl, DynamicData, DynamicType, Value};

const CYCLONE_URI: &str = r#"<CycloneDDS><Domain id="any"><General><Interfaces><NetworkInterface name="lo" multicast="true"/></Interfaces><AllowMulticast>true</AllowMulticast></General></Domain></CycloneDDS>"#;

/// A `cyclone_dynapi.py` process: its stdout lines as they come; it exits when its stdin closes.
struct Peer {
    child: Child,
    stdin: Option<ChildStdin>,
    lines: Receiver<String>,
    seen: Vec<String>,
    /// Lines before this index were matched by `expect` already.
    cursor: usize,
}

impl Peer {
    fn spawn(domain: u32, args: &[&str]) -> Peer {
        let script = concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/tests/dcps_util/cyclone_dynapi.py"
        );
        let mut child = Command::new("python3")
            .arg(script)
            .args(args)
            .env("CYCLONEDDS_URI", CYCLONE_URI)
            .env("DDS_DOMAIN_ID", domain.to_string())
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .stderr(Stdio::inherit())
            .spawn()
            .expect("python3 with cyclonedds");
        let out = BufReader::new(child.stdout.take().unwrap());
        let (tx, lines) = channel();
        std::thread::spawn(move || {
            for l in out.lines().map_while(Result::ok) {
                if tx.send(l).is_err() {
                    break;
                }
            }
        });
        let stdin = child.stdin.take();
        Peer {
            child,
            stdin,
            lines,
            seen: Vec::new(),
            cursor: 0,
        }
    }

    /// Receives what the peer printed within `wait`.
    fn pump(&mut self, wait: Duration) {
        if let Ok(l) = self.lines.recv_timeout(wait) {
            self.seen.push(l);
        }
        while let Ok(l) = self.lines.try_recv() {
            self.seen.push(l);
        }
    }

    /// Waits up to 20 s for a line equal to `line` after the last one `expect` found; panics without.
    fn expect(&mut self, line: &str) {
        let end = Instant::now() + Duration::from_secs(20);
        loop {
            if let Some(i) = self.seen[self.cursor..].iter().position(|l| l == line) {
                self.cursor += i + 1;
                return;
            }
            assert!(
                Instant::now() < end,
                "no `{line}` from the Cyclone peer; it printed {:?}",
                self.seen
            );
            self.pump(Duration::from_millis(100));
        }
    }

    /// Waits up to 20 s for all of `lines`, in any order, after the last line `expect` found.
    fn expect_all(&mut self, lines: &[&str]) {
        let end = Instant::now() + Duration::from_secs(20);
        loop {
            let rest = &self.seen[self.cursor..];
            let found: Option<Vec<usize>> = lines
                .iter()
                .map(|l| rest.iter().position(|r| r == l))
                .collect();
            if let Some(at) = found {
                self.cursor += at.into_iter().max().map_or(0, |i| i + 1);
                return;
            }
            assert!(
                Instant::now() < end,
                "not all of {lines:?} from the Cyclone peer; it printed {:?}",
                self.seen
            );
            self.pump(Duration::from_millis(100));
        }
    }

    /// Whether the peer printed `line` (so far).
    fn printed(&mut self, line: &str) -> bool {
        self.pump(Duration::ZERO);
        self.seen.iter().any(|l| l == line)
    }
}

impl Drop for Peer {
    fn drop(&mut self) {
        drop(self.stdin.take()); // the peer exits when its stdin closes
        let _ = self.child.wait();
    }
}

fn beat_type() -> DynamicType {
    types_from_idl(
        "b.idl",
        "module xs { @final struct Beat { @key long id; long n; }; };",
    )
    .unwrap()
    .remove("xs::Beat")
    .unwrap()
}

fn beat(ty: &DynamicType, id: i32, n: i32) -> DynamicData {
    let mut d = DynamicData::new(ty.clone());
    d.set("id", Value::Int32(id)).unwrap();
    d.set("n", Value::Int32(n)).unwrap();
    d
}

/// A dynamic writer's instance operations, liveliness and QoS changes as a Cyclone 11 reader sees them:
/// - register and look up instances; dispose and unregister (autodispose off) by value and by handle
///   give the Cyclone reader NOT_ALIVE_DISPOSED and NOT_ALIVE_NO_WRITERS instances;
/// - with MANUAL_BY_TOPIC liveliness (1 s lease), `assert_liveliness` alone keeps the writer alive for
///   Cyclone for 2.5 leases, and the writer is lost once it stops asserting;
/// - `set_qos` refuses an immutable change (RELIABILITY); it applies a 300 ms deadline, which the writer
///   then misses once it stops writing, and an ownership strength, which the Cyclone reader sees in the
///   writer's SEDP update;
/// - deleting the writer unregisters its live instances.
#[test]
#[ignore = "needs python3 with cyclonedds; run explicitly"]
fn dynamic_writer_operations_seen_by_a_cyclone_reader() {
    require_netns();
    let ty = beat_type();
    let p = participant(38);
    let t = p
        .create_dynamic_topic("BeatTopic", ty.clone(), &TopicQos::default())
        .unwrap();
    let qos = DataWriterQos::builder()
        .reliability(reliable())
        .history(History::KeepLast(8))
        .liveliness(Liveliness {
            kind: LivelinessKind::ManualByTopic,
            lease_duration: Duration::from_secs(1),
        })
        .writer_data_lifecycle(WriterDataLifecycle {
            autodispose_unregistered_instances: false,
        })
        .build();
    let w = p
        .create_publisher(&PublisherQos::default())
        .and_then(|publ| publ.create_dynamic_writer(&t, &qos))
        .unwrap();
    let mut peer = Peer::spawn(38, &["reader"]);
    assert!(w.wait_for_readers(1, Duration::from_secs(20)), "no match");
    peer.expect("matched");

    // Instances.
    let h1 = w.register_instance(&beat(&ty, 1, 0)).unwrap();
    assert!(!h1.is_nil());
    assert_eq!(w.lookup_instance(&beat(&ty, 1, 99)).unwrap(), Some(h1));
    assert_eq!(w.lookup_instance(&beat(&ty, 7, 0)).unwrap(), None);
    assert_eq!(
        w.get_key_value(h1).unwrap().get("id"),
        Some(&Value::Int32(1))
    );
    for id in 1..=5 {
        w.write(&beat(&ty, id, 10 * id)).unwrap();
    }
    assert_eq!(w.lookup_instance(&beat(&ty, 1, 0)).unwrap(), Some(h1));
    let handle = |id| w.lookup_instance(&beat(&ty, id, 0)).unwrap().unwrap();
    let (h2, h4) = (handle(2), handle(4));
    peer.expect_all(&[
        "sample 1 10",
        "sample 2 20",
        "sample 3 30",
        "sample 4 40",
        "sample 5 50",
    ]);
    w.dispose(&beat(&ty, 1, 0)).unwrap();
    w.dispose_w_handle(h2).unwrap();
    w.unregister_instance(&beat(&ty, 3, 0)).unwrap();
    w.unregister_instance_w_handle(h4).unwrap();
    peer.expect_all(&[
        "state 1 disposed",
        "state 2 disposed",
        "state 3 no_writers",
        "state 4 no_writers",
    ]);
    assert_eq!(w.lookup_instance(&beat(&ty, 3, 0)).unwrap(), None);
    assert!(matches!(
        w.unregister_instance_w_handle(h4),
        Err(DdsError::BadParameter(_))
    ));

    // Liveliness: asserted without writing for 2.5 lease durations, then lost, then regained.
    assert!(peer.printed("liveliness 1 0"), "{:?}", peer.seen);
    assert!(
        peer.printed("writer deadline inf strength 0"),
        "{:?}",
        peer.seen
    );
    let end = Instant::now() + Duration::from_millis(2500);
    while Instant::now() < end {
        w.assert_liveliness().unwrap();
        peer.pump(Duration::from_millis(200));
    }
    assert!(
        !peer.printed("liveliness 0 1"),
        "lost while asserted: {:?}",
        peer.seen
    );
    // Cyclone 11 marks the lost writer's instances NOT_ALIVE_NO_WRITERS, and takes it back alive at
    // its next sample (a liveliness HEARTBEAT alone renews a live writer's lease but does not revive it).
    peer.expect_all(&["liveliness 0 1", "state 5 no_writers"]);
    w.write(&beat(&ty, 5, 51)).unwrap();
    peer.expect_all(&["liveliness 1 0", "sample 5 51"]);

    // QoS.
    let immutable = DataWriterQos {
        reliability: Reliability::BestEffort,
        ..w.qos()
    };
    assert!(matches!(
        w.set_qos(&immutable),
        Err(DdsError::ImmutablePolicy(QosPolicyId::Reliability))
    ));
    w.set_qos(&DataWriterQos {
        deadline: Deadline(Duration::from_millis(300)),
        ownership_strength: OwnershipStrength(7),
        ..w.qos()
    })
    .unwrap();
    assert_eq!(w.qos().deadline.0, Duration::from_millis(300));
    // Cyclone 11 takes the new strength from the SEDP update, but keeps the deadline it first saw (it
    // applies no change of a request-offered policy of a remote writer).
    peer.expect("writer deadline inf strength 7");
    w.write(&beat(&ty, 6, 60)).unwrap();
    peer.expect("sample 6 60");
    let mut missed = 0;
    assert!(wait_until(Duration::from_secs(10), || {
        missed += w.offered_deadline_missed_status().total_count_change;
        missed > 0
    }));

    // Deletion unregisters the instances still registered (5 and 6; 1 and 2 stay disposed).
    let before = peer.seen.len();
    drop(w);
    let unregistered = wait_until(Duration::from_secs(20), || {
        peer.pump(Duration::from_millis(100));
        let after = &peer.seen[before..];
        ["state 5 no_writers", "state 6 no_writers"]
            .iter()
            .all(|l| after.iter().any(|a| a == l))
    });
    assert!(unregistered, "the Cyclone reader printed {:?}", peer.seen);
    eprintln!("the Cyclone reader printed {:?}", peer.seen);
}

/// What the listeners above the dynamic endpoints saw: one line per call.
#[derive(Default)]
struct Seen(Mutex<Vec<String>>);

impl Seen {
    fn push(&self, what: String) {
        self.0.lock().unwrap().push(what);
    }
    fn has(&self, line: &str) -> bool {
        self.0.lock().unwrap().iter().any(|l| l == line)
    }
    fn all(&self) -> Vec<String> {
        self.0.lock().unwrap().clone()
    }
}

/// The publisher's listener: publication matched, naming the writer by handle.
struct PubLevel(Arc<Seen>, InstanceHandle);

impl PublisherListener for PubLevel {
    fn on_publication_matched(&self, w: InstanceHandle, s: PublicationMatchedStatus) {
        let who = if w == self.1 { "writer" } else { "other" };
        self.0
            .push(format!("pub matched {who} {}", s.current_count));
    }
}

/// The subscriber's listener: subscription matched, and DATA_ON_READERS, which lists the readers with
/// data and hands the data to their own listeners (`notify_datareaders`).
struct SubLevel(Arc<Seen>, Arc<Mutex<InstanceHandle>>);

impl SubscriberListener for SubLevel {
    fn on_subscription_matched(&self, r: InstanceHandle, s: SubscriptionMatchedStatus) {
        let who = if r == *self.1.lock().unwrap() {
            "reader"
        } else {
            "other"
        };
        self.0
            .push(format!("sub matched {who} {}", s.current_count));
    }
    fn on_data_on_readers(&self, s: &Subscriber) {
        let with_data = s
            .get_datareaders(
                SampleStateMask::NOT_READ,
                ViewStateMask::ANY,
                InstanceStateMask::ANY,
            )
            .unwrap();
        let listed = with_data.contains(&self.1.lock().unwrap());
        self.0.push(format!("data on readers {listed}"));
        s.notify_datareaders().unwrap();
    }
}

/// The participant's listener: the deadline and liveliness statuses of writers and readers.
struct PartLevel(Arc<Seen>);

impl DomainParticipantListener for PartLevel {
    fn on_offered_deadline_missed(&self, _: InstanceHandle, s: DeadlineMissedStatus) {
        self.0
            .push(format!("offered deadline {}", (s.total_count > 0)));
    }
    fn on_liveliness_changed(&self, _: InstanceHandle, s: LivelinessChangedStatus) {
        self.0.push(format!(
            "liveliness {} {}",
            s.alive_count, s.not_alive_count
        ));
    }
}

/// The dynamic reader's own listener, enabled for DATA_AVAILABLE only: called by `notify_datareaders`.
struct ReaderOwn(Arc<Seen>);

impl DynamicReaderListener for ReaderOwn {
    fn on_data_available(&self, r: &DynamicReader) {
        let n = r.take().len();
        self.0.push(format!("reader data {}", n > 0));
    }
}

/// A dynamic writer to a Cyclone 11 reader and a Cyclone 11 writer to a dynamic reader, neither with a
/// listener of its own for the statuses tested: the publisher's listener gets the writer's match, the
/// subscriber's the reader's match and DATA_ON_READERS (with the reader among `get_datareaders`), and the
/// participant's the writer's missed deadline and the reader's liveliness change when the Cyclone writer
/// (MANUAL_BY_TOPIC, 600 ms lease) falls silent.
#[test]
#[ignore = "needs python3 with cyclonedds; run explicitly"]
fn dynamic_endpoint_statuses_reach_publisher_subscriber_and_participant_listeners() {
    require_netns();
    let ty = beat_type();
    let p = participant(39);
    let seen = Arc::new(Seen::default());
    p.set_listener(
        Box::new(PartLevel(seen.clone())),
        StatusMask::OFFERED_DEADLINE_MISSED | StatusMask::LIVELINESS_CHANGED,
    );
    let out = p
        .create_dynamic_topic("BeatOut", ty.clone(), &TopicQos::default())
        .unwrap();
    let inp = p
        .create_dynamic_topic("BeatIn", ty.clone(), &TopicQos::default())
        .unwrap();
    let publ = p.create_publisher(&PublisherQos::default()).unwrap();
    // The Cyclone reader requests MANUAL_BY_TOPIC liveliness.
    let wq = DataWriterQos::builder()
        .reliability(reliable())
        .deadline(Duration::from_millis(300))
        .liveliness(Liveliness {
            kind: LivelinessKind::ManualByTopic,
            lease_duration: Duration::from_secs(1),
        })
        .build();
    let w = publ.create_dynamic_writer(&out, &wq).unwrap();
    publ.set_listener(
        Box::new(PubLevel(seen.clone(), w.instance_handle())),
        StatusMask::PUBLICATION_MATCHED,
    )
    .unwrap();
    let sub = p.create_subscriber(&SubscriberQos::default()).unwrap();
    let reader_handle = Arc::new(Mutex::new(InstanceHandle::NIL));
    sub.set_listener(
        Box::new(SubLevel(seen.clone(), reader_handle.clone())),
        StatusMask::SUBSCRIPTION_MATCHED | StatusMask::DATA_ON_READERS,
    )
    .unwrap();
    let rq = DataReaderQos::builder()
        .reliability(reliable())
        .history(History::KeepLast(8))
        .build();
    let r = sub
        .create_dynamic_reader_with_listener(
            &inp,
            &rq,
            Box::new(ReaderOwn(seen.clone())),
            StatusMask::DATA_AVAILABLE,
        )
        .unwrap();
    *reader_handle.lock().unwrap() = r.instance_handle();
    assert!(sub
        .get_datareaders(
            SampleStateMask::ANY,
            ViewStateMask::ANY,
            InstanceStateMask::ANY
        )
        .unwrap()
        .is_empty());
    let mut cy_reader = Peer::spawn(39, &["reader", "BeatOut"]);
    let mut cy_writer = Peer::spawn(39, &["writer", "BeatIn"]);
    assert!(w.wait_for_readers(1, Duration::from_secs(20)), "no match");
    cy_reader.expect("matched");
    w.write(&beat(&ty, 1, 1)).unwrap();
    cy_reader.expect("sample 1 1");
    cy_writer.expect("matched");
    let wanted = [
        "pub matched writer 1",
        "sub matched reader 1",
        "data on readers true",
        "reader data true",
        "offered deadline true",
        "liveliness 1 0",
        "liveliness 0 1",
    ];
    let done = wait_until(Duration::from_secs(20), || {
        wanted.iter().all(|l| seen.has(l))
    });
    eprintln!("the listeners saw {:?}", seen.all());
    assert!(done, "the listeners saw {:?}", seen.all());
    assert!(!seen.has("pub matched other 1") && !seen.has("sub matched other 1"));
}
