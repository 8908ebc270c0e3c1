//! WaitSet wakeups from read conditions, status conditions and guard conditions; listeners.
mod dcps_util;

use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

use dcps_util::*;
use dds_runtime::prelude::*;

#[test]
fn waitset_wakes_on_data_status_and_guard() {
    let p1 = participant(41);
    let p2 = participant(41);
    let r = reader::<ShapeType>(
        &p2,
        "Square",
        &DataReaderQos::builder().reliability(reliable()).build(),
    );

    let ws = WaitSet::new();
    let sc = r.status_condition();
    sc.set_enabled_statuses(StatusMask::SUBSCRIPTION_MATCHED);
    ws.attach_condition(sc.clone());
    let rc = r.create_readcondition(
        SampleStateMask::NOT_READ,
        ViewStateMask::ANY,
        InstanceStateMask::ANY,
    );
    ws.attach_condition(rc.clone());
    let guard = GuardCondition::new();
    ws.attach_condition(guard.clone());
    assert!(matches!(
        ws.wait(Duration::from_millis(50)),
        Err(DdsError::Timeout)
    ));

    // Status condition: the writer appears.
    let w = writer::<ShapeType>(
        &p1,
        "Square",
        &DataWriterQos::builder().reliability(reliable()).build(),
    );
    let got = ws.wait(MATCH_TIMEOUT).unwrap();
    assert!(got.iter().any(|c| matches!(c, Condition::Status(_))));
    assert_eq!(r.subscription_matched_status().current_count, 1);
    assert!(!sc.trigger_value(), "reading the status resets the trigger");
    assert!(wait_until(MATCH_TIMEOUT, || w
        .publication_matched_status()
        .current_count
        == 1));

    // Read condition: data arrives from another thread while we wait.
    let w2 = w.clone();
    let t = std::thread::spawn(move || {
        std::thread::sleep(Duration::from_millis(100));
        w2.write(&shape("RED", 1)).unwrap();
    });
    let start = Instant::now();
    let got = ws.wait(Duration::from_secs(10)).unwrap();
    assert!(start.elapsed() < Duration::from_secs(9));
    assert!(got.iter().any(|c| matches!(c, Condition::Read(_))));
    t.join().unwrap();
    assert_eq!(r.take_w_condition(&rc).unwrap().len(), 1);
    assert!(!rc.trigger_value());

    // Guard condition.
    guard.set_trigger_value(true);
    let got = ws.wait(Duration::from_secs(1)).unwrap();
    assert!(got.iter().any(|c| matches!(c, Condition::Guard(_))));
}

struct Counter(Arc<AtomicUsize>, Arc<AtomicUsize>);

impl DataReaderListener<ShapeType> for Counter {
    fn on_data_available(&self, reader: &DataReader<ShapeType>) {
        let n = reader.take().unwrap().len();
        self.0.fetch_add(n, Ordering::SeqCst);
    }
    fn on_subscription_matched(&self, _r: &DataReader<ShapeType>, s: SubscriptionMatchedStatus) {
        self.1.store(s.current_count as usize, Ordering::SeqCst);
    }
}

#[test]
fn listener_sees_matches_and_data() {
    let p1 = participant(42);
    let p2 = participant(42);
    let r = reader::<ShapeType>(
        &p2,
        "Square",
        &DataReaderQos::builder()
            .reliability(reliable())
            .history(History::KeepAll)
            .build(),
    );
    let (data, matched) = (Arc::new(AtomicUsize::new(0)), Arc::new(AtomicUsize::new(0)));
    r.set_listener(Box::new(Counter(data.clone(), matched.clone())));
    let w = writer::<ShapeType>(
        &p1,
        "Square",
        &DataWriterQos::builder()
            .reliability(reliable())
            .history(History::KeepAll)
            .build(),
    );
    assert!(wait_until(MATCH_TIMEOUT, || matched.load(Ordering::SeqCst) == 1));
    assert!(wait_until(MATCH_TIMEOUT, || w
        .publication_matched_status()
        .current_count
        == 1));
    for i in 0..10 {
        w.write(&shape("GREEN", i)).unwrap();
    }
    assert!(wait_until(Duration::from_secs(10), || data
        .load(Ordering::SeqCst)
        == 10));
}

struct MatchChanges(Arc<std::sync::Mutex<Vec<(u32, i32)>>>);

impl DataReaderListener<ShapeType> for MatchChanges {
    fn on_subscription_matched(&self, _r: &DataReader<ShapeType>, s: SubscriptionMatchedStatus) {
        self.0
            .lock()
            .unwrap()
            .push((s.current_count, s.current_count_change));
    }
}

/// Each listener call reports the change since the previous one: +1 on match, -1 on unmatch.
#[test]
fn listener_reports_unmatch_as_minus_one() {
    let p1 = participant(43);
    let p2 = participant(43);
    let r = reader::<ShapeType>(
        &p2,
        "Square",
        &DataReaderQos::builder().reliability(reliable()).build(),
    );
    let seen = Arc::new(std::sync::Mutex::new(Vec::new()));
    r.set_listener(Box::new(MatchChanges(seen.clone())));
    let w = writer::<ShapeType>(&p1, "Square", &DataWriterQos::default());
    assert!(wait_until(MATCH_TIMEOUT, || !seen
        .lock()
        .unwrap()
        .is_empty()));
    drop(w);
    assert!(wait_until(MATCH_TIMEOUT, || seen.lock().unwrap().len() >= 2));
    assert_eq!(*seen.lock().unwrap(), vec![(1, 1), (0, -1)]);
}

/// A reliable KEEP_ALL reader with max_samples holds the writer back instead of dropping samples.
#[test]
fn full_keep_all_reader_applies_back_pressure_without_loss() {
    let p1 = participant(44);
    let p2 = participant(44);
    let r = reader::<ShapeType>(
        &p2,
        "Square",
        &DataReaderQos::builder()
            .reliability(reliable())
            .history(History::KeepAll)
            .resource_limits(ResourceLimits {
                max_samples: Some(20),
                max_instances: None,
                max_samples_per_instance: None,
            })
            .build(),
    );
    let w = writer::<ShapeType>(
        &p1,
        "Square",
        &DataWriterQos::builder()
            .reliability(Reliability::Reliable {
                max_blocking_time: Duration::from_secs(10),
            })
            .history(History::KeepAll)
            .build(),
    );
    // Both sides: a volatile writer that has not matched the reader yet would send into the void.
    assert!(wait_until(MATCH_TIMEOUT, || r
        .subscription_matched_status()
        .current_count
        == 1
        && w.publication_matched_status().current_count == 1));
    for i in 0..100 {
        w.write(&shape("RED", i)).unwrap();
    }
    assert!(wait_until(Duration::from_secs(5), || r.sample_count() == 20));
    std::thread::sleep(Duration::from_millis(300));
    assert_eq!(r.sample_count(), 20, "the cache never overflows");
    assert!(w
        .wait_for_acknowledgments(Duration::from_millis(100))
        .is_err());
    let mut got = Vec::new();
    let deadline = Instant::now() + Duration::from_secs(20);
    while got.len() < 100 && Instant::now() < deadline {
        got.extend(
            r.take()
                .unwrap()
                .into_iter()
                .filter_map(|s| s.data)
                .map(|d| d.x),
        );
        std::thread::sleep(Duration::from_millis(5));
    }
    assert_eq!(got, (0..100).collect::<Vec<_>>());
    assert_eq!(r.sample_rejected_status().total_count, 0);
    assert_eq!(r.sample_lost_status().total_count, 0);
}
