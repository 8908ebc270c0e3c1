//! Unions and instance states against a real Cyclone DDS 11 peer (python `cyclonedds`,
//! `dcps_util/cyclone_union.py`), typed and dynamic endpoints. Cyclone 11 numbers the members of non-mutable
//! unions from 0 in its type objects, where XTypes 1.3 (and Cyclone after 11.0.1) starts at 1; we follow
//! Cyclone 11 (docs/xtypes.md). With ids from 1 these endpoints never matched; these tests prove they match
//! and exchange samples both ways.
//! Ignored by default (needs python3 + cyclonedds): run with
//! `scripts/isolated cargo nextest run -p dds-runtime --features idl,json --test dcps_dynamic_cyclone
//! --run-ignored ignored-only`. Domains 215, 216, 217, 218 and 15.
mod dcps_util;

use std::io::{BufRead, BufReader};
use std::process::{Child, Command, Stdio};
use std::time::Duration;

use dcps_util::*;
use dds_runtime::prelude::*;

const CYCLONE_URI: &str = r#"<CycloneDDS><Domain id="any"><General><Interfaces><NetworkInterface name="lo" multicast="true"/></Interfaces><AllowMulticast>true</AllowMulticast></General></Domain></CycloneDDS>"#;

/// `xu::Choice`, as the Python peer declares it.
#[derive(DdsType, Debug, Clone, PartialEq)]
#[dds(name = "xu::Choice", final, discriminator = i32)]
pub(crate) enum Choice {
    #[dds(case = 1, name = "a")]
    A(i32),
    #[dds(case = 2, name = "b")]
    B(String),
}

impl Default for Choice {
    fn default() -> Self {
        Choice::A(0)
    }
}

/// `xu::Holder`: keyed on `id`, holding the union.
#[derive(DdsType, Debug, Clone, PartialEq, Default)]
#[dds(name = "xu::Holder", final)]
pub(crate) struct Holder {
    #[dds(key)]
    pub(crate) id: i32,
    pub(crate) c: Choice,
}

fn python(domain: u32, args: &[&str]) -> Child {
    let script = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/dcps_util/cyclone_union.py"
    );
    Command::new("python3")
        .arg(script)
        .args(args)
        .env("CYCLONEDDS_URI", CYCLONE_URI)
        .env("DDS_DOMAIN_ID", domain.to_string())
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::inherit())
        .spawn()
        .expect("python3 with cyclonedds")
}

fn tl_writer_qos() -> DataWriterQos {
    DataWriterQos::builder()
        .reliability(reliable())
        .durability(Durability::TransientLocal)
        .history(History::KeepLast(10))
        .build()
}

fn tl_reader_qos() -> DataReaderQos {
    DataReaderQos::builder()
        .reliability(reliable())
        .durability(Durability::TransientLocal)
        .history(History::KeepLast(10))
        .build()
}

fn holder(id: i32) -> Holder {
    let c = if id % 2 == 1 {
        Choice::A(10 * id)
    } else {
        Choice::B(format!("s{id}"))
    };
    Holder { id, c }
}

#[test]
#[ignore = "needs python3 with cyclonedds; run explicitly"]
fn typed_union_writer_to_cyclone_reader() {
    require_netns();
    let p = participant(215);
    let t = p
        .create_topic::<Holder>("UnionTopic", &TopicQos::default())
        .unwrap();
    let w = p
        .create_publisher(&PublisherQos::default())
        .and_then(|publ| publ.create_datawriter(&t, &tl_writer_qos()))
        .unwrap();
    let mut child = python(215, &["sub", "4"]);
    for id in 1..=4 {
        w.write(&holder(id)).unwrap();
    }
    let out = BufReader::new(child.stdout.take().unwrap());
    let lines: Vec<String> = out.lines().map_while(Result::ok).collect();
    assert!(child.wait().unwrap().success(), "cyclone sub: {lines:?}");
    let want = [
        r#"{"id": 1, "d": 1, "v": 10}"#,
        r#"{"id": 2, "d": 2, "v": "s2"}"#,
        r#"{"id": 3, "d": 1, "v": 30}"#,
        r#"{"id": 4, "d": 2, "v": "s4"}"#,
    ];
    assert_eq!(lines, want);
}

