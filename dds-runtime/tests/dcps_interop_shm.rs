//! A mixed reader set against a real peer (feature `shm`): one writer of ours, a reader of ours in
//! another participant on this host (shared memory) and a Cyclone DDS 11 reader (python `cyclonedds`,
//! UDP), both getting every sample, with the disposal. Ignored by default (needs python3 + cyclonedds);
//! runs in the `interop` profile:
//! `scripts/isolated cargo nextest run -p dds-runtime -F shm --profile interop --test dcps_interop_shm --run-ignored all`.
mod dcps_util;

use std::process::{Command, Stdio};
use std::sync::atomic::Ordering;
use std::time::Duration;

use dcps_util::*;
use dds_runtime::prelude::*;

const CYCLONE_URI: &str = r#"<CycloneDDS><Domain id="any"><General><Interfaces><NetworkInterface name="lo" multicast="true"/></Interfaces><AllowMulticast>true</AllowMulticast></General></Domain></CycloneDDS>"#;

#[test]
#[ignore = "needs python3 with cyclonedds; run in the interop profile"]
fn one_writer_to_a_shared_memory_reader_and_a_cyclone_udp_reader() {
    let domain = 65;
    let with_shm = Config {
        interface: dds_runtime::config::InterfaceSelection::Name("lo".into()),
        shm: true,
        ..Config::default()
    };
    let p = participant_with(domain, with_shm.clone());
    let q = participant_with(domain, with_shm);
    let wq = DataWriterQos::builder()
        .reliability(reliable())
        .durability(Durability::TransientLocal)
        .history(History::KeepLast(100))
        .build();
    let rq = DataReaderQos::builder()
        .reliability(reliable())
        .durability(Durability::TransientLocal)
        .history(History::KeepLast(100))
        .build();
    let w = writer::<ShapeType>(&p, "Square", &wq);
    let ours = reader::<ShapeType>(&q, "Square", &rq);
    let script = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/dcps_util/cyclone_shapes.py"
    );
    let mut cyclone = Command::new("python3")
        .args([script, "sub", "Square", "10", "dispose"])
        .env("CYCLONEDDS_URI", CYCLONE_URI)
        .env("DDS_DOMAIN_ID", domain.to_string())
        .stdout(Stdio::piped())
        .stderr(Stdio::inherit())
        .spawn()
        .expect("python3 with cyclonedds");
    assert!(
        wait_until(Duration::from_secs(20), || w
            .publication_matched_status()
            .current_count
            == 2),
        "writer matched {:?}",
        w.publication_matched_status()
    );
    let sent = || p.transport_stats().sent.load(Ordering::Relaxed);
    let before = sent();
    for i in 0..10 {
        w.write(&shape("RED", i)).unwrap();
    }
    w.dispose(&shape("RED", 0)).unwrap();
    w.wait_for_acknowledgments(Duration::from_secs(10)).unwrap();
    // Our reader took shared memory: the 11 changes went out as datagrams once (to Cyclone), not twice.
    let during = sent() - before;
    assert!(
        during < 22,
        "{during} datagrams for 11 changes (both readers on UDP: at least 22)"
    );
    // Read, not taken: every sample of the instance shows its state, disposed once the disposal arrived.
    let (mut xs, mut disposed) = (Vec::new(), false);
    wait_until(MATCH_TIMEOUT, || {
        let got = ours.read().unwrap();
        xs = got
            .iter()
            .filter_map(|s| s.data.as_ref().map(|d| d.x))
            .collect();
        disposed = got
            .iter()
            .any(|s| s.info.instance_state == InstanceState::NotAliveDisposed);
        xs.len() >= 10 && disposed
    });
    assert_eq!(xs, (0..10).collect::<Vec<_>>());
    assert!(disposed, "our reader did not see the disposal");
    let (xs, disposed, lines) = cyclone_sub_result(&mut cyclone);
    assert_eq!(xs, (0..10).collect::<Vec<_>>(), "cyclone got {lines:?}");
    assert!(disposed, "{lines:?}");
}
