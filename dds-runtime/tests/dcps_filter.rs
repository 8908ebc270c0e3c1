//! Content-filtered topics and query conditions through the DCPS API, on loopback (run inside
//! `scripts/isolated`): filters on nested members and enumerators, parameters changed at run time, query
//! conditions in a waitset and in `read_w_condition`/`take_w_condition` with ORDER BY.
mod dcps_util;

use std::time::Duration;

use dcps_util::*;
use dds_runtime::prelude::*;

#[derive(DdsType, Debug, Clone, Copy, PartialEq)]
#[dds(name = "test::Level")]
enum Level {
    Low,
    High,
}

#[derive(DdsType, Debug, Clone, PartialEq)]
#[dds(name = "test::Pos")]
struct Pos {
    x: i32,
    y: i32,
}

#[derive(DdsType, Debug, Clone, PartialEq)]
#[dds(name = "test::Reading")]
struct Reading {
    #[dds(key)]
    id: u32,
    level: Level,
    pos: Pos,
    label: String,
}

fn reading(id: u32, level: Level, x: i32) -> Reading {
    Reading {
        id,
        level,
        pos: Pos { x, y: -x },
        label: format!("r{id}"),
    }
}

fn ids(samples: &[Sample<Reading>]) -> Vec<u32> {
    samples
        .iter()
        .filter_map(|s| s.data.as_ref().map(|d| d.id))
        .collect()
}

#[test]
fn content_filtered_reader_sees_only_matching_samples() {
    require_netns();
    let p1 = participant(91);
    let p2 = participant(91);
    let (wq, rq) = reliable_keep_all();
    let w = writer::<Reading>(&p1, "Readings", &wq);
    let topic = p2
        .create_topic::<Reading>("Readings", &TopicQos::default())
        .unwrap();
    let cft = p2
        .create_content_filtered_topic("HighFar", &topic, "level = 'High' AND pos.x > %0", &["10"])
        .unwrap();
    let r = p2
        .create_subscriber(&SubscriberQos::default())
        .and_then(|s| s.create_datareader(&cft, &rq))
        .unwrap();
    assert!(wait_until(MATCH_TIMEOUT, || w
        .publication_matched_status()
        .current_count
        == 1));
    for (id, level, x) in [
        (1, Level::High, 20),
        (2, Level::Low, 20),
        (3, Level::High, 5),
        (4, Level::High, 11),
    ] {
        w.write(&reading(id, level, x)).unwrap();
    }
    w.wait_for_acknowledgments(Duration::from_secs(5)).unwrap();
    assert!(wait_until(Duration::from_secs(5), || r.sample_count() == 2));
    assert_eq!(ids(&r.take().unwrap()), [1, 4]);

    // New parameters reach the reader at once and the writer through SEDP (the reader announces them
    // again): until then the writer may still skip id 5, so it is written until it arrives.
    cft.set_expression_parameters(&["0"]).unwrap();
    assert!(cft.set_expression_parameters::<&str>(&[]).is_err());
    assert!(wait_until(Duration::from_secs(5), || {
        w.write(&reading(5, Level::High, 3)).unwrap();
        w.write(&reading(6, Level::Low, 3)).unwrap();
        r.sample_count() > 0
    }));
    let got = ids(&r.take().unwrap());
    assert!(!got.is_empty() && got.iter().all(|&i| i == 5), "{got:?}");
    assert!(matches!(
        p2.create_content_filtered_topic("Bad", &topic, "pos.x >", &[] as &[&str]),
        Err(DdsError::Filter(_))
    ));
}

#[test]
fn query_condition_wakes_a_waitset_and_selects_in_order() {
    require_netns();
    let p = participant(92);
    let (wq, rq) = reliable_keep_all();
    let w = writer::<Reading>(&p, "Queried", &wq);
    let r = reader::<Reading>(&p, "Queried", &rq);
    let q = r
        .create_querycondition(
            SampleStateMask::ANY,
            ViewStateMask::ANY,
            InstanceStateMask::ANY,
            "pos.x >= %0 ORDER BY pos.y",
            &["100"],
        )
        .unwrap();
    assert_eq!(q.query_expression(), "pos.x >= %0 ORDER BY pos.y");
    let ws = WaitSet::new();
    ws.attach_condition(q.clone());
    assert!(wait_until(MATCH_TIMEOUT, || w
        .publication_matched_status()
        .current_count
        == 1));
    for (id, x) in [(1, 5), (2, 50), (3, 30), (4, 40)] {
        w.write(&reading(id, Level::Low, x)).unwrap();
    }
    assert!(wait_until(Duration::from_secs(5), || r.sample_count() == 4));
    assert!(!q.trigger_value(), "no sample has x >= 100");
    assert!(matches!(
        ws.wait(Duration::from_millis(50)),
        Err(DdsError::Timeout)
    ));

    // Lower the bar from another thread: the waitset wakes.
    let q2 = q.clone();
    let t = std::thread::spawn(move || {
        std::thread::sleep(Duration::from_millis(50));
        q2.set_query_parameters(&["30"]).unwrap();
    });
    let got = ws.wait(Duration::from_secs(5)).unwrap();
    t.join().unwrap();
    assert!(matches!(&got[..], [Condition::Read(c)] if c.is_query()));
    // ORDER BY pos.y (= -x): largest x first.
    assert_eq!(ids(&r.read_w_condition(&q).unwrap()), [2, 4, 3]);
    assert_eq!(ids(&r.take_w_condition(&q).unwrap()), [2, 4, 3]);
    assert_eq!(
        ids(&r.read().unwrap()),
        [1],
        "the query took only its samples"
    );
    assert!(!q.trigger_value());
    assert!(q.set_query_parameters::<&str>(&[]).is_err());
    assert_eq!(q.query_parameters(), ["30"]);

    // A plain read condition on the same reader is a different condition.
    let rc = r.create_readcondition(
        SampleStateMask::ANY,
        ViewStateMask::ANY,
        InstanceStateMask::ANY,
    );
    ws.attach_condition(rc.clone());
    assert_eq!(ws.conditions().len(), 2);
    assert!(matches!(
        r.create_querycondition(
            SampleStateMask::ANY,
            ViewStateMask::ANY,
            InstanceStateMask::ANY,
            "x = %3",
            &["1"],
        ),
        Err(DdsError::Filter(FilterError::MissingParameter { .. }))
    ));
}