/// Cyclone writes ids 1..4, disposes 2 and unregisters 3 (its only writer): the typed reader sees the union
/// values and the instance states.
#[test]
#[ignore = "needs python3 with cyclonedds; run explicitly"]
fn cyclone_union_writer_to_typed_reader() {
    require_netns();
    let p = participant(216);
    let t = p
        .create_topic::<Holder>("UnionTopic", &TopicQos::default())
        .unwrap();
    let r = p
        .create_subscriber(&SubscriberQos::default())
        .and_then(|s| s.create_datareader(&t, &tl_reader_qos()))
        .unwrap();
    let mut child = python(216, &["pub"]);
    let mut states = std::collections::BTreeMap::new();
    let mut values = std::collections::BTreeMap::new();
    wait_until(Duration::from_secs(25), || {
        let _ = r.wait_for_data(Duration::from_millis(100));
        for s in r.read().unwrap() {
            if let Some(d) = &s.data {
                values.insert(d.id, d.clone());
            }
            states.insert(s.info.instance_handle, s.info.instance_state);
        }
        values.len() == 4
            && states
                .values()
                .filter(|s| **s != InstanceState::Alive)
                .count()
                == 2
    });
    drop(child.stdin.take()); // the peer exits when its stdin closes
    let _ = child.wait();
    assert_eq!(
        values.into_values().collect::<Vec<_>>(),
        (1..=4).map(holder).collect::<Vec<_>>()
    );
    let mut got: Vec<(i32, InstanceState)> = Vec::new();
    for id in 1..=4 {
        let h = r
            .lookup_instance(&holder(id))
            .unwrap()
            .expect("instance known");
        got.push((id, states[&h]));
    }
    assert_eq!(
        got,
        [
            (1, InstanceState::Alive),
            (2, InstanceState::NotAliveDisposed),
            (3, InstanceState::NotAliveNoWriters),
            (4, InstanceState::Alive),
        ]
    );
}

/// The same Cyclone writer to a dynamic reader (type from IDL text): the dynamic reader keeps instances with
/// the typed reader's cache, so it sees the union values, disposed and unregistered instances, sample states
/// (read, then not read again) and reads by instance.
#[cfg(all(feature = "idl", feature = "json"))]
#[test]
#[ignore = "needs python3 with cyclonedds; run explicitly"]
fn cyclone_union_writer_to_dynamic_reader_instance_states() {
    use dds_runtime::xtypes::dynamic::{types_from_idl, DynamicData, Value};
    require_netns();
    let idl =
        "module xu { @final union Choice switch (long) { case 1: long a; case 2: string b; }; \
               @final struct Holder { @key long id; Choice c; }; };";
    let ty = types_from_idl("u.idl", idl)
        .unwrap()
        .remove("xu::Holder")
        .unwrap();
    let p = participant(217);
    let t = p
        .create_dynamic_topic("UnionTopic", ty.clone(), &TopicQos::default())
        .unwrap();
    let r = p
        .create_subscriber(&SubscriberQos::default())
        .and_then(|s| s.create_dynamic_reader(&t, &tl_reader_qos()))
        .unwrap();
    let mut child = python(217, &["pub"]);
    let key = |id: i32| {
        let mut d = DynamicData::new(ty.clone());
        d.set("id", Value::Int32(id)).unwrap();
        d
    };
    let settled = wait_until(Duration::from_secs(25), || {
        r.wait_for_data(Duration::from_millis(100));
        let states: Vec<_> = (1..=4)
            .map(|id| {
                r.lookup_instance(&key(id))
                    .and_then(|h| r.instance_state(h))
            })
            .collect();
        states
            == [
                Some(InstanceState::Alive),
                Some(InstanceState::NotAliveDisposed),
                Some(InstanceState::NotAliveNoWriters),
                Some(InstanceState::Alive),
            ]
    });
    drop(child.stdin.take());
    let _ = child.wait();
    assert!(settled, "instance states never settled");
    assert_eq!(r.instance_count(), 4);
    let any = (
        SampleStateMask::ANY,
        ViewStateMask::ANY,
        InstanceStateMask::ANY,
    );
    let first = r.read_states(SampleStateMask::NOT_READ, any.1, any.2);
    let values: Vec<String> = first
        .iter()
        .filter_map(|s| s.data.as_ref())
        .map(|d| d.to_json().to_string())
        .collect();
    assert_eq!(
        values,
        [
            r#"{"c":{"a":10,"discriminator":1},"id":1}"#,
            r#"{"c":{"b":"s2","discriminator":2},"id":2}"#,
            r#"{"c":{"a":30,"discriminator":1},"id":3}"#,
            r#"{"c":{"b":"s4","discriminator":2},"id":4}"#,
        ]
    );
    assert!(r
        .read_states(SampleStateMask::NOT_READ, any.1, any.2)
        .is_empty());
    let only_disposed = InstanceStateMask {
        alive: false,
        disposed: true,
        no_writers: false,
    };
    let disposed = r.read_states(any.0, any.1, only_disposed);
    assert!(!disposed.is_empty());
    assert!(disposed
        .iter()
        .all(|s| s.info.instance_state == InstanceState::NotAliveDisposed));
    let h4 = r.lookup_instance(&key(4)).unwrap();
    let taken = r.take_instance(h4);
    assert_eq!(taken.len(), 1);
    assert_eq!(taken[0].info.instance_handle, h4);
    assert!(r.read_instance(h4).is_empty());
}

