//! Writer-side content filtering in the sans-I/O simulator, under loss: the writer evaluates each matched
//! reader's announced filter once per sample (here the test plays the typed layer, as `DataWriter` does),
//! and the core sends DATA only to the readers that accept it and GAP to the others. The RTPS readers here
//! apply no filter of their own, so what they deliver is exactly what the writer chose to send. A reader
//! that joins late receives the history as DATA (the writer had no verdict for it) and is filtered from
//! then on.

mod rtps_support;

use std::time::Duration;

use dds_runtime::cdr::{self, ByteOrder, XcdrVersion};
use dds_runtime::filter::ContentFilter;
use dds_runtime::qos::*;
use dds_runtime::rtps::discovery::ContentFilterProperty;
use dds_runtime::rtps::*;
use dds_runtime::DdsType;
use rtps_support::*;

#[derive(DdsType, Debug, Clone, PartialEq)]
#[dds(name = "M::Tick", final)]
struct Tick {
    i: u32,
    label: String,
}

fn payload(i: u32) -> Vec<u8> {
    let t = Tick {
        i,
        label: format!("t{i}"),
    };
    let mut out = Vec::new();
    cdr::serialize(&t, XcdrVersion::Xcdr1, ByteOrder::LittleEndian, &mut out).unwrap();
    out
}

fn indices(samples: &[ReceivedSample]) -> Vec<u32> {
    let mut v: Vec<u32> = samples
        .iter()
        .map(|s| cdr::deserialize::<Tick>(&s.payload).unwrap().i)
        .collect();
    v.sort_unstable();
    v
}

fn reader_spec(filter: Option<(&str, &str)>) -> ReaderSpec {
    let rq = DataReaderQos::builder()
        .reliability(Reliability::RELIABLE)
        .durability(Durability::TransientLocal)
        .history(History::KeepAll)
        .build();
    let mut spec = ReaderSpec::new("T", "M::Tick", false, rq);
    spec.content_filter = filter
        .map(|(e, p)| ContentFilterProperty::ddssql("T_filtered", "T", e, vec![p.to_string()]));
    spec
}

/// Writes sample `i`, rejected by the matched readers whose announced filter refuses it.
fn write(sim: &mut Sim, w: EntityId, i: u32) {
    let t = Tick {
        i,
        label: format!("t{i}"),
    };
    let p = &mut sim.nodes[0].p;
    let rejected: Vec<Guid> = p
        .writer_reader_filters(w)
        .into_iter()
        .filter(|(_, f)| {
            !ContentFilter::new(&f.filter_expression, &f.expression_parameters)
                .unwrap()
                .matches(&t)
        })
        .map(|(g, _)| g)
        .collect();
    let now = sim.now;
    p.write_filtered(now, w, WriteChange::alive(payload(i)), rejected)
        .unwrap();
}

/// A reliable, transient-local, keep-all writer: late joiners get its history.
fn writer_qos() -> DataWriterQos {
    DataWriterQos::builder()
        .reliability(Reliability::RELIABLE)
        .durability(Durability::TransientLocal)
        .history(History::KeepAll)
        .build()
}

