//! Scratch interop check against a real Cyclone DDS 11 peer (python `cyclonedds`), both directions, and
//! content filtering with Cyclone (which has no SQL filters) as a plain writer and as a plain reader, and
//! dynamic writers and readers (features `idl` and `json`) in both directions.
//! Ignored by default (needs python3 + cyclonedds): run with
//! `scripts/isolated cargo test -p dds-runtime --test dcps_interop_cyclone -- --ignored`.
mod dcps_util;

use std::io::{BufRead, BufReader};
use std::process::{Child, Command, Stdio};
use std::time::Duration;

use dcps_util::*;
use dds_runtime::prelude::*;

const CYCLONE_URI: &str = r#"<CycloneDDS><Domain id="any"><General><Interfaces><NetworkInterface name="lo" multicast="true"/></Interfaces><AllowMulticast>true</AllowMulticast></General></Domain></CycloneDDS>"#;

fn python(domain: u32, args: &[&str]) -> Child {
    let script = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/dcps_util/cyclone_shapes.py"
    );
    Command::new("python3")
        .arg(script)
        .args(args)
        .env("CYCLONEDDS_URI", CYCLONE_URI)
        .env("DDS_DOMAIN_ID", domain.to_string())
        .stdout(Stdio::piped())
        .stderr(Stdio::inherit())
        .spawn()
        .expect("python3 with cyclonedds")
}

/// A transient-local reliable writer of "Square" on `p`.
fn square_writer(p: &DomainParticipant) -> DataWriter<ShapeType> {
    let t = p
        .create_topic::<ShapeType>("Square", &TopicQos::default())
        .unwrap();
    p.create_publisher(&PublisherQos::default())
        .unwrap()
        .create_datawriter(&t, &tl_reliable_writer())
        .unwrap()
}

/// Writes RED x = 0..10 and disposes it; returns the x values the Cyclone subscriber `child` printed, and
/// all its lines.
fn write_red_to_cyclone(w: &DataWriter<ShapeType>, mut child: Child) -> (Vec<i64>, Vec<String>) {
    for i in 0..10 {
        w.write(&shape("RED", i)).unwrap();
    }
    w.dispose(&shape("RED", 0)).unwrap();
    w.wait_for_acknowledgments(Duration::from_secs(10)).unwrap();
    let out = BufReader::new(child.stdout.take().unwrap());
    let lines: Vec<String> = out.lines().map_while(Result::ok).collect();
    let status = child.wait().unwrap();
    assert!(status.success(), "cyclone sub failed: {lines:?}");
    let xs = lines
        .iter()
        .filter(|l| l.contains("\"RED\""))
        .filter_map(|l| l.split("\"x\": ").nth(1)?.split(',').next()?.parse().ok())
        .collect();
    (xs, lines)
}

fn tl_reliable_writer() -> DataWriterQos {
    DataWriterQos::builder()
        .reliability(reliable())
        .durability(Durability::TransientLocal)
        .history(History::KeepLast(100))
        .build()
}

#[test]
#[ignore = "needs python3 with cyclonedds; run explicitly"]
fn rust_writer_to_cyclone_reader() {
    let p = participant(61);
    let w = square_writer(&p);
    let child = python(61, &["sub", "Square", "10", "dispose"]);
    assert!(
        wait_until(Duration::from_secs(20), || w
            .publication_matched_status()
            .current_count
            == 1),
        "no match with Cyclone"
    );
    let (xs, lines) = write_red_to_cyclone(&w, child);
    assert_eq!(xs, (0..10).collect::<Vec<_>>(), "{lines:?}");
    assert!(
        lines.iter().any(|l| l.contains("\"disposed\": true")),
        "no dispose seen by Cyclone: {lines:?}"
    );
}

