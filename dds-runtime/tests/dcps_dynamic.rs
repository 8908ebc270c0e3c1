//! Dynamic writers and readers against typed ones, in one process over loopback: the same discovery and
//! matching, the same bytes. Run inside `scripts/isolated`.
mod dcps_util;

use std::time::Duration;

use dcps_util::*;
use dds_runtime::cdr::Extensibility;
use dds_runtime::dcps::DynamicSample;
use dds_runtime::filter::ContentFilter;
use dds_runtime::prelude::*;
use dds_runtime::rtps::ChangeKind;
use dds_runtime::xtypes::dynamic::{
    types_from_idl, DynamicData, DynamicType, MemberBuilder, Primitive, StructBuilder, Value,
};

const SHAPE_IDL: &str =
    "@appendable struct ShapeType { @key string color; long x; long y; long shapesize; };";

fn shape_from_builder() -> DynamicType {
    let long = DynamicType::primitive(Primitive::Int32);
    StructBuilder::new("ShapeType")
        .extensibility(Extensibility::Appendable)
        .with(MemberBuilder::new("color", DynamicType::string(None)).key())
        .member("x", long.clone())
        .member("y", long.clone())
        .member("shapesize", long)
        .build()
        .expect("ShapeType")
}

fn dynamic_shape(ty: &DynamicType, color: &str, x: i32) -> DynamicData {
    let mut d = DynamicData::new(ty.clone());
    d.set("color", Value::String(color.into())).unwrap();
    d.set("x", Value::Int32(x)).unwrap();
    d.set("y", Value::Int32(2 * x)).unwrap();
    d.set("shapesize", Value::Int32(30)).unwrap();
    d
}

#[test]
fn dynamic_writer_from_idl_to_typed_reader() {
    let ty = types_from_idl("shape.idl", SHAPE_IDL)
        .unwrap()
        .remove("ShapeType")
        .expect("ShapeType from IDL");
    let (p1, p2) = (participant(91), participant(91));
    let (wq, rq) = reliable_keep_all();
    let topic = p1
        .create_dynamic_topic("Square", ty.clone(), &TopicQos::default())
        .unwrap();
    let w = p1
        .create_publisher(&PublisherQos::default())
        .and_then(|p| p.create_dynamic_writer(&topic, &wq))
        .unwrap();
    let r = reader::<ShapeType>(&p2, "Square", &rq);
    assert!(
        w.wait_for_readers(1, MATCH_TIMEOUT),
        "dynamic writer matched the typed reader"
    );
    assert!(wait_until(MATCH_TIMEOUT, || r
        .subscription_matched_status()
        .current_count
        == 1));
    for i in 0..10 {
        w.write(&dynamic_shape(
            &ty,
            if i % 2 == 0 { "RED" } else { "BLUE" },
            i,
        ))
        .unwrap();
    }
    let mut got = Vec::new();
    wait_until(Duration::from_secs(10), || {
        got.extend(r.take().unwrap().into_iter().filter_map(|s| s.data));
        got.len() >= 10
    });
    let want: Vec<ShapeType> = (0..10)
        .map(|i| shape(if i % 2 == 0 { "RED" } else { "BLUE" }, i))
        .collect();
    assert_eq!(got, want);
    assert_eq!(
        r.instance_count(),
        2,
        "the dynamic key hash gives the typed instances"
    );
}

/// A typed `ShapeType` writer on `p1` and a dynamic reader of `ty` on `p2`, on `topic`, reliable KEEP_ALL;
/// with `wait`, once each has matched the other.
fn typed_writer_dynamic_reader(
    (p1, p2): (&DomainParticipant, &DomainParticipant),
    topic: &str,
    ty: &DynamicType,
    wait: bool,
) -> (DataWriter<ShapeType>, DynamicReader) {
    let (wq, rq) = reliable_keep_all();
    let w = writer::<ShapeType>(p1, topic, &wq);
    let t = p2
        .create_dynamic_topic(topic, ty.clone(), &TopicQos::default())
        .unwrap();
    let r = p2
        .create_subscriber(&SubscriberQos::default())
        .and_then(|s| s.create_dynamic_reader(&t, &rq))
        .unwrap();
    if wait {
        assert!(wait_until(MATCH_TIMEOUT, || w
            .publication_matched_status()
            .current_count
            == 1));
        assert!(wait_until(MATCH_TIMEOUT, || r.matched_writers().len() == 1));
    }
    (w, r)
}

