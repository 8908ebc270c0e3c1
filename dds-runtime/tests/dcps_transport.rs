//! Transport: participant index probing, ephemeral ports, multicast on the selected interface.
mod dcps_util;

use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{Arc, Mutex};
use std::time::Duration;

use dcps_util::*;
use dds_runtime::config::{Config, InterfaceSelection, ParticipantIndex};
use dds_runtime::rtps::discovery::ports;
use dds_runtime::transport::{Channel, Datagram, ReceivePath, UdpTransport};

fn cfg(domain: u32, index: ParticipantIndex) -> Config {
    Config {
        domain_id: domain,
        interface: InterfaceSelection::Name("lo".into()),
        participant_index: index,
        ..Config::default()
    }
}

#[test]
fn auto_index_probes_and_multicast_reaches_every_participant() {
    require_netns();
    let a = UdpTransport::bind(&cfg(51, ParticipantIndex::Auto)).unwrap();
    let b = UdpTransport::bind(&cfg(51, ParticipantIndex::Auto)).unwrap();
    let c = UdpTransport::bind(&cfg(51, ParticipantIndex::None)).unwrap();
    assert_eq!(a.participant_index(), Some(0));
    assert_eq!(b.participant_index(), Some(1));
    assert_eq!(c.participant_index(), None);
    assert_eq!(
        a.metatraffic_unicast().port(),
        ports::metatraffic_unicast(51, 0).unwrap()
    );
    assert_eq!(b.user_unicast().port(), ports::user_unicast(51, 1).unwrap());
    assert_eq!(
        a.metatraffic_unicast().ip(),
        std::net::IpAddr::from([127, 0, 0, 1])
    );
    assert!(Config {
        participant_index: ParticipantIndex::Fixed(0),
        ..cfg(51, ParticipantIndex::Auto)
    }
    .validate()
    .is_ok());
    assert!(
        UdpTransport::bind(&cfg(51, ParticipantIndex::Fixed(0))).is_err(),
        "index 0 is taken"
    );

    let counts: Vec<Arc<AtomicUsize>> = (0..3).map(|_| Arc::new(AtomicUsize::new(0))).collect();
    for (t, n) in [&a, &b, &c].into_iter().zip(&counts) {
        let n = n.clone();
        t.start(Arc::new(move |ch, batch: &[Datagram<'_>]| {
            for d in batch {
                if ch == Channel::SpdpMulticast && d.data == b"hello" {
                    n.fetch_add(1, Ordering::SeqCst);
                }
            }
        }))
        .unwrap();
    }
    a.send_to(b"hello", a.spdp_multicast().unwrap());
    assert!(wait_until(Duration::from_secs(5), || counts
        .iter()
        .all(|n| n.load(Ordering::SeqCst) == 1)));

    // Unicast to the metatraffic port reaches only that participant.
    let got = Arc::new(AtomicUsize::new(0));
    drop(c);
    let d = UdpTransport::bind(&cfg(51, ParticipantIndex::None)).unwrap();
    let g = got.clone();
    d.start(Arc::new(move |ch, batch: &[Datagram<'_>]| {
        if ch == Channel::MetaUnicast {
            g.fetch_add(batch.len(), Ordering::SeqCst);
        }
    }))
    .unwrap();
    a.send_to(b"x", d.metatraffic_unicast());
    assert!(wait_until(Duration::from_secs(5), || got
        .load(Ordering::SeqCst)
        == 1));
    d.shutdown();
    a.shutdown();
    b.shutdown();
}

#[test]
fn multicast_off_binds_no_group_socket() {
    require_netns();
    let mut c = cfg(52, ParticipantIndex::Auto);
    c.multicast = false;
    let t = UdpTransport::bind(&c).unwrap();
    assert!(t.spdp_multicast().is_none());
    assert!(!t.multicast_enabled());
}

/// Sends `n` numbered datagrams to a transport reading its sockets `path`'s way; each arrives once, whole,
/// from the sender: the first from its metatraffic socket, the rest from there or, once the destination is
/// busy, from the one socket the sender connected to it.
fn receives_every_datagram(path: ReceivePath, domain: u32, spin: Duration) {
    let rx = UdpTransport::bind(&Config {
        receive_spin: spin,
        ..cfg(domain, ParticipantIndex::None)
    })
    .unwrap();
    let tx = UdpTransport::bind(&cfg(domain, ParticipantIndex::None)).unwrap();
    let got = Arc::new(Mutex::new(Vec::new()));
    let g = got.clone();
    let from = tx.metatraffic_unicast().port();
    rx.start_with(
        Arc::new(move |ch, batch: &[Datagram<'_>]| {
            let mut g = g.lock().unwrap();
            g.extend(batch.iter().map(|d| (ch, d.from.port(), d.data.to_vec())));
        }),
        path,
    )
    .unwrap();
    // Bursts of 20 small datagrams, so that the batched path reads several per call and no socket buffer
    // overflows.
    let n = 200u16;
    for burst in (0..n).collect::<Vec<_>>().chunks(20) {
        for &i in burst {
            let payload: Vec<u8> = i.to_be_bytes().repeat(usize::from(i % 50) + 1);
            tx.send_to(&payload, rx.user_unicast());
        }
        let sent = usize::from(burst[burst.len() - 1] + 1);
        assert!(wait_until(Duration::from_secs(5), || got
            .lock()
            .unwrap()
            .len()
            >= sent));
    }
    let mut got = got.lock().unwrap().clone();
    assert_eq!(got.len(), usize::from(n));
    got.sort_by_key(|(_, _, d)| u16::from_be_bytes([d[0], d[1]]));
    let busy = got.iter().map(|(_, p, _)| *p).find(|p| *p != from);
    assert_eq!(got[0].1, from);
    for (i, (ch, port, d)) in (0..n).zip(&got) {
        assert_eq!(*ch, Channel::UserUnicast);
        assert!(
            *port == from || Some(*port) == busy,
            "datagram {i} from port {port}"
        );
        assert_eq!(d.len(), 2 * (usize::from(i % 50) + 1));
        assert_eq!(d[..2], i.to_be_bytes());
    }
    assert_eq!(rx.stats().received.load(Ordering::SeqCst), u64::from(n));
    rx.shutdown();
    tx.shutdown();
}

#[test]
fn portable_receive_path_delivers_every_datagram() {
    require_netns();
    assert_eq!(ReceivePath::OneByOne.effective(), ReceivePath::OneByOne);
    receives_every_datagram(ReceivePath::OneByOne, 53, Duration::ZERO);
}

#[test]
fn batched_receive_path_delivers_every_datagram() {
    require_netns();
    receives_every_datagram(ReceivePath::Batched, 54, Duration::ZERO);
}

/// With busy polling on, the receive thread polls between bursts (they follow each other within the
/// window) and still hands over every datagram once; and the portable path, which cannot poll, too.
#[test]
fn polling_receive_paths_deliver_every_datagram() {
    require_netns();
    let spin = Duration::from_millis(20);
    receives_every_datagram(ReceivePath::Batched, 55, spin);
    receives_every_datagram(ReceivePath::OneByOne, 56, spin);
}

/// Polling with a window short enough (50 µs) that the receive thread often finds nothing, polls shorter
/// (`transport/poll.rs`) and waits in the kernel again between bursts: every datagram still arrives once.
#[test]
fn short_polling_windows_deliver_every_datagram() {
    require_netns();
    receives_every_datagram(ReceivePath::Batched, 110, Duration::from_micros(50));
}