#[test]
#[ignore = "needs python3 with cyclonedds; run explicitly"]
fn cyclone_writer_to_rust_reader() {
    let p = participant(62);
    let t = p
        .create_topic::<ShapeType>("Circle", &TopicQos::default())
        .unwrap();
    let rq = DataReaderQos::builder()
        .reliability(reliable())
        .durability(Durability::TransientLocal)
        .history(History::KeepLast(100))
        .build();
    let r = p
        .create_subscriber(&SubscriberQos::default())
        .unwrap()
        .create_datareader(&t, &rq)
        .unwrap();
    let mut child = python(62, &["pub", "Circle", "BLUE", "10"]);
    let mut got = Vec::new();
    let mut disposed = false;
    wait_until(Duration::from_secs(25), || {
        for s in r.take().unwrap() {
            match s.data {
                Some(d) => got.push(d),
                None => disposed |= s.info.instance_state == InstanceState::NotAliveDisposed,
            }
        }
        got.len() >= 10 && disposed
    });
    let status = child.wait().unwrap();
    assert!(status.success());
    assert_eq!(
        got.iter().map(|d| d.x).collect::<Vec<_>>(),
        (0..10).collect::<Vec<_>>()
    );
    assert!(got
        .iter()
        .all(|d| d.color == "BLUE" && d.y == 2 * d.x && d.shapesize == 30));
    assert!(
        disposed,
        "dispose from Cyclone not seen as NOT_ALIVE_DISPOSED"
    );
}

fn tl_reliable_reader() -> DataReaderQos {
    DataReaderQos::builder()
        .reliability(reliable())
        .durability(Durability::TransientLocal)
        .history(History::KeepLast(100))
        .build()
}

#[test]
#[ignore = "needs python3 with cyclonedds; run explicitly"]
fn cyclone_writer_to_rust_content_filtered_reader() {
    let p = participant(63);
    let t = p
        .create_topic::<ShapeType>("Triangle", &TopicQos::default())
        .unwrap();
    let cft = p
        .create_content_filtered_topic(
            "Triangle_filtered",
            &t,
            "x >= %0 AND color = 'BLUE'",
            &["5"],
        )
        .unwrap();
    let r = p
        .create_subscriber(&SubscriberQos::default())
        .unwrap()
        .create_datareader(&cft, &tl_reliable_reader())
        .unwrap();
    let mut child = python(63, &["pub", "Triangle", "BLUE", "10"]);
    let mut xs = Vec::new();
    let mut disposed = false;
    wait_until(Duration::from_secs(25), || {
        for s in r.take().unwrap() {
            match s.data {
                Some(d) => xs.push(d.x),
                None => disposed |= s.info.instance_state == InstanceState::NotAliveDisposed,
            }
        }
        xs.len() >= 5 && disposed
    });
    let status = child.wait().unwrap();
    assert!(
        status.success(),
        "Cyclone writer did not match our filtering reader"
    );
    assert_eq!(xs, (5..10).collect::<Vec<_>>());
    assert!(disposed, "the dispose passes the filter's instance");
}

#[test]
#[ignore = "needs python3 with cyclonedds; run explicitly"]
fn rust_writer_filters_for_our_reader_while_cyclone_gets_everything() {
    let p = participant(64);
    let w = square_writer(&p);
    // Our filtering reader in another participant, so that the writer filters for it on the wire.
    let p2 = participant(64);
    let t2 = p2
        .create_topic::<ShapeType>("Square", &TopicQos::default())
        .unwrap();
    let cft = p2
        .create_content_filtered_topic("Square_low", &t2, "x < %0", &["3"])
        .unwrap();
    let r = p2
        .create_subscriber(&SubscriberQos::default())
        .unwrap()
        .create_datareader(&cft, &tl_reliable_reader())
        .unwrap();
    let child = python(64, &["sub", "Square", "10", "dispose"]);
    assert!(
        wait_until(Duration::from_secs(20), || w
            .publication_matched_status()
            .current_count
            == 2),
        "the writer did not match both readers"
    );
    let (cyclone_xs, lines) = write_red_to_cyclone(&w, child);
    assert_eq!(cyclone_xs, (0..10).collect::<Vec<_>>(), "{lines:?}");
    let mut ours = take_xs_until(&r, 3);
    std::thread::sleep(Duration::from_millis(200));
    ours.extend(take_xs_until(&r, 0));
    assert_eq!(ours, [0, 1, 2]);
}

/// The `x` of the valid samples `r` holds, taken until there are at least `n` (or 5 s passed).
fn take_xs_until(r: &DataReader<ShapeType>, n: usize) -> Vec<i32> {
    let mut xs = Vec::new();
    wait_until(Duration::from_secs(5), || {
        xs.extend(
            r.take()
                .unwrap()
                .into_iter()
                .filter_map(|s| s.data.map(|d| d.x)),
        );
        xs.len() >= n
    });
    xs
}