#[test]
fn typed_writer_to_dynamic_reader_with_dispose_and_filter() {
    let ty = shape_from_builder();
    let (p1, p2) = (participant(92), participant(92));
    let (w, r) = typed_writer_dynamic_reader((&p1, &p2), "Circle", &ty, true);
    for i in 0..5 {
        w.write(&shape("GREEN", i)).unwrap();
    }
    w.dispose(&shape("GREEN", 0)).unwrap();
    // The typed reader's cache: the dispose marks the instance (and the samples still in the cache) as
    // NOT_ALIVE_DISPOSED; it is a sample of its own (without data, with the key) only once the data is taken.
    let mut got = Vec::new();
    let disposed = |got: &[DynamicSample]| {
        got.iter()
            .any(|s| s.info.instance_state == InstanceState::NotAliveDisposed)
    };
    wait_until(Duration::from_secs(10), || {
        r.wait_for_data(Duration::from_millis(100));
        got.extend(r.take());
        got.iter().filter(|s| s.info.valid_data).count() >= 5 && disposed(&got)
    });
    let valid: Vec<&DynamicSample> = got.iter().filter(|s| s.info.valid_data).collect();
    assert_eq!(valid.len(), 5);
    for (i, s) in valid.iter().enumerate() {
        assert_eq!(s.kind, ChangeKind::Alive);
        assert_eq!(
            s.data.as_ref(),
            Some(&dynamic_shape(&ty, "GREEN", i as i32))
        );
        assert_eq!(s.writer, w.guid());
    }
    assert!(disposed(&got), "the dispose was not seen");
    for s in got.iter().filter(|s| !s.info.valid_data) {
        assert_eq!(s.kind, ChangeKind::Dispose);
        let key = s.data.as_ref().expect("the dispose carries the key");
        assert_eq!(key.get("color"), Some(&Value::String("GREEN".into())));
    }
    let got: Vec<DynamicSample> = valid.into_iter().cloned().collect();
    let f = ContentFilter::new("x > 2 AND color = 'GREEN'", &[] as &[&str]).unwrap();
    let passed: Vec<_> = got[..5]
        .iter()
        .filter(|s| f.matches(s.data.as_ref().unwrap()))
        .collect();
    assert_eq!(passed.len(), 2);
}

/// Takes until `n` samples came (or 10 s passed).
fn take_n_dynamic(r: &DynamicReader, n: usize) -> Vec<DynamicSample> {
    let mut got = Vec::new();
    wait_until(Duration::from_secs(10), || {
        r.wait_for_data(Duration::from_millis(100));
        got.extend(r.take());
        got.len() >= n
    });
    got
}

