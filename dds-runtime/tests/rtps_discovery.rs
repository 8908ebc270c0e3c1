//! Discovery and matching through the simulated network.

mod rtps_support;

use std::time::Duration;

use dds_runtime::qos::*;
use dds_runtime::rtps::*;
use rtps_support::*;

fn reliable_writer() -> DataWriterQos {
    DataWriterQos::default()
}
fn reliable_reader() -> DataReaderQos {
    DataReaderQos::builder().reliability(Reliability::RELIABLE).build()
}

#[test]
fn two_participants_discover_and_match() {
    let mut sim = Sim::with_participants(1, Faults::NONE, 2);
    let now = sim.now;
    let w = sim.nodes[0].p.create_writer(now, WriterSpec::new("Square", "ShapeType", true, reliable_writer())).unwrap();
    let r = sim.nodes[1].p.create_reader(now, ReaderSpec::new("Square", "ShapeType", true, reliable_reader())).unwrap();
    let rg = sim.guid(1, r);
    let wg = sim.guid(0, w);
    assert!(sim.run_until(Duration::from_secs(2), |s| {
        s.nodes[0].p.writer_matches(w) == vec![rg] && s.nodes[1].p.reader_matches(r) == vec![wg]
    }));
    assert!(sim.elapsed() < Duration::from_millis(100), "discovery took {:?}", sim.elapsed());
    assert!(sim.has_event(0, |e| matches!(e, Event::ParticipantDiscovered(d) if d.guid_prefix == prefix(1))));
    assert!(sim.has_event(0, |e| *e == Event::PublicationMatched { writer: w, reader: rg, matched: true }));
    assert!(sim.has_event(1, |e| *e == Event::SubscriptionMatched { reader: r, writer: wg, matched: true }));

    let now = sim.now;
    sim.nodes[0].p.write(now, w, WriteChange::alive(vec![0, 1, 0, 0, 42, 0, 0, 0]).with_key_hash([7; 16])).unwrap();
    assert!(sim.run_until(Duration::from_secs(1), |s| s.has_event(1, |e| matches!(e, Event::Sample(_)))));
    let got = sim.take_samples(1, r);
    assert_eq!(got.len(), 1);
    assert_eq!(&got[0].payload[..], &[0, 1, 0, 0, 42, 0, 0, 0]);
    assert_eq!(got[0].key_hash, Some([7; 16]));
    assert_eq!(got[0].writer, wg);
}
