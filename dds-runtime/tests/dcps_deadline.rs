//! DEADLINE end to end between two of our participants: OFFERED_DEADLINE_MISSED on the writer and
//! REQUESTED_DEADLINE_MISSED on the reader are counted per instance, name the instance that missed, and a
//! listener consumes the change counts (each callback reports what happened since the previous one).
mod dcps_util;

use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use dcps_util::*;
use dds_runtime::prelude::*;

const PERIOD: Duration = Duration::from_millis(150);

/// Every (total, change) a listener was called with.
#[derive(Default, Clone)]
struct Calls(Arc<Mutex<Vec<(u32, u32, InstanceHandle)>>>);

impl Calls {
    fn record(&self, s: &DeadlineMissedStatus) {
        self.0
            .lock()
            .unwrap()
            .push((s.total_count, s.total_count_change, s.last_instance_handle));
    }
    fn get(&self) -> Vec<(u32, u32, InstanceHandle)> {
        self.0.lock().unwrap().clone()
    }
}

impl DataWriterListener<ShapeType> for Calls {
    fn on_offered_deadline_missed(&self, _: &DataWriter<ShapeType>, s: DeadlineMissedStatus) {
        self.record(&s);
    }
}

impl DataReaderListener<ShapeType> for Calls {
    fn on_requested_deadline_missed(&self, _: &DataReader<ShapeType>, s: DeadlineMissedStatus) {
        self.record(&s);
    }
}

/// Each callback's change count is what happened since the previous callback: they add up to the total.
fn assert_consumed(calls: &[(u32, u32, InstanceHandle)]) {
    let mut sum = 0;
    for (total, change, _) in calls {
        sum += change;
        assert_eq!(*total, sum, "change counts must add up: {calls:?}");
    }
}

#[test]
fn deadline_missed_per_instance_on_both_sides() {
    let (p1, p2) = (participant(133), participant(133));
    let (mut wq, mut rq) = reliable_keep_all();
    wq.deadline = Deadline(PERIOD);
    rq.deadline = Deadline(PERIOD);
    let (w, r) = matched::<ShapeType>(&p1, &p2, "Square", &wq, &rq);
    let (wcalls, rcalls) = (Calls::default(), Calls::default());
    w.set_listener(Box::new(wcalls.clone()));
    r.set_listener(Box::new(rcalls.clone()));

    // RED is written every 40 ms and never misses; BLUE is written once and then misses every period.
    w.write(&shape("BLUE", 1)).unwrap();
    let end = Instant::now() + Duration::from_millis(1200);
    let mut x = 0;
    while Instant::now() < end {
        w.write(&shape("RED", x)).unwrap();
        x += 1;
        std::thread::sleep(Duration::from_millis(40));
    }
    let blue_w = w.lookup_instance(&shape("BLUE", 0)).unwrap().unwrap();
    let blue_r = r.lookup_instance(&shape("BLUE", 0)).unwrap().unwrap();

    let (wc, rc) = (wcalls.get(), rcalls.get());
    // About 1.2 s / 150 ms = 8 misses of BLUE alone; the 50 ms check may merge or delay one.
    for (calls, blue, side) in [(&wc, blue_w, "writer"), (&rc, blue_r, "reader")] {
        let total = calls.last().map_or(0, |c| c.0);
        assert!(
            (5..=9).contains(&total),
            "{side}: {total} misses, {calls:?}"
        );
        assert!(
            calls.iter().all(|c| c.2 == blue),
            "{side}: only BLUE misses its deadline: {calls:?}"
        );
        assert_consumed(calls);
    }
    // The status read by the application: the same total, no change since the last callback.
    let ws = w.offered_deadline_missed_status();
    assert!(ws.total_count >= wc.last().unwrap().0);
    assert_eq!(ws.last_instance_handle, blue_w);
    let rs = r.requested_deadline_missed_status();
    assert!(rs.total_count >= rc.last().unwrap().0);
    assert_eq!(rs.last_instance_handle, blue_r);
}

#[test]
fn deadline_status_without_listener_counts_changes_until_read() {
    let (p1, p2) = (participant(134), participant(134));
    let (mut wq, mut rq) = reliable_keep_all();
    wq.deadline = Deadline(PERIOD);
    rq.deadline = Deadline(PERIOD);
    let (w, r) = matched::<ShapeType>(&p1, &p2, "Square", &wq, &rq);
    w.write(&shape("GREEN", 1)).unwrap();
    w.write(&shape("BLUE", 1)).unwrap();
    // Both instances miss: two misses per period on each side.
    assert!(wait_until(Duration::from_secs(5), || {
        r.sample_count() == 2
    }));
    std::thread::sleep(Duration::from_millis(700));
    let ws = w.offered_deadline_missed_status();
    let rs = r.requested_deadline_missed_status();
    for (s, side) in [(&ws, "writer"), (&rs, "reader")] {
        assert!(s.total_count >= 4, "{side}: {s:?}");
        assert_eq!(s.total_count_change, s.total_count, "{side}: {s:?}");
    }
    // Reading reset the change counts.
    assert_eq!(w.offered_deadline_missed_status().total_count_change, 0);
    assert_eq!(r.requested_deadline_missed_status().total_count_change, 0);
    // A write of both instances restarts their clocks: no miss right after.
    w.write(&shape("GREEN", 2)).unwrap();
    w.write(&shape("BLUE", 2)).unwrap();
    let before = w.offered_deadline_missed_status().total_count;
    std::thread::sleep(Duration::from_millis(60));
    assert_eq!(w.offered_deadline_missed_status().total_count, before);
}

#[test]
fn a_deadline_set_after_writes_counts_from_the_change() {
    // Writes without a deadline do not read the clock for it (write path): a deadline set later must
    // count from the set_qos, not from a stale last-write time.
    let (p1, p2) = (participant(13), participant(13));
    let (wq, rq) = reliable_keep_all();
    let (w, _r) = matched::<ShapeType>(&p1, &p2, "Square", &wq, &rq);
    w.write(&shape("BLUE", 1)).unwrap();
    std::thread::sleep(PERIOD * 2);
    let mut q = w.get_qos().unwrap();
    q.deadline = Deadline(PERIOD);
    let set = Instant::now();
    w.set_qos(&q).unwrap();
    assert!(wait_until(Duration::from_secs(5), || {
        w.offered_deadline_missed_status().total_count > 0
    }));
    let first_miss = set.elapsed();
    assert!(
        first_miss >= PERIOD - Duration::from_millis(10),
        "the first miss came {first_miss:?} after the deadline was set (period {PERIOD:?})"
    );
}