/// The key members of a dispose or unregister (domain 94): a dispose of an instance the reader never had
/// data of, and the unregister (disposing) of one it had, both carry the instance's key (the other members defaulted),
/// although the take forgets each instance at once (not alive, no writers, no samples left); while the
/// instance lives, `get_key_value` gives the same key. Before session 27 both were `None`: the key was
/// looked up after the take, and an instance made by data had no key holder in a dynamic reader.
#[test]
fn dynamic_reader_invalid_samples_carry_the_key() {
    let ty = shape_from_builder();
    let (p1, p2) = (participant(94), participant(94));
    let (w, r) = typed_writer_dynamic_reader((&p1, &p2), "Ghost", &ty, true);
    let color = |s: &DynamicSample| s.data.as_ref().and_then(|d| d.get("color").cloned());
    let x = |s: &DynamicSample| s.data.as_ref().and_then(|d| d.get("x").cloned());

    w.dispose(&shape("PURPLE", 5)).unwrap();
    let got = take_n_dynamic(&r, 1);
    assert_eq!(got.len(), 1, "{got:?}");
    assert_eq!(
        (got[0].kind, got[0].info.valid_data),
        (ChangeKind::Dispose, false)
    );
    assert_eq!(color(&got[0]), Some(Value::String("PURPLE".into())));
    assert_eq!(x(&got[0]), Some(Value::Int32(0)), "only the key is known");

    w.write(&shape("RED", 7)).unwrap();
    let got = take_n_dynamic(&r, 1);
    assert_eq!(got.len(), 1, "{got:?}");
    assert_eq!(got[0].data.as_ref(), Some(&dynamic_shape(&ty, "RED", 7)));
    let red = got[0].info.instance_handle;
    let key = r.get_key_value(red).expect("RED is alive");
    assert_eq!(key.get("color"), Some(&Value::String("RED".into())));
    assert_eq!(key.get("x"), Some(&Value::Int32(0)));

    w.unregister_instance(&shape("RED", 7)).unwrap();
    let got = take_n_dynamic(&r, 1);
    assert_eq!(got.len(), 1, "{got:?}");
    // The writer disposes what it unregisters (autodispose_unregistered_instances, on by default).
    assert_eq!(
        (got[0].kind, got[0].info.valid_data),
        (ChangeKind::Dispose, false)
    );
    assert_eq!(got[0].info.instance_handle, red);
    assert_eq!(color(&got[0]), Some(Value::String("RED".into())));
    assert!(
        r.get_key_value(red).is_none(),
        "the take forgot the instance"
    );
}

#[test]
fn dynamic_types_have_the_derived_type_information() {
    let from_idl = types_from_idl("shape.idl", SHAPE_IDL)
        .unwrap()
        .remove("ShapeType")
        .expect("ShapeType from IDL");
    for ty in [shape_from_builder(), from_idl] {
        let s = ty.type_support().expect("type support");
        assert_eq!(
            Some(s.information_bytes.as_slice()),
            ShapeType::type_information()
        );
        assert_eq!(Some(s.mapping_bytes.as_slice()), ShapeType::type_mapping());
    }
}

/// `ShapeType` with `x` a string: not assignable from `ShapeType`, whatever the name.
fn unassignable_shape() -> DynamicType {
    let long = DynamicType::primitive(Primitive::Int32);
    StructBuilder::new("ShapeType")
        .extensibility(Extensibility::Appendable)
        .with(MemberBuilder::new("color", DynamicType::string(None)).key())
        .member("x", DynamicType::string(None))
        .member("y", long.clone())
        .member("shapesize", long)
        .build()
        .expect("ShapeType")
}

/// `ShapeType`'s first two members under another name: assignable from `ShapeType` (appendable, members cut
/// at the end), so it matches although the type names differ.
fn reduced_shape() -> DynamicType {
    StructBuilder::new("Shapes::Reduced")
        .extensibility(Extensibility::Appendable)
        .with(MemberBuilder::new("color", DynamicType::string(None)).key())
        .member("x", DynamicType::primitive(Primitive::Int32))
        .build()
        .expect("Reduced")
}