/// `write_owned`: our reader in the writer's participant gets the samples themselves, Cyclone gets them
/// serialized (the writer has a wire reader, so the bytes are made with the write).
#[test]
#[ignore = "needs python3 with cyclonedds; run explicitly"]
fn typed_writes_reach_a_local_reader_and_cyclone() {
    let p = participant(69);
    let w = square_writer(&p);
    let t = p
        .create_topic::<ShapeType>("Square", &TopicQos::default())
        .unwrap();
    let r = p
        .create_subscriber(&SubscriberQos::default())
        .unwrap()
        .create_datareader(&t, &tl_reliable_reader())
        .unwrap();
    let mut child = python(69, &["sub", "Square", "10", "dispose"]);
    assert!(
        wait_until(Duration::from_secs(20), || w
            .publication_matched_status()
            .current_count
            == 2),
        "the writer did not match both readers"
    );
    for i in 0..10 {
        w.write_owned(shape("RED", i)).unwrap();
    }
    w.dispose(&shape("RED", 0)).unwrap();
    w.wait_for_acknowledgments(Duration::from_secs(10)).unwrap();
    let (xs, disposed, lines) = cyclone_sub_result(&mut child);
    assert_eq!(xs, (0..10).collect::<Vec<_>>(), "{lines:?}");
    assert!(disposed, "no dispose seen by Cyclone: {lines:?}");
    assert_eq!(take_xs_until(&r, 10), (0..10).collect::<Vec<_>>());
}

/// The shapes type as a dynamic type, from IDL text (as `dds subscribe --idl` builds it).
#[cfg(all(feature = "idl", feature = "json"))]
fn dynamic_shape_type() -> dds_runtime::xtypes::dynamic::DynamicType {
    let idl =
        "@appendable struct ShapeType { @key string color; long x; long y; long shapesize; };";
    dds_runtime::xtypes::dynamic::types_from_idl("shape.idl", idl)
        .unwrap()
        .remove("ShapeType")
        .unwrap()
}

#[cfg(all(feature = "idl", feature = "json"))]
#[test]
#[ignore = "needs python3 with cyclonedds; run explicitly"]
fn dynamic_writer_to_cyclone_reader() {
    use dds_runtime::xtypes::dynamic::DynamicData;
    let p = participant(63);
    let ty = dynamic_shape_type();
    let t = p
        .create_dynamic_topic("Square", ty.clone(), &TopicQos::default())
        .unwrap();
    let w = p
        .create_publisher(&PublisherQos::default())
        .and_then(|publ| publ.create_dynamic_writer(&t, &tl_reliable_writer()))
        .unwrap();
    let mut child = python(63, &["sub", "Square", "10", "dispose"]);
    assert!(
        w.wait_for_readers(1, Duration::from_secs(20)),
        "no match with Cyclone"
    );
    for i in 0..10 {
        let j = serde_json::json!({"color": "RED", "x": i, "y": 2 * i, "shapesize": 30});
        w.write(&DynamicData::from_json(&ty, &j).unwrap()).unwrap();
    }
    w.dispose(&DynamicData::from_json(&ty, &serde_json::json!({"color": "RED"})).unwrap())
        .unwrap();
    w.wait_for_acknowledgments(Duration::from_secs(10)).unwrap();
    let (xs, disposed, lines) = cyclone_sub_result(&mut child);
    assert_eq!(xs, (0..10).collect::<Vec<_>>(), "{lines:?}");
    assert!(disposed, "no dispose seen by Cyclone: {lines:?}");
}

#[cfg(all(feature = "idl", feature = "json"))]
#[test]
#[ignore = "needs python3 with cyclonedds; run explicitly"]
fn cyclone_writer_to_dynamic_reader() {
    use dds_runtime::rtps::ChangeKind;
    use dds_runtime::xtypes::dynamic::Value;
    let p = participant(64);
    let t = p
        .create_dynamic_topic("Circle", dynamic_shape_type(), &TopicQos::default())
        .unwrap();
    let r = p
        .create_subscriber(&SubscriberQos::default())
        .and_then(|s| s.create_dynamic_reader(&t, &tl_reliable_reader()))
        .unwrap();
    let mut child = python(64, &["pub", "Circle", "BLUE", "10"]);
    let (mut xs, mut disposed) = (Vec::new(), false);
    wait_until(Duration::from_secs(25), || {
        r.wait_for_data(Duration::from_millis(100));
        for s in r.take() {
            match (s.kind, s.data) {
                (ChangeKind::Alive, Some(d)) => {
                    assert_eq!(d.get("color"), Some(&Value::String("BLUE".into())));
                    if let (Some(Value::Int32(x)), Some(Value::Int32(y))) = (d.get("x"), d.get("y"))
                    {
                        assert_eq!(*y, 2 * *x);
                        xs.push(*x);
                    }
                }
                (k, _) => {
                    disposed |= matches!(k, ChangeKind::Dispose | ChangeKind::DisposeUnregister)
                }
            }
        }
        xs.len() >= 10 && disposed
    });
    assert!(child.wait().unwrap().success());
    assert_eq!(xs, (0..10).collect::<Vec<_>>());
    assert!(disposed, "dispose from Cyclone not seen");
}

