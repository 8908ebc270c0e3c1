//! Multicast user data and IPv6 between our own participants over real sockets (run inside
//! `scripts/isolated`): readers in several participants on one multicast group get every sample of a
//! writer that sends it once; two participants talk over `::1` with IPv6 locators.
mod dcps_util;

use std::time::Duration;

use dcps_util::*;
use dds_runtime::config::{AddressFamily, Config, InterfaceSelection, MulticastData};
use dds_runtime::prelude::*;

fn multicast_data_config() -> Config {
    Config {
        interface: InterfaceSelection::Name("lo".into()),
        multicast_data: MulticastData::On,
        ..Config::default()
    }
}

/// Writes `n` shapes and checks that every reader takes all of them, in order.
fn exchange(w: &DataWriter<ShapeType>, readers: &[DataReader<ShapeType>], n: i32) {
    for i in 0..n {
        w.write(&shape("GREEN", i)).unwrap();
    }
    w.wait_for_acknowledgments(Duration::from_secs(10)).unwrap();
    for r in readers {
        let got = take_xs(r, n as usize, Duration::from_secs(10));
        assert_eq!(got, (0..n).collect::<Vec<_>>());
    }
}

#[test]
fn readers_on_a_multicast_group_get_every_sample() {
    // The writer's participant is set up through the builder, the readers' through `Config`.
    let pw = DomainParticipant::builder()
        .domain_id(81)
        .interface("lo")
        .multicast_data(MulticastData::On)
        .ignore_env()
        .build()
        .unwrap();
    let prs: Vec<_> = (0..3)
        .map(|_| participant_with(81, multicast_data_config()))
        .collect();
    let (wq, rq) = reliable_keep_all();
    let w = writer::<ShapeType>(&pw, "McastSquare", &wq);
    let readers: Vec<_> = prs
        .iter()
        .map(|p| reader::<ShapeType>(p, "McastSquare", &rq))
        .collect();
    assert!(wait_until(MATCH_TIMEOUT, || w
        .publication_matched_status()
        .current_count
        == 3));
    exchange(&w, &readers, 200);
}

#[test]
fn ipv6_loopback_unicast_discovery_and_data() {
    let v6 = || Config {
        transport: AddressFamily::Ipv6,
        interface: InterfaceSelection::parse("::1"),
        // IPv6 multicast does not loop back over `lo`: discovery by unicast peers.
        multicast: false,
        peers: vec![dds_runtime::config::Peer::parse("::1").unwrap()],
        ..Config::default()
    };
    // One participant through the builder, the other through `Config`.
    let pw = DomainParticipant::builder()
        .domain_id(82)
        .transport(AddressFamily::Ipv6)
        .interface("::1")
        .multicast(false)
        .peers(["::1"])
        .unwrap()
        .ignore_env()
        .build()
        .unwrap();
    let pr = participant_with(82, v6());
    let (wq, rq) = reliable_keep_all();
    let (w, r) = matched::<ShapeType>(&pw, &pr, "V6Square", &wq, &rq);
    exchange(&w, &[r], 50);
}
