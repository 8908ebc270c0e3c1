//! Typed writes (`write_owned`, `write_shared`) through the DCPS API (run inside `scripts/isolated`): a
//! reader of the writer's own participant gets the sample itself, not a decoded copy; the bytes are made
//! only for readers that need them (another participant, a durable history).
mod dcps_util;

use std::sync::atomic::Ordering;
use std::sync::Arc;
use std::time::Duration;

use dcps_util::*;
use dds_runtime::prelude::*;

fn take_blobs(r: &DataReader<Blob>, n: usize) -> Vec<Blob> {
    let mut got = Vec::new();
    wait_until(MATCH_TIMEOUT, || {
        got.extend(r.take().unwrap().into_iter().filter_map(|s| s.data));
        got.len() >= n
    });
    got
}

fn blob(id: u32, len: usize) -> Blob {
    Blob {
        id,
        data: vec![id as u8; len],
    }
}

#[test]
fn a_local_reader_gets_the_written_sample_itself() {
    let p = participant(105);
    let (wq, rq) = reliable_keep_all();
    let (w, r) = matched::<Blob>(&p, &p, "Handover", &wq, &rq);
    let sent = || p.transport_stats().sent.load(Ordering::Relaxed);
    let before = sent();
    let n = 300;
    let mut buffers = Vec::new();
    for id in 0..n {
        let b = blob(id, 4096);
        buffers.push(b.data.as_ptr() as usize);
        w.write_owned(b).unwrap();
    }
    let got = take_blobs(&r, n as usize);
    assert_eq!(got.len(), n as usize);
    for (i, b) in got.iter().enumerate() {
        assert_eq!(*b, blob(i as u32, 4096));
        // Moved, not serialized and decoded: the reader holds the very buffer that was written.
        assert_eq!(
            b.data.as_ptr() as usize,
            buffers[i],
            "sample {i} was copied"
        );
    }
    let during = sent() - before;
    assert!(during < 20, "{during} datagrams sent for {n} local samples");

    // A shared sample the application keeps: the reader gets an equal clone.
    let keep = Arc::new(blob(7, 100));
    w.write_shared(keep.clone()).unwrap();
    let got = take_blobs(&r, 1);
    assert_eq!(got, vec![(*keep).clone()]);
    assert_ne!(got[0].data.as_ptr(), keep.data.as_ptr());
}

#[test]
fn readers_elsewhere_get_the_bytes_and_the_local_one_the_sample() {
    let p = participant(106);
    let other = participant(106);
    let (wq, rq) = reliable_keep_all();
    let (w, local) = matched::<Blob>(&p, &p, "HandoverMixed", &wq, &rq);
    // Before the second reader: nothing needs bytes.
    w.write_owned(blob(0, 64 * 1024)).unwrap();
    assert_eq!(take_blobs(&local, 1), vec![blob(0, 64 * 1024)]);

    let far = reader::<Blob>(&other, "HandoverMixed", &rq);
    assert!(wait_until(MATCH_TIMEOUT, || {
        w.publication_matched_status().current_count == 2
            && far.subscription_matched_status().current_count == 1
    }));
    // Fragmented on the wire to the other participant, handed over to the local reader.
    for id in 1..=20 {
        w.write_owned(blob(id, 64 * 1024)).unwrap();
    }
    let want: Vec<Blob> = (1..=20).map(|id| blob(id, 64 * 1024)).collect();
    assert_eq!(take_blobs(&local, 20), want);
    assert_eq!(take_blobs(&far, 20), want);
    w.wait_for_acknowledgments(Duration::from_secs(10)).unwrap();

    // The other reader gone, writes are local again; the local reader still gets every sample.
    drop(far);
    assert!(wait_until(MATCH_TIMEOUT, || w
        .publication_matched_status()
        .current_count
        == 1));
    for id in 21..=40 {
        w.write_owned(blob(id, 1000)).unwrap();
    }
    let want: Vec<Blob> = (21..=40).map(|id| blob(id, 1000)).collect();
    assert_eq!(take_blobs(&local, 20), want);
}

#[test]
fn a_durable_late_joiner_gets_typed_writes_from_the_history() {
    let p = participant(107);
    let durable = Durability::TransientLocal;
    let wq = DataWriterQos::builder()
        .reliability(reliable())
        .durability(durable)
        .history(History::KeepLast(5))
        .build();
    let rq = DataReaderQos::builder()
        .reliability(reliable())
        .durability(durable)
        .history(History::KeepLast(5))
        .build();
    let w = writer::<Blob>(&p, "HandoverDurable", &wq);
    for id in 0..8 {
        w.write_owned(blob(id, 300)).unwrap();
    }
    let late_here = reader::<Blob>(&p, "HandoverDurable", &rq);
    let other = participant(107);
    let late_there = reader::<Blob>(&other, "HandoverDurable", &rq);
    // Each id is an instance of its own: the history keeps all eight.
    let want: Vec<Blob> = (0..8).map(|id| blob(id, 300)).collect();
    assert_eq!(take_blobs(&late_here, 8), want);
    assert_eq!(take_blobs(&late_there, 8), want);
}