/// What a dynamic reader saw of its statuses: one line per status change.
#[cfg(feature = "idl")]
#[derive(Default)]
struct Seen(std::sync::Mutex<Vec<String>>);

#[cfg(feature = "idl")]
impl Seen {
    fn push(&self, what: String) {
        self.0.lock().unwrap().push(what);
    }
    fn has(&self, prefix: &str) -> bool {
        self.0.lock().unwrap().iter().any(|l| l.starts_with(prefix))
    }
    fn all(&self) -> Vec<String> {
        self.0.lock().unwrap().clone()
    }
}

#[cfg(feature = "idl")]
struct Recorder(std::sync::Arc<Seen>);

#[cfg(feature = "idl")]
impl DynamicReaderListener for Recorder {
    fn on_data_available(&self, r: &DynamicReader) {
        let n = r.read_states(
            SampleStateMask::NOT_READ,
            ViewStateMask::ANY,
            InstanceStateMask::ANY,
        );
        self.0.push(format!("data {}", n.len()));
    }
    fn on_subscription_matched(&self, _: &DynamicReader, s: SubscriptionMatchedStatus) {
        self.0.push(format!("matched {}", s.current_count));
    }
    fn on_requested_deadline_missed(&self, _: &DynamicReader, s: DeadlineMissedStatus) {
        self.0.push(format!("deadline {}", s.total_count));
    }
    fn on_liveliness_changed(&self, _: &DynamicReader, s: LivelinessChangedStatus) {
        self.0.push(format!(
            "liveliness {} {}",
            s.alive_count, s.not_alive_count
        ));
    }
}

/// The statuses a WaitSet on a dynamic reader's status condition reports, each read (and so reset) once
/// seen, in the `Seen` notation.
#[cfg(feature = "idl")]
fn waitset_round(r: &DynamicReader, ws: &WaitSet, seen: &Seen) {
    let Ok(triggered) = ws.wait(Duration::from_millis(200)) else {
        return;
    };
    if triggered.is_empty() {
        return;
    }
    let changed = r.status_condition().changed_statuses();
    if changed.contains(StatusMask::SUBSCRIPTION_MATCHED) {
        seen.push(format!(
            "matched {}",
            r.subscription_matched_status().current_count
        ));
    }
    if changed.contains(StatusMask::DATA_AVAILABLE) {
        seen.push(format!("data {}", r.take().len()));
    }
    if changed.contains(StatusMask::REQUESTED_DEADLINE_MISSED) {
        let s = r.requested_deadline_missed_status();
        seen.push(format!("deadline {}", s.total_count));
    }
    if changed.contains(StatusMask::LIVELINESS_CHANGED) {
        let s = r.liveliness_changed_status();
        seen.push(format!(
            "liveliness {} {}",
            s.alive_count, s.not_alive_count
        ));
    }
}