#[test]
fn writer_skips_readers_whose_filter_rejects_and_filters_late_joiners_from_then_on() {
    for seed in 0..20 {
        let mut sim = Sim::with_participants(seed, Faults::lossy(0.2), 4);
        sim.faults_on_discovery = false;
        let now = sim.now;
        let wq = writer_qos();
        let w = sim.nodes[0]
            .p
            .create_writer(now, WriterSpec::new("T", "M::Tick", false, wq))
            .unwrap();
        let high = sim.nodes[1]
            .p
            .create_reader(now, reader_spec(Some(("i >= %0", "10"))))
            .unwrap();
        let all = sim.nodes[2]
            .p
            .create_reader(now, reader_spec(None))
            .unwrap();
        assert!(sim.run_until(Duration::from_secs(5), |s| s.nodes[0]
            .p
            .writer_matches(w)
            .len()
            == 2));
        assert_eq!(sim.nodes[0].p.writer_reader_filters(w).len(), 1);
        for i in 0..20 {
            write(&mut sim, w, i);
            sim.run_for(Duration::from_millis(5));
        }
        // A reader that joins late, filtering i < 5.
        let now = sim.now;
        let low = sim.nodes[3]
            .p
            .create_reader(now, reader_spec(Some(("i < %0", "5"))))
            .unwrap();
        assert!(sim.run_until(Duration::from_secs(5), |s| s.nodes[0]
            .p
            .writer_matches(w)
            .len()
            == 3));
        for i in 20..40 {
            write(&mut sim, w, i);
            sim.run_for(Duration::from_millis(5));
        }
        assert!(
            sim.run_until(Duration::from_secs(30), |s| s.nodes[0].p.is_acknowledged(w)),
            "seed {seed}: rejecting readers acknowledge through the GAPs"
        );
        sim.run_for(Duration::from_millis(200));
        assert_eq!(
            indices(&sim.take_samples(1, high)),
            (10..40).collect::<Vec<_>>(),
            "seed {seed}: the filtering reader gets only what passes"
        );
        assert_eq!(
            indices(&sim.take_samples(2, all)),
            (0..40).collect::<Vec<_>>(),
            "seed {seed}: the reader without a filter gets everything"
        );
        assert_eq!(
            indices(&sim.take_samples(3, low)),
            (0..20).collect::<Vec<_>>(),
            "seed {seed}: the late joiner gets the history unfiltered, then nothing (no new i < 5)"
        );
    }
}

/// A key-only change (dispose, unregister) passes every filter, in both wire forms: the serialized key (a
/// reader of ours) and the key hash alone (a Fast DDS reader). Even when the caller names readers as
/// rejecting it, both readers get it, as DATA, while a sample they reject reaches neither.
#[test]
fn key_only_changes_reach_every_filtering_reader_in_both_wire_forms() {
    let mut sim = Sim::new(5, Faults::NONE);
    sim.add(config(0));
    sim.add(config(1).vendor_id(VendorId::FASTDDS));
    sim.add(config(2));
    let now = sim.now;
    let wq = writer_qos();
    let w = sim.nodes[0]
        .p
        .create_writer(now, WriterSpec::new("T", "M::Tick", true, wq))
        .unwrap();
    let spec = || {
        let mut s = reader_spec(Some(("i >= %0", "10")));
        s.keyed = true;
        s
    };
    let fast = sim.nodes[1].p.create_reader(now, spec()).unwrap();
    let ours = sim.nodes[2].p.create_reader(now, spec()).unwrap();
    assert!(sim.run_until(Duration::from_secs(5), |s| s.nodes[0]
        .p
        .writer_matches(w)
        .len()
        == 2));
    let both: Vec<Guid> = sim.nodes[0]
        .p
        .writer_reader_filters(w)
        .into_iter()
        .map(|(g, _)| g)
        .collect();
    assert_eq!(both.len(), 2);
    let key = [7u8; 16];
    let write = |sim: &mut Sim, ch: WriteChange| {
        let now = sim.now;
        let ch = ch.with_key_hash(key);
        sim.nodes[0]
            .p
            .write_filtered(now, w, ch, both.clone())
            .unwrap();
        sim.run_for(Duration::from_millis(50));
    };
    write(&mut sim, WriteChange::alive(payload(1)));
    write(
        &mut sim,
        WriteChange::alive(vec![0, 1, 0, 0, 7, 0, 0, 0]).with_kind(ChangeKind::Dispose),
    );
    write(
        &mut sim,
        WriteChange::alive(vec![0, 1, 0, 0, 7, 0, 0, 0]).with_kind(ChangeKind::Unregister),
    );
    assert!(sim.run_until(Duration::from_secs(10), |s| s.nodes[0].p.is_acknowledged(w)));
    for (node, r) in [(1, fast), (2, ours)] {
        let got: Vec<(ChangeKind, Option<[u8; 16]>)> = sim
            .take_samples(node, r)
            .iter()
            .map(|s| (s.kind, s.key_hash))
            .collect();
        assert_eq!(
            got,
            [
                (ChangeKind::Dispose, Some(key)),
                (ChangeKind::Unregister, Some(key))
            ],
            "node {node}: the rejected sample is skipped, the key-only changes arrive"
        );
    }
}
