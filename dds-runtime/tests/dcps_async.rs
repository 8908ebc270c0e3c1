//! The reader's `Stream` works inside tokio (multi-thread and current-thread) without blocking or panicking.
mod dcps_util;

use std::future::poll_fn;
use std::pin::Pin;
use std::time::Duration;

use dcps_util::*;
use dds_runtime::prelude::*;
use futures_core::Stream;

async fn next<S: Stream + Unpin>(s: &mut S) -> Option<S::Item> {
    poll_fn(|cx| Pin::new(&mut *s).poll_next(cx)).await
}

fn setup(
    domain: u32,
) -> (
    DomainParticipant,
    DomainParticipant,
    DataWriter<ShapeType>,
    DataReader<ShapeType>,
) {
    let (p1, p2) = (participant(domain), participant(domain));
    let (wq, rq) = reliable_keep_all();
    let (w, r) = matched(&p1, &p2, "Square", &wq, &rq);
    (p1, p2, w, r)
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn stream_yields_samples_under_tokio() {
    let (_p1, _p2, w, r) = setup(31);
    let mut stream = r.stream();
    let writer = tokio::spawn(async move {
        for i in 0..20 {
            tokio::time::sleep(Duration::from_millis(5)).await;
            w.write(&shape("RED", i)).unwrap();
        }
        w
    });
    let mut xs = Vec::new();
    while xs.len() < 20 {
        let s = tokio::time::timeout(Duration::from_secs(10), next(&mut stream))
            .await
            .expect("stream stalled")
            .expect("stream ended");
        xs.push(s.data.unwrap().x);
    }
    assert_eq!(xs, (0..20).collect::<Vec<_>>());
    let _w = writer.await.unwrap();
}

#[tokio::test(flavor = "current_thread")]
async fn stream_wakes_a_current_thread_runtime() {
    let (_p1, _p2, w, r) = setup(32);
    let mut stream = r.stream();
    // The write happens on another OS thread while this runtime's only thread is parked in the stream.
    let t = std::thread::spawn(move || {
        std::thread::sleep(Duration::from_millis(200));
        w.write(&shape("BLUE", 42)).unwrap();
        w
    });
    let s = tokio::time::timeout(Duration::from_secs(10), next(&mut stream))
        .await
        .expect("not woken")
        .unwrap();
    assert_eq!(s.data.unwrap().x, 42);
    let _w = t.join().unwrap();
}