/// A Cyclone writer (offered deadline 300 ms, MANUAL_BY_TOPIC liveliness with a 600 ms lease) writes five
/// samples, then falls silent. Two dynamic readers of its type: one with a listener, one watched through a
/// WaitSet on its status condition. Both see the match, the data, the missed deadline and the lost
/// liveliness (a status change with no alive writer and one not alive).
#[cfg(feature = "idl")]
#[test]
#[ignore = "needs python3 with cyclonedds; run explicitly"]
fn dynamic_reader_statuses_from_a_cyclone_writer() {
    use dds_runtime::xtypes::dynamic::types_from_idl;
    use std::sync::Arc;
    require_netns();
    let ty = types_from_idl(
        "b.idl",
        "module xs { @final struct Beat { @key long id; long n; }; };",
    )
    .unwrap()
    .remove("xs::Beat")
    .unwrap();
    let p = participant(218);
    let t = p
        .create_dynamic_topic("BeatTopic", ty, &TopicQos::default())
        .unwrap();
    let qos = DataReaderQos::builder()
        .reliability(reliable())
        .history(History::KeepLast(1))
        .deadline(Duration::from_millis(300))
        .build();
    let s = p.create_subscriber(&SubscriberQos::default()).unwrap();
    let by_listener = Arc::new(Seen::default());
    let _listened = s
        .create_dynamic_reader_with_listener(
            &t,
            &qos,
            Box::new(Recorder(by_listener.clone())),
            StatusMask::all(),
        )
        .unwrap();
    let watched = s.create_dynamic_reader(&t, &qos).unwrap();
    let cond = watched.status_condition();
    cond.set_enabled_statuses(
        StatusMask::SUBSCRIPTION_MATCHED
            | StatusMask::DATA_AVAILABLE
            | StatusMask::REQUESTED_DEADLINE_MISSED
            | StatusMask::LIVELINESS_CHANGED,
    );
    let ws = WaitSet::new();
    ws.attach_condition(cond);
    let by_waitset = Seen::default();
    let script = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/dcps_util/cyclone_status.py"
    );
    let mut child = Command::new("python3")
        .arg(script)
        .env("CYCLONEDDS_URI", CYCLONE_URI)
        .env("DDS_DOMAIN_ID", "218")
        .stdin(Stdio::piped())
        .stderr(Stdio::inherit())
        .spawn()
        .expect("python3 with cyclonedds");
    let wanted = ["matched 1", "data ", "deadline ", "liveliness 0 1"];
    let done = wait_until(Duration::from_secs(25), || {
        waitset_round(&watched, &ws, &by_waitset);
        wanted
            .iter()
            .all(|w| by_waitset.has(w) && by_listener.has(w))
    });
    drop(child.stdin.take());
    let _ = child.wait();
    assert!(
        done,
        "listener saw {:?}, waitset saw {:?}",
        by_listener.all(),
        by_waitset.all()
    );
    eprintln!(
        "listener saw {:?}\nwaitset saw {:?}",
        by_listener.all(),
        by_waitset.all()
    );
    assert!(by_listener.has("liveliness 1 0") && by_waitset.has("liveliness 1 0"));
}

/// Records a dynamic writer's listener calls.
#[cfg(feature = "idl")]
struct WriterRecorder(std::sync::Arc<Seen>);

