//! IGNORE_LOCAL (Cyclone's `ignorelocal`) through the DCPS API (run inside `scripts/isolated`): with
//! `Participant`, a writer and a reader of one participant do not match while readers of another
//! participant of the process do; `Process` excludes both; `None` keeps intra-process delivery; the policy
//! is fixed once the entity is enabled; `Process` on either side of two participants of the process is
//! enough in both; endpoints that leave the policy unset take the participant's default, an explicit
//! `None` wins over it.
mod dcps_util;

use dcps_util::*;
use dds_runtime::prelude::*;

fn qos(ignore: IgnoreLocal) -> (DataWriterQos, DataReaderQos) {
    let (mut wq, mut rq) = reliable_keep_all();
    wq.ignore_local = ignore;
    rq.ignore_local = ignore;
    (wq, rq)
}

fn xs(r: &DataReader<ShapeType>) -> Vec<i32> {
    r.take()
        .unwrap()
        .iter()
        .filter_map(|s| s.data.as_ref().map(|d| d.x))
        .collect()
}

/// A writer on `p`, a reader on `p` and a reader on another participant `q` of the process, all with
/// `ignore`; the writer writes 0..10 once discovery settled; what each reader got, and the matches.
fn exchange(domain: u32, ignore: IgnoreLocal) -> Outcome {
    let (p, q) = (participant(domain), participant(domain));
    let (wq, rq) = qos(ignore);
    // One topic per test: the tests run in parallel, on two domains.
    let topic = format!("IgnoreLocal{ignore:?}");
    let w = writer::<ShapeType>(&p, &topic, &wq);
    let own = reader::<ShapeType>(&p, &topic, &rq);
    let other = reader::<ShapeType>(&q, &topic, &rq);
    let e_own = u32::from(ignore == IgnoreLocal::None);
    let e_other = u32::from(ignore != IgnoreLocal::Process);
    assert!(
        wait_until(MATCH_TIMEOUT, || {
            w.publication_matched_status().current_count == e_own + e_other
                && own.subscription_matched_status().current_count == e_own
                && other.subscription_matched_status().current_count == e_other
        }),
        "{ignore:?}: writer {:?}, own reader {:?}, other reader {:?}",
        w.publication_matched_status(),
        own.subscription_matched_status(),
        other.subscription_matched_status()
    );
    // Discovery has settled (SEDP of all three is long in): nothing more matches later.
    std::thread::sleep(std::time::Duration::from_millis(500));
    for x in 0..10 {
        w.write(&shape("RED", x)).unwrap();
    }
    if e_own + e_other > 0 {
        w.wait_for_acknowledgments(MATCH_TIMEOUT).unwrap();
    }
    std::thread::sleep(std::time::Duration::from_millis(200));
    Outcome {
        writer_matches: w.matched_subscriptions().len(),
        own_matches: own.matched_publications().len(),
        other_matches: other.matched_publications().len(),
        own: xs(&own),
        other: xs(&other),
    }
}

#[derive(Debug, PartialEq)]
struct Outcome {
    writer_matches: usize,
    own_matches: usize,
    other_matches: usize,
    own: Vec<i32>,
    other: Vec<i32>,
}

#[test]
fn participant_ignores_its_own_endpoints_only() {
    let all: Vec<i32> = (0..10).collect();
    let o = exchange(61, IgnoreLocal::Participant);
    assert_eq!(
        o,
        Outcome {
            writer_matches: 1,
            own_matches: 0,
            other_matches: 1,
            own: vec![],
            other: all,
        }
    );
}

#[test]
fn process_ignores_every_participant_of_the_process() {
    let o = exchange(66, IgnoreLocal::Process);
    assert_eq!(
        o,
        Outcome {
            writer_matches: 0,
            own_matches: 0,
            other_matches: 0,
            own: vec![],
            other: vec![],
        }
    );
}

#[test]
fn none_keeps_every_match_and_ignore_local_is_fixed_once_enabled() {
    let all: Vec<i32> = (0..10).collect();
    let o = exchange(61, IgnoreLocal::None);
    assert_eq!(
        o,
        Outcome {
            writer_matches: 2,
            own_matches: 1,
            other_matches: 1,
            own: all.clone(),
            other: all,
        }
    );
    let p = participant(66);
    let (wq, rq) = qos(IgnoreLocal::None);
    let w = writer::<ShapeType>(&p, "IgnoreLocalFixed", &wq);
    let r = reader::<ShapeType>(&p, "IgnoreLocalFixed", &rq);
    let (wq2, rq2) = qos(IgnoreLocal::Participant);
    assert!(matches!(
        w.set_qos(&wq2),
        Err(DdsError::ImmutablePolicy(QosPolicyId::IgnoreLocal))
    ));
    assert!(matches!(
        r.set_qos(&rq2),
        Err(DdsError::ImmutablePolicy(QosPolicyId::IgnoreLocal))
    ));
}