#[test]
fn dynamic_readers_match_typed_writers_by_assignability() {
    std::env::set_var(dds_runtime::xtypes::ANNOUNCE_ENV, "on");
    let (p1, p2) = (participant(96), participant(96));
    let (wq, rq) = reliable_keep_all();
    let sub = p2.create_subscriber(&SubscriberQos::default()).unwrap();
    let dynamic_reader = |topic: &str, ty: DynamicType| {
        let t = p2
            .create_dynamic_topic(topic, ty, &TopicQos::default())
            .unwrap();
        assert!(
            t.type_information_bytes().is_some(),
            "{topic}: no type information"
        );
        sub.create_dynamic_reader(&t, &rq).unwrap()
    };
    let good = dynamic_reader("Triangle", reduced_shape());
    let bad = dynamic_reader("Star", unassignable_shape());
    let w_good = writer::<ShapeType>(&p1, "Triangle", &wq);
    let w_bad = writer::<ShapeType>(&p1, "Star", &wq);
    assert!(wait_until(MATCH_TIMEOUT, || good.matched_writers().len()
        == 1
        && w_good.publication_matched_status().current_count == 1));
    assert!(wait_until(MATCH_TIMEOUT, || w_bad
        .offered_incompatible_qos_status()
        .total_count
        >= 1));
    let st = w_bad.offered_incompatible_qos_status();
    assert_eq!(
        st.last_policy_id,
        Some(QosPolicyId::TypeConsistencyEnforcement)
    );
    assert_eq!(w_bad.publication_matched_status().current_count, 0);
    assert!(bad.matched_writers().is_empty());
    assert!(wait_until(MATCH_TIMEOUT, || bad
        .requested_incompatible_qos_status()
        .total_count
        >= 1));
    let st = bad.requested_incompatible_qos_status();
    assert_eq!(
        st.last_policy_id,
        Some(QosPolicyId::TypeConsistencyEnforcement)
    );
    assert_eq!(good.requested_incompatible_qos_status().total_count, 0);
    w_good.write(&shape("RED", 7)).unwrap();
    let mut got = Vec::new();
    wait_until(Duration::from_secs(10), || {
        good.wait_for_data(Duration::from_millis(100));
        got.extend(good.take());
        !got.is_empty()
    });
    let d = got[0].data.as_ref().expect("a sample");
    assert_eq!(d.get("color"), Some(&Value::String("RED".into())));
    assert_eq!(d.get("x"), Some(&Value::Int32(7)));
}

#[test]
fn dynamic_writers_match_typed_readers_by_assignability() {
    std::env::set_var(dds_runtime::xtypes::ANNOUNCE_ENV, "on");
    let (p1, p2) = (participant(97), participant(97));
    let (wq, rq) = reliable_keep_all();
    let publ = p1.create_publisher(&PublisherQos::default()).unwrap();
    let dynamic_writer = |topic: &str, ty: DynamicType| {
        let t = p1
            .create_dynamic_topic(topic, ty, &TopicQos::default())
            .unwrap();
        publ.create_dynamic_writer(&t, &wq).unwrap()
    };
    let reduced = reduced_shape();
    let good = dynamic_writer("Pentagon", reduced.clone());
    let bad = dynamic_writer("Hexagon", unassignable_shape());
    let r_good = reader::<ShapeType>(&p2, "Pentagon", &rq);
    let r_bad = reader::<ShapeType>(&p2, "Hexagon", &rq);
    assert!(good.wait_for_readers(1, MATCH_TIMEOUT));
    assert!(wait_until(MATCH_TIMEOUT, || bad
        .offered_incompatible_qos_status()
        .total_count
        >= 1));
    assert_eq!(
        bad.offered_incompatible_qos_status().last_policy_id,
        Some(QosPolicyId::TypeConsistencyEnforcement)
    );
    assert!(bad.matched_readers().is_empty());
    assert!(wait_until(MATCH_TIMEOUT, || r_bad
        .requested_incompatible_qos_status()
        .last_policy_id
        == Some(QosPolicyId::TypeConsistencyEnforcement)));
    let mut d = DynamicData::new(reduced);
    d.set("color", Value::String("RED".into())).unwrap();
    d.set("x", Value::Int32(5)).unwrap();
    good.write(&d).unwrap();
    let mut got = Vec::new();
    wait_until(Duration::from_secs(10), || {
        got.extend(r_good.take().unwrap().into_iter().filter_map(|s| s.data));
        !got.is_empty()
    });
    // The members the writer's type lacks take their defaults.
    assert_eq!(
        got.first(),
        Some(&ShapeType {
            color: "RED".into(),
            x: 5,
            y: 0,
            shapesize: 0
        })
    );
}

