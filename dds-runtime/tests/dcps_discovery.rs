//! Two participants in one process find each other and match a writer with a reader.
mod dcps_util;

use std::time::Duration;

use dcps_util::*;
use dds_runtime::prelude::*;

#[test]
fn two_participants_discover_each_other_and_match() {
    let p1 = participant(11);
    let p2 = participant(11);
    assert_ne!(p1.guid_prefix(), p2.guid_prefix());
    assert_ne!(
        p1.transport().metatraffic_unicast(),
        p2.transport().metatraffic_unicast()
    );

    let found = wait_until(MATCH_TIMEOUT, || {
        p1.discovered_participants()
            .iter()
            .any(|d| d.guid_prefix == p2.guid_prefix())
            && p2
                .discovered_participants()
                .iter()
                .any(|d| d.guid_prefix == p1.guid_prefix())
    });
    assert!(
        found,
        "SPDP: {:?} / {:?}",
        p1.discovered_participants(),
        p2.discovered_participants()
    );

    let (w, r) = matched::<ShapeType>(
        &p1,
        &p2,
        "Square",
        &DataWriterQos::default(),
        &DataReaderQos::default(),
    );
    assert_eq!(w.matched_subscriptions().len(), 1);
    assert_eq!(r.matched_publications(), vec![w.instance_handle()]);

    // Deleting the writer unmatches it on the reader side.
    drop(w);
    assert!(wait_until(MATCH_TIMEOUT, || r
        .subscription_matched_status()
        .current_count
        == 0));
}

#[test]
fn unicast_peers_without_multicast() {
    require_netns();
    init_tracing();
    let build = || {
        DomainParticipant::builder()
            .domain_id(12)
            .interface("127.0.0.1")
            .multicast(false)
            .peers(["127.0.0.1"])
            .unwrap()
            .spdp_interval(Duration::from_millis(200))
            .build()
            .unwrap()
    };
    let p1 = build();
    let p2 = build();
    assert!(!p1.transport().multicast_enabled());
    assert_eq!(p1.transport().participant_index(), Some(0));
    assert_eq!(p2.transport().participant_index(), Some(1));
    assert!(wait_until(MATCH_TIMEOUT, || {
        p1.discovered_participants().len() == 1 && p2.discovered_participants().len() == 1
    }));
}