#[cfg(feature = "idl")]
impl DynamicWriterListener for WriterRecorder {
    fn on_publication_matched(&self, _: &DynamicWriter, s: PublicationMatchedStatus) {
        self.0.push(format!("matched {}", s.current_count));
    }
    fn on_offered_deadline_missed(&self, _: &DynamicWriter, s: DeadlineMissedStatus) {
        self.0.push(format!("deadline {}", s.total_count));
    }
    fn on_offered_incompatible_qos(&self, _: &DynamicWriter, s: IncompatibleQosStatus) {
        self.0.push(format!("incompatible {:?}", s.last_policy_id));
    }
}

/// A dynamic writer's listener and status condition against Cyclone 11 readers (`cyclone_status.py sub`):
/// the reader requesting a 1 s deadline matches, the one requesting 100 ms is reported as offered
/// incompatible QoS (DEADLINE), and the writer's 300 ms offered deadline is missed once it stops writing.
#[cfg(feature = "idl")]
#[test]
#[ignore = "needs python3 with cyclonedds; run explicitly"]
fn dynamic_writer_statuses_to_cyclone_readers() {
    use dds_runtime::xtypes::dynamic::{types_from_idl, DynamicData, Value};
    use std::sync::Arc;
    require_netns();
    let ty = types_from_idl(
        "b.idl",
        "module xs { @final struct Beat { @key long id; long n; }; };",
    )
    .unwrap()
    .remove("xs::Beat")
    .unwrap();
    let p = participant(15);
    let t = p
        .create_dynamic_topic("BeatTopic", ty.clone(), &TopicQos::default())
        .unwrap();
    let qos = DataWriterQos::builder()
        .reliability(reliable())
        .history(History::KeepLast(1))
        .deadline(Duration::from_millis(300))
        .build();
    let seen = Arc::new(Seen::default());
    let w = p
        .create_publisher(&PublisherQos::default())
        .and_then(|publ| {
            publ.create_dynamic_writer_with_listener(
                &t,
                &qos,
                Box::new(WriterRecorder(seen.clone())),
                StatusMask::all(),
            )
        })
        .unwrap();
    let cond = w.status_condition();
    cond.set_enabled_statuses(StatusMask::PUBLICATION_MATCHED);
    let ws = WaitSet::new();
    ws.attach_condition(cond.clone());
    let script = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/dcps_util/cyclone_status.py"
    );
    let mut child = Command::new("python3")
        .arg(script)
        .arg("sub")
        .env("CYCLONEDDS_URI", CYCLONE_URI)
        .env("DDS_DOMAIN_ID", "15")
        .stdin(Stdio::piped())
        .stderr(Stdio::inherit())
        .spawn()
        .expect("python3 with cyclonedds");
    let matched = !ws.wait(Duration::from_secs(20)).unwrap().is_empty();
    let m = w.publication_matched_status();
    let mut beat = DynamicData::new(ty);
    beat.set("id", Value::Int32(1)).unwrap();
    for n in 0..3 {
        beat.set("n", Value::Int32(n)).unwrap();
        w.write(&beat).unwrap();
        std::thread::sleep(Duration::from_millis(50));
    }
    cond.set_enabled_statuses(StatusMask::OFFERED_DEADLINE_MISSED);
    let missed = !ws.wait(Duration::from_secs(5)).unwrap().is_empty();
    let d = w.offered_deadline_missed_status();
    let wanted = ["matched 1", "deadline ", "incompatible Some(Deadline)"];
    let done = wait_until(Duration::from_secs(10), || {
        wanted.iter().all(|x| seen.has(x))
    });
    let q = w.offered_incompatible_qos_status();
    drop(child.stdin.take());
    let _ = child.wait();
    eprintln!("listener saw {:?}", seen.all());
    assert!(matched && m.current_count == 1, "no match: {m:?}");
    assert!(missed && d.total_count >= 1, "no deadline missed: {d:?}");
    assert!(done, "listener saw {:?}", seen.all());
    assert_eq!(q.last_policy_id, Some(QosPolicyId::Deadline));
}