/// The dynamic reader's read and query conditions (the typed reader's `ReadCondition`/`QueryCondition` over its
/// cache): a waitset wakes for them, and read/take with a condition return what it selects, in its ORDER BY.
#[test]
fn dynamic_reader_read_and_query_conditions() {
    let ty = shape_from_builder();
    let (p1, p2) = (participant(215), participant(215));
    let (w, r) = typed_writer_dynamic_reader((&p1, &p2), "DynCond", &ty, false);
    let unread = r.create_readcondition(
        SampleStateMask::NOT_READ,
        ViewStateMask::ANY,
        InstanceStateMask::ANY,
    );
    let q = r
        .create_querycondition(
            SampleStateMask::ANY,
            ViewStateMask::ANY,
            InstanceStateMask::ANY,
            "x >= %0 ORDER BY y",
            &["2"],
        )
        .unwrap();
    let ws = WaitSet::new();
    ws.attach_condition(unread.clone());
    assert!(!unread.trigger_value());
    assert!(wait_until(MATCH_TIMEOUT, || w
        .publication_matched_status()
        .current_count
        == 1));
    for (color, x) in [("RED", 1), ("BLUE", 3), ("GREEN", 2), ("RED", 4)] {
        w.write(&shape(color, x)).unwrap();
    }
    let woke = ws.wait(Duration::from_secs(5)).expect("the waitset wakes");
    assert!(matches!(&woke[..], [Condition::Read(_)]));
    assert!(wait_until(Duration::from_secs(5), || r
        .read_states(
            SampleStateMask::ANY,
            ViewStateMask::ANY,
            InstanceStateMask::ANY
        )
        .len()
        == 4));
    assert!(!unread.trigger_value(), "everything was read");
    let xs = |v: Vec<Sample<DynamicData>>| -> Vec<i32> {
        v.iter()
            .filter_map(|s| match s.data.as_ref()?.get("x")? {
                Value::Int32(x) => Some(*x),
                _ => None,
            })
            .collect()
    };
    assert!(q.trigger_value());
    assert_eq!(xs(r.read_w_condition(&q)), [2, 3, 4]);
    assert_eq!(xs(r.take_w_condition(&q)), [2, 3, 4]);
    assert_eq!(
        xs(r.take_states(
            SampleStateMask::ANY,
            ViewStateMask::ANY,
            InstanceStateMask::ANY
        )),
        [1],
        "the query took only its samples"
    );
    assert!(!q.trigger_value());
}