/// Two participants of the process: one side's `Process` is enough, in both participants (as in Cyclone),
/// although the policy is not announced. A `None` writer on `p` and a `Process` reader on `q`, then a
/// `Process` writer on `p` and a `None` reader on `q`: neither pair matches on either side, while a `None`
/// pair beside them does (discovery has run).
#[test]
fn process_on_either_side_is_enough_in_both_participants() {
    let (p, q) = (participant(108), participant(108));
    let (wq_none, rq_none) = qos(IgnoreLocal::None);
    let (wq_process, rq_process) = qos(IgnoreLocal::Process);
    let w_none = writer::<ShapeType>(&p, "IgnoreLocalEither", &wq_none);
    let w_process = writer::<ShapeType>(&p, "IgnoreLocalEither", &wq_process);
    let r_none = reader::<ShapeType>(&q, "IgnoreLocalEither", &rq_none);
    let r_process = reader::<ShapeType>(&q, "IgnoreLocalEither", &rq_process);
    assert!(
        wait_until(MATCH_TIMEOUT, || {
            w_none.publication_matched_status().current_count == 1
                && r_none.subscription_matched_status().current_count == 1
        }),
        "the None pair: writer {:?}, reader {:?}",
        w_none.publication_matched_status(),
        r_none.subscription_matched_status()
    );
    // Discovery has settled (SEDP of all four is long in): nothing more matches later.
    std::thread::sleep(std::time::Duration::from_millis(500));
    assert_eq!(w_none.matched_subscriptions().len(), 1, "None writer");
    assert_eq!(w_process.matched_subscriptions().len(), 0, "Process writer");
    assert_eq!(r_none.matched_publications().len(), 1, "None reader");
    assert_eq!(r_process.matched_publications().len(), 0, "Process reader");
}

/// A participant of `domain` whose endpoints inherit `policy` (`Config::ignore_local`).
fn defaulting_to(domain: u32, policy: IgnoreLocal) -> DomainParticipant {
    participant_with(
        domain,
        dds_runtime::config::Config {
            ignore_local: policy,
            ..dds_runtime::config::Config::default()
        },
    )
}

/// RED x = 0..10 from `w`, acknowledged by every matched reader, and a moment for the readers' caches.
fn write_ten_acknowledged(w: &DataWriter<ShapeType>) {
    for x in 0..10 {
        w.write(&shape("RED", x)).unwrap();
    }
    w.wait_for_acknowledgments(MATCH_TIMEOUT).unwrap();
    std::thread::sleep(std::time::Duration::from_millis(200));
}

/// The participant-wide default (`Config::ignore_local`, domain 123): endpoints that leave their policy
/// unset (`Inherit`, the QoS default) inherit the participant's `Participant`, so its writer and reader do
/// not match, while a reader of another participant (default configuration) does and gets the data.
#[test]
fn endpoints_inherit_the_participant_default() {
    let p = defaulting_to(123, IgnoreLocal::Participant);
    let q = participant(123);
    let (wq, rq) = reliable_keep_all();
    assert_eq!(wq.ignore_local, IgnoreLocal::Inherit);
    let w = writer::<ShapeType>(&p, "IgnoreLocalDefault", &wq);
    let own = reader::<ShapeType>(&p, "IgnoreLocalDefault", &rq);
    let other = reader::<ShapeType>(&q, "IgnoreLocalDefault", &rq);
    assert!(
        wait_until(MATCH_TIMEOUT, || {
            w.publication_matched_status().current_count == 1
                && other.subscription_matched_status().current_count == 1
        }),
        "writer {:?}, other reader {:?}",
        w.publication_matched_status(),
        other.subscription_matched_status()
    );
    std::thread::sleep(std::time::Duration::from_millis(500));
    write_ten_acknowledged(&w);
    assert_eq!(w.matched_subscriptions().len(), 1);
    assert_eq!(own.matched_publications().len(), 0);
    assert_eq!(xs(&own), Vec::<i32>::new());
    assert_eq!(xs(&other), (0..10).collect::<Vec<_>>());
}

/// An endpoint's explicit `None` wins over the participant default (domain 124, as in Cyclone, where an
/// explicitly set policy is kept): on a participant whose default is `Process`, a writer and a reader that
/// set `None` match each other and a reader of another participant of the process, while a reader that
/// leaves the policy unset inherits `Process` and matches nothing. `get_qos` shows each endpoint's own setting.
#[test]
fn an_explicit_none_wins_over_the_participant_default() {
    let p = defaulting_to(124, IgnoreLocal::Process);
    let q = participant(124);
    let (wq_none, rq_none) = qos(IgnoreLocal::None);
    let (_, rq_unset) = reliable_keep_all();
    let topic = "IgnoreLocalExplicitNone";
    let w = writer::<ShapeType>(&p, topic, &wq_none);
    let own_none = reader::<ShapeType>(&p, topic, &rq_none);
    let own_unset = reader::<ShapeType>(&p, topic, &rq_unset);
    let other = reader::<ShapeType>(&q, topic, &rq_unset);
    assert!(
        wait_until(MATCH_TIMEOUT, || {
            w.publication_matched_status().current_count == 2
                && own_none.subscription_matched_status().current_count == 1
                && other.subscription_matched_status().current_count == 1
        }),
        "writer {:?}, own None reader {:?}, other reader {:?}",
        w.publication_matched_status(),
        own_none.subscription_matched_status(),
        other.subscription_matched_status()
    );
    // Discovery has settled: the unset reader would have matched by now.
    std::thread::sleep(std::time::Duration::from_millis(500));
    write_ten_acknowledged(&w);
    let all: Vec<i32> = (0..10).collect();
    assert_eq!(w.matched_subscriptions().len(), 2);
    assert_eq!(own_unset.matched_publications().len(), 0);
    assert_eq!(xs(&own_none), all);
    assert_eq!(xs(&own_unset), Vec::<i32>::new());
    assert_eq!(xs(&other), all);
    assert_eq!(w.get_qos().unwrap().ignore_local, IgnoreLocal::None);
    assert_eq!(
        own_unset.get_qos().unwrap().ignore_local,
        IgnoreLocal::Inherit
    );
}
