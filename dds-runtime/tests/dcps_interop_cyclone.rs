//! Scratch interop check against a real Cyclone DDS 11 peer (python `cyclonedds`), both directions.
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
    let t = p
        .create_topic::<ShapeType>("Square", &TopicQos::default())
        .unwrap();
    let w = p
        .create_publisher(&PublisherQos::default())
        .unwrap()
        .create_datawriter(&t, &tl_reliable_writer())
        .unwrap();
    let mut child = python(61, &["sub", "Square", "10", "dispose"]);
    assert!(
        wait_until(Duration::from_secs(20), || w
            .publication_matched_status()
            .current_count
            == 1),
        "no match with Cyclone"
    );
    for i in 0..10 {
        w.write(&shape("RED", i)).unwrap();
    }
    w.dispose(&shape("RED", 0)).unwrap();
    w.wait_for_acknowledgments(Duration::from_secs(10)).unwrap();
    let out = BufReader::new(child.stdout.take().unwrap());
    let lines: Vec<String> = out.lines().map_while(Result::ok).collect();
    let status = child.wait().unwrap();
    assert!(status.success(), "cyclone sub failed: {lines:?}");
    let xs: Vec<i64> = lines
        .iter()
        .filter(|l| l.contains("\"RED\""))
        .filter_map(|l| l.split("\"x\": ").nth(1)?.split(',').next()?.parse().ok())
        .collect();
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