/// A Cyclone `ShapeType` writer and a dynamic reader of another type name, `Shapes::Reduced` (`color`, `x`),
/// assignable from it: matched by assignability (both sides resolve the other's type through TypeLookup), and
/// the reader reads Cyclone's samples in its own type.
#[cfg(all(feature = "idl", feature = "json"))]
#[test]
#[ignore = "needs python3 with cyclonedds; run explicitly"]
fn cyclone_writer_to_assignable_dynamic_reader() {
    use dds_runtime::xtypes::dynamic::{types_from_idl, Value};
    std::env::set_var(dds_runtime::xtypes::ANNOUNCE_ENV, "on");
    let p = participant(66);
    let idl = "module Shapes { @appendable struct Reduced { @key string color; long x; }; };";
    let ty = types_from_idl("reduced.idl", idl)
        .unwrap()
        .remove("Shapes::Reduced")
        .unwrap();
    let t = p
        .create_dynamic_topic("Triangle", ty, &TopicQos::default())
        .unwrap();
    let r = p
        .create_subscriber(&SubscriberQos::default())
        .and_then(|s| s.create_dynamic_reader(&t, &tl_reliable_reader()))
        .unwrap();
    let mut child = python(66, &["pub", "Triangle", "GREEN", "10"]);
    let mut xs = Vec::new();
    wait_until(Duration::from_secs(25), || {
        r.wait_for_data(Duration::from_millis(100));
        for s in r.take() {
            if let Some(d) = s
                .data
                .filter(|_| s.kind == dds_runtime::rtps::ChangeKind::Alive)
            {
                assert_eq!(d.get("color"), Some(&Value::String("GREEN".into())));
                if let Some(Value::Int32(x)) = d.get("x") {
                    xs.push(*x);
                }
            }
        }
        xs.len() >= 10
    });
    assert!(
        child.wait().unwrap().success(),
        "Cyclone's writer did not match"
    );
    assert_eq!(xs, (0..10).collect::<Vec<_>>());
}

/// A Cyclone `ShapeType` writer and a dynamic reader of a `ShapeType` whose `x` is a string: same name, not
/// assignable. Once the writer's type has arrived through TypeLookup the pair is reported incompatible
/// (`TypeConsistencyEnforcement`) and nothing is read.
#[cfg(all(feature = "idl", feature = "json"))]
#[test]
#[ignore = "needs python3 with cyclonedds; run explicitly"]
fn cyclone_writer_and_unassignable_dynamic_reader_are_incompatible() {
    use dds_runtime::xtypes::dynamic::types_from_idl;
    std::env::set_var(dds_runtime::xtypes::ANNOUNCE_ENV, "on");
    let p = participant(67);
    let idl =
        "@appendable struct ShapeType { @key string color; string x; long y; long shapesize; };";
    let ty = types_from_idl("bad.idl", idl)
        .unwrap()
        .remove("ShapeType")
        .unwrap();
    let t = p
        .create_dynamic_topic("Octagon", ty, &TopicQos::default())
        .unwrap();
    let r = p
        .create_subscriber(&SubscriberQos::default())
        .and_then(|s| s.create_dynamic_reader(&t, &tl_reliable_reader()))
        .unwrap();
    let mut child = python(67, &["pub", "Octagon", "RED", "10"]);
    let reported = wait_until(Duration::from_secs(15), || {
        r.requested_incompatible_qos_status().total_count >= 1
    });
    let _ = child.kill();
    let _ = child.wait();
    assert!(reported, "no incompatibility reported");
    assert_eq!(
        r.requested_incompatible_qos_status().last_policy_id,
        Some(QosPolicyId::TypeConsistencyEnforcement)
    );
    assert!(r.matched_writers().is_empty());
    assert!(
        r.take().is_empty(),
        "samples of an unassignable type were read"
    );
}