/// Records each listener call of a dynamic reader by name.
struct Calls(std::sync::Arc<std::sync::Mutex<Vec<&'static str>>>);

impl DynamicReaderListener for Calls {
    fn on_data_available(&self, _: &DynamicReader) {
        self.0.lock().unwrap().push("data");
    }
    fn on_subscription_matched(&self, _: &DynamicReader, _: SubscriptionMatchedStatus) {
        self.0.lock().unwrap().push("matched");
    }
    fn on_requested_deadline_missed(&self, _: &DynamicReader, _: DeadlineMissedStatus) {
        self.0.lock().unwrap().push("deadline");
    }
    fn on_requested_incompatible_qos(&self, _: &DynamicReader, _: IncompatibleQosStatus) {
        self.0.lock().unwrap().push("incompatible");
    }
    fn on_sample_rejected(&self, _: &DynamicReader, _: SampleRejectedStatus) {
        self.0.lock().unwrap().push("rejected");
    }
}

/// A dynamic reader's listener and status condition, against typed writers: matched, data available and
/// deadline missed (a writer that stops), requested incompatible QoS (a best-effort writer), sample rejected
/// (KEEP_ALL with max_samples_per_instance 2); `get_*_status` reset the counts and clear the condition.
#[test]
fn dynamic_reader_listener_and_status_condition() {
    let ty = shape_from_builder();
    let (p1, p2) = (participant(17), participant(17));
    let publ = p1.create_publisher(&PublisherQos::default()).unwrap();
    let t1 = p1
        .create_topic::<ShapeType>("Square", &TopicQos::default())
        .unwrap();
    let w = publ
        .create_datawriter(
            &t1,
            &DataWriterQos::builder()
                .reliability(reliable())
                .deadline(Duration::from_millis(100))
                .history(History::KeepAll)
                .build(),
        )
        .unwrap();
    let topic = p2
        .create_dynamic_topic("Square", ty, &TopicQos::default())
        .unwrap();
    let calls = std::sync::Arc::new(std::sync::Mutex::new(Vec::new()));
    let rq = DataReaderQos::builder()
        .reliability(reliable())
        .deadline(Duration::from_millis(200))
        .history(History::KeepAll)
        .resource_limits(ResourceLimits {
            max_samples_per_instance: Some(2),
            ..ResourceLimits::default()
        })
        .build();
    let r = p2
        .create_subscriber(&SubscriberQos::default())
        .and_then(|s| {
            s.create_dynamic_reader_with_listener(
                &topic,
                &rq,
                Box::new(Calls(calls.clone())),
                StatusMask::all(),
            )
        })
        .unwrap();
    let cond = r.status_condition();
    cond.set_enabled_statuses(StatusMask::SUBSCRIPTION_MATCHED);
    let ws = WaitSet::new();
    ws.attach_condition(cond.clone());
    assert!(!ws.wait(MATCH_TIMEOUT).unwrap().is_empty(), "no match");
    assert_eq!(r.subscription_matched_status().current_count, 1);
    assert!(!cond.trigger_value(), "reading the status clears it");
    // Volatile: the writer must have matched the reader too, or the sample goes nowhere.
    assert!(wait_until(MATCH_TIMEOUT, || w
        .publication_matched_status()
        .current_count
        == 1));
    w.write(&shape("RED", 0)).unwrap();
    cond.set_enabled_statuses(StatusMask::REQUESTED_DEADLINE_MISSED);
    assert!(
        !ws.wait(Duration::from_secs(5)).unwrap().is_empty(),
        "no deadline"
    );
    assert!(r.requested_deadline_missed_status().total_count >= 1);
    // Reliable KEEP_ALL: the third sample of the instance is rejected (and repaired later).
    for x in 1..3 {
        w.write(&shape("RED", x)).unwrap();
    }
    let best_effort = publ
        .create_datawriter(
            &t1,
            &DataWriterQos::builder()
                .reliability(Reliability::BestEffort)
                .build(),
        )
        .unwrap();
    cond.set_enabled_statuses(StatusMask::REQUESTED_INCOMPATIBLE_QOS);
    assert!(
        !ws.wait(MATCH_TIMEOUT).unwrap().is_empty(),
        "no incompatible QoS"
    );
    assert_eq!(r.requested_incompatible_qos_status().total_count, 1);
    drop(best_effort);
    // The status condition is raised just before the listener is called: wait for the calls.
    let all = ["matched", "data", "deadline", "incompatible", "rejected"];
    let seen_all = || all.iter().all(|w| calls.lock().unwrap().contains(w));
    assert!(
        wait_until(Duration::from_secs(5), seen_all),
        "listener calls: {:?}",
        calls.lock().unwrap()
    );
    assert!(r.sample_rejected_status().total_count >= 1);
    assert_eq!(r.take().len(), 2, "max_samples_per_instance");
}

impl DynamicWriterListener for Calls {
    fn on_publication_matched(&self, _: &DynamicWriter, _: PublicationMatchedStatus) {
        self.0.lock().unwrap().push("matched");
    }
    fn on_offered_deadline_missed(&self, _: &DynamicWriter, _: DeadlineMissedStatus) {
        self.0.lock().unwrap().push("deadline");
    }
    fn on_offered_incompatible_qos(&self, _: &DynamicWriter, _: IncompatibleQosStatus) {
        self.0.lock().unwrap().push("incompatible");
    }
}

/// A dynamic writer's listener and status condition, against typed readers: publication matched (a reader
/// appears), offered deadline missed (the writer stops writing its instance), offered incompatible QoS (a
/// reader requesting a shorter deadline); `*_status` reset the counts and clear the condition.
#[test]
fn dynamic_writer_listener_and_status_condition() {
    let ty = shape_from_builder();
    let (p1, p2) = (participant(14), participant(14));
    let topic = p1
        .create_dynamic_topic("Square", ty.clone(), &TopicQos::default())
        .unwrap();
    let calls = std::sync::Arc::new(std::sync::Mutex::new(Vec::new()));
    let wq = DataWriterQos::builder()
        .reliability(reliable())
        .deadline(Duration::from_millis(100))
        .history(History::KeepAll)
        .build();
    let w = p1
        .create_publisher(&PublisherQos::default())
        .and_then(|p| {
            p.create_dynamic_writer_with_listener(
                &topic,
                &wq,
                Box::new(Calls(calls.clone())),
                StatusMask::all(),
            )
        })
        .unwrap();
    let cond = w.status_condition();
    cond.set_enabled_statuses(StatusMask::PUBLICATION_MATCHED);
    let ws = WaitSet::new();
    ws.attach_condition(cond.clone());
    let requested = |deadline| {
        DataReaderQos::builder()
            .reliability(reliable())
            .deadline(deadline)
            .history(History::KeepAll)
            .build()
    };
    let _r = reader::<ShapeType>(&p2, "Square", &requested(Duration::from_millis(200)));
    assert!(!ws.wait(MATCH_TIMEOUT).unwrap().is_empty(), "no match");
    let m = w.publication_matched_status();
    assert_eq!((m.current_count, m.total_count), (1, 1));
    assert!(!cond.trigger_value(), "reading the status clears it");
    assert_eq!(w.publication_matched_status().total_count_change, 0);
    w.write(&dynamic_shape(&ty, "RED", 1)).unwrap();
    cond.set_enabled_statuses(StatusMask::OFFERED_DEADLINE_MISSED);
    assert!(
        !ws.wait(Duration::from_secs(5)).unwrap().is_empty(),
        "no deadline"
    );
    let d = w.offered_deadline_missed_status();
    assert!(d.total_count >= 1);
    assert_ne!(
        d.last_instance_handle,
        InstanceHandle::NIL,
        "keyed instance"
    );
    // A reader requesting a 50 ms deadline cannot be served by a writer offering 100 ms.
    let _short = reader::<ShapeType>(&p2, "Square", &requested(Duration::from_millis(50)));
    cond.set_enabled_statuses(StatusMask::OFFERED_INCOMPATIBLE_QOS);
    assert!(
        !ws.wait(MATCH_TIMEOUT).unwrap().is_empty(),
        "no incompatible QoS"
    );
    let q = w.offered_incompatible_qos_status();
    assert_eq!(q.total_count, 1);
    assert_eq!(q.last_policy_id, Some(QosPolicyId::Deadline));
    assert_eq!(w.matched_readers().len(), 1);
    // The status condition is raised just before the listener is called: wait for the calls.
    let all = ["matched", "deadline", "incompatible"];
    let seen_all = || all.iter().all(|c| calls.lock().unwrap().contains(c));
    assert!(
        wait_until(Duration::from_secs(5), seen_all),
        "listener calls: {:?}",
        calls.lock().unwrap()
    );
}

/// GROUP presentation (coherent and ordered) across a typed and a dynamic endpoint of each side: the
/// publisher's coherent set spans its typed writer and its dynamic writer; the subscriber's access scope
/// holds back what arrives for its typed and its dynamic reader until `end_access`; and
/// `get_datareaders` lists the dynamic reader in the subscriber's sample order. Both count among their
/// publisher's and subscriber's entities until deleted.
#[test]
fn dynamic_endpoints_take_part_in_group_presentation() {
    let (p1, p2) = (participant(40), participant(40));
    let (wq, rq) = reliable_keep_all();
    let group = Presentation {
        access_scope: PresentationAccessScope::Group,
        coherent_access: true,
        ordered_access: true,
    };
    let publ = p1
        .create_publisher(&PublisherQos::builder().presentation(group).build())
        .unwrap();
    let sub = p2
        .create_subscriber(&SubscriberQos::builder().presentation(group).build())
        .unwrap();
    let ty = shape_from_builder();
    let tw = publ
        .create_datawriter(
            &p1.create_topic::<ShapeType>("Square", &TopicQos::default())
                .unwrap(),
            &wq,
        )
        .unwrap();
    let dw = publ
        .create_dynamic_writer(
            &p1.create_dynamic_topic("Circle", ty.clone(), &TopicQos::default())
                .unwrap(),
            &wq,
        )
        .unwrap();
    let tr = sub
        .create_datareader::<ShapeType, _>(
            &p2.create_topic::<ShapeType>("Square", &TopicQos::default())
                .unwrap(),
            &rq,
        )
        .unwrap();
    let dr = sub
        .create_dynamic_reader(
            &p2.create_dynamic_topic("Circle", ty.clone(), &TopicQos::default())
                .unwrap(),
            &rq,
        )
        .unwrap();
    assert!(wait_until(MATCH_TIMEOUT, || {
        tw.publication_matched_status().current_count == 1
            && dw.matched_readers().len() == 1
            && tr.subscription_matched_status().current_count == 1
            && dr.subscription_matched_status().current_count == 1
    }));
    let any = (
        SampleStateMask::ANY,
        ViewStateMask::ANY,
        InstanceStateMask::ANY,
    );
    let held = |r: &DynamicReader| r.read_states(any.0, any.1, any.2).len();

    // The access scope holds back a group set until it ends.
    sub.begin_access().unwrap();
    publ.begin_coherent_changes().unwrap();
    tw.write(&shape("RED", 1)).unwrap();
    dw.write(&dynamic_shape(&ty, "RED", 1)).unwrap();
    publ.end_coherent_changes().unwrap();
    tw.wait_for_acknowledgments(Duration::from_secs(10))
        .unwrap();
    dw.wait_for_acknowledgments(Duration::from_secs(10))
        .unwrap();
    assert_eq!((tr.sample_count(), held(&dr)), (0, 0));
    sub.end_access().unwrap();
    assert_eq!((tr.sample_count(), held(&dr)), (1, 1));
    tr.take().unwrap();
    dr.take();

    // Ordered access: the readers once per sample, in the order written, the dynamic one included.
    // (Outside a coherent set: a group set is stored writer by writer.)
    let writes = [(0, 2), (1, 2), (1, 3), (0, 3)];
    for &(w, x) in &writes {
        match w {
            0 => tw.write(&shape("RED", x)).unwrap(),
            _ => dw.write(&dynamic_shape(&ty, "RED", x)).unwrap(),
        }
    }
    assert!(wait_until(MATCH_TIMEOUT, || sub
        .get_datareaders(any.0, any.1, any.2)
        .unwrap()
        .len()
        == writes.len()));
    sub.begin_access().unwrap();
    let list = sub
        .get_datareaders(SampleStateMask::NOT_READ, any.1, any.2)
        .unwrap();
    sub.end_access().unwrap();
    let handles = [tr.instance_handle(), dr.instance_handle()];
    let want: Vec<InstanceHandle> = writes.iter().map(|&(w, _)| handles[w]).collect();
    assert_eq!(list, want);

    // Explicit deletion: the publisher and subscriber count their dynamic endpoints as children.
    let other = p1.create_publisher(&PublisherQos::default()).unwrap();
    assert!(matches!(
        other.delete_dynamic_writer(&dw),
        Err(DdsError::PreconditionNotMet(_))
    ));
    publ.delete_datawriter(&tw).unwrap();
    assert!(matches!(
        p1.delete_publisher(&publ),
        Err(DdsError::PreconditionNotMet(_))
    ));
    publ.delete_dynamic_writer(&dw).unwrap();
    assert!(matches!(
        dw.write(&dynamic_shape(&ty, "RED", 9)),
        Err(DdsError::AlreadyDeleted)
    ));
    p1.delete_publisher(&publ).unwrap();
    sub.delete_datareader(&tr).unwrap();
    sub.delete_dynamic_reader(&dr).unwrap();
    p2.delete_subscriber(&sub).unwrap();
}
