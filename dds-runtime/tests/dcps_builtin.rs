//! The built-in subscriber (DDS 1.4 §2.2.5): its DCPSParticipant, DCPSPublication, DCPSSubscription and
//! DCPSTopic readers see participants, writers, readers and topics come (ALIVE) and go (disposed), with
//! type information, listeners, read conditions in a WaitSet and status conditions. Run inside
//! `scripts/isolated` (loopback only).
mod dcps_util;

use std::sync::atomic::{AtomicU32, Ordering};
use std::sync::Arc;
use std::time::Duration;

use dcps_util::*;
use dds_runtime::prelude::*;

fn alive<T>(samples: &[Sample<T>]) -> Vec<&T> {
    samples
        .iter()
        .filter(|s| s.info.instance_state == InstanceState::Alive)
        .filter_map(|s| s.data.as_ref())
        .collect()
}

struct Count(Arc<AtomicU32>);

impl<T: DdsType> DataReaderListener<T> for Count {
    fn on_data_available(&self, _r: &DataReader<T>) {
        self.0.fetch_add(1, Ordering::SeqCst);
    }
}

#[test]
fn builtin_readers_see_entities_come_and_go() {
    // Type information is announced on opt-in (nextest runs each test in its own process).
    std::env::set_var(dds_runtime::xtypes::ANNOUNCE_ENV, "on");
    let p = participant(229);
    let builtin = p.get_builtin_subscriber().unwrap();
    let parts = builtin.participant_reader();
    let pubs = builtin.publication_reader();
    let subs = builtin.subscription_reader();
    let topics = builtin.topic_reader();
    assert_eq!(parts.topic().name(), "DCPSParticipant");
    // Our own participant is there from the start.
    let own = parts.read().unwrap();
    assert!(alive(&own).iter().any(|d| d.key == p.guid_prefix()));
    let calls = Arc::new(AtomicU32::new(0));
    pubs.set_listener(Box::new(Count(calls.clone())));
    let ws = WaitSet::new();
    let new_pub = pubs.create_readcondition(
        SampleStateMask::NOT_READ,
        ViewStateMask::ANY,
        InstanceStateMask::ALIVE,
    );
    ws.attach_condition(new_pub.clone());

    let other = participant(229);
    let w = writer::<ShapeType>(&other, "BuiltinSq", &DataWriterQos::default());
    let r = reader::<ShapeType>(&other, "BuiltinSq", &DataReaderQos::default());
    assert!(wait_until(MATCH_TIMEOUT, || {
        alive(&parts.read().unwrap())
            .iter()
            .any(|d| d.key == other.guid_prefix())
    }));
    // The remote writer arrives: the read condition and the listener fire.
    assert!(!ws.wait(MATCH_TIMEOUT).unwrap().is_empty());
    // The WaitSet may wake before the listener has run (another thread).
    assert!(wait_until(MATCH_TIMEOUT, || calls.load(Ordering::SeqCst) >= 1));
    let got = pubs.read_w_condition(&new_pub).unwrap();
    let wd = got
        .iter()
        .filter_map(|s| s.data.as_ref())
        .find(|d| d.key == w.guid())
        .expect("the remote writer");
    assert_eq!(wd.topic_name, "BuiltinSq");
    assert_eq!(wd.type_name, "ShapeType");
    assert_eq!(
        wd.participant_key.map(|g| g.prefix),
        Some(other.guid_prefix())
    );
    assert!(wd.type_information.is_some(), "type information announced");
    let h = InstanceHandle::from_guid(w.guid());
    assert_eq!(
        got.iter()
            .find(|s| s.info.instance_handle == h)
            .unwrap()
            .info
            .view_state,
        ViewState::New
    );
    assert!(!new_pub.trigger_value(), "read: no unread sample left");
    assert!(wait_until(MATCH_TIMEOUT, || {
        alive(&subs.read().unwrap())
            .iter()
            .any(|d| d.key == r.guid())
    }));
    let ts = topics.read().unwrap();
    assert!(alive(&ts)
        .iter()
        .any(|t| t.name == "BuiltinSq" && t.type_name == "ShapeType"));

    // The writer leaves: its instance is disposed, the status condition raised again.
    let cond = pubs.status_condition();
    let _ = pubs.read().unwrap();
    assert!(!cond.trigger_value());
    drop(w);
    assert!(wait_until(MATCH_TIMEOUT, || {
        pubs.read_instance(h).is_ok_and(|s| {
            s.first()
                .is_some_and(|s| s.info.instance_state == InstanceState::NotAliveDisposed)
        })
    }));
    // The participant leaves: it and its reader are disposed; taking them forgets them.
    let other_prefix = other.guid_prefix();
    let rh = InstanceHandle::from_guid(r.guid());
    drop(r);
    drop(other);
    assert!(wait_until(MATCH_TIMEOUT, || {
        parts.read().unwrap().iter().any(|s| {
            s.info.instance_state == InstanceState::NotAliveDisposed
                && s.data.as_ref().is_none_or(|d| d.key == other_prefix)
        })
    }));
    assert!(wait_until(MATCH_TIMEOUT, || {
        subs.read_instance(rh).is_ok_and(|s| {
            s.first()
                .is_some_and(|s| s.info.instance_state == InstanceState::NotAliveDisposed)
        })
    }));
    // The data read before, then the dispose as a sample without data (as for any reader).
    let taken = subs.take_instance(rh).unwrap();
    let last = taken.last().expect("samples of the disposed reader");
    assert!(!last.info.valid_data && taken.len() <= 2);
    assert!(
        subs.read_instance(rh).is_err(),
        "a taken, disposed instance is forgotten"
    );
    // Every call returns the same readers.
    let again = p.get_builtin_subscriber().unwrap().publication_reader();
    assert!(again.read_instance(h).is_ok());
}

#[test]
fn builtin_subscriber_created_late_is_seeded_with_what_was_discovered() {
    let p = participant(230);
    let other = participant(230);
    let w = writer::<ShapeType>(&other, "Late", &DataWriterQos::default());
    assert!(wait_until(MATCH_TIMEOUT, || {
        p.discovered_participants().len() == 1
    }));
    // Give SEDP a moment: the writer must be known before the built-in subscriber exists.
    assert!(wait_until(MATCH_TIMEOUT, || {
        let b = p.get_builtin_subscriber().unwrap();
        alive(&b.publication_reader().read().unwrap())
            .iter()
            .any(|d| d.key == w.guid())
    }));
    // Local endpoints are there too, and a deleted local writer is disposed.
    let mine = writer::<ShapeType>(&p, "Mine", &DataWriterQos::default());
    let pubs = p.get_builtin_subscriber().unwrap().publication_reader();
    let h = InstanceHandle::from_guid(mine.guid());
    assert!(wait_until(MATCH_TIMEOUT, || pubs.read_instance(h).is_ok()));
    drop(mine);
    assert!(wait_until(MATCH_TIMEOUT, || {
        pubs.take_instance(h).is_ok_and(|s| {
            s.iter()
                .any(|s| s.info.instance_state == InstanceState::NotAliveDisposed)
        })
    }));
}

#[test]
fn ignore_topic_by_its_dcpstopic_handle() {
    let p = participant(231);
    let other = participant(231);
    let r = reader::<ShapeType>(&p, "IgnoreMe", &DataReaderQos::default());
    let w = writer::<ShapeType>(&other, "IgnoreMe", &DataWriterQos::default());
    assert!(wait_until(MATCH_TIMEOUT, || r.matched_publications().len() == 1));
    let topics = p.get_builtin_subscriber().unwrap().topic_reader();
    let key = topics
        .read()
        .unwrap()
        .into_iter()
        .filter_map(|s| s.data)
        .find(|t| t.name == "IgnoreMe")
        .expect("DCPSTopic sample")
        .key;
    assert!(matches!(
        p.ignore_topic_by_handle(InstanceHandle(7)),
        Err(DdsError::BadParameter(_))
    ));
    p.ignore_topic_by_handle(key).unwrap();
    assert!(wait_until(MATCH_TIMEOUT, || r
        .matched_publications()
        .is_empty()));
    let w2 = writer::<ShapeType>(&other, "IgnoreMe", &DataWriterQos::default());
    std::thread::sleep(std::time::Duration::from_millis(500));
    assert!(r.matched_publications().is_empty());
    drop((w, w2));
}

/// Topics travel in SEDP (DCPSTopic, builtin endpoints 0x2c2/0x2c7): a topic with no reader or writer is
/// seen by the other participant's DCPSTopic reader and `find_topic`, clashes as INCONSISTENT_TOPIC, and
/// is disposed when deleted.
#[test]
fn topics_are_announced_in_sedp() {
    let p = participant(232);
    let other = participant(232);
    let topics = p.get_builtin_subscriber().unwrap().topic_reader();
    let qos = TopicQos::builder().topic_data(b"about".to_vec()).build();
    let lonely = other.create_topic::<ShapeType>("Lonely", &qos).unwrap();
    let mut seen = None;
    assert!(wait_until(MATCH_TIMEOUT, || {
        seen = topics
            .read()
            .unwrap()
            .into_iter()
            .find(|s| s.data.as_ref().is_some_and(|t| t.name == "Lonely"));
        seen.is_some()
    }));
    let seen = seen.unwrap();
    let t = seen.data.unwrap();
    assert_eq!(
        (t.type_name.as_str(), t.topic_data.as_slice()),
        ("ShapeType", &b"about"[..])
    );
    let found = p
        .find_topic::<ShapeType>("Lonely", MATCH_TIMEOUT)
        .expect("find_topic sees the remote topic");
    assert_eq!(found.name(), "Lonely");
    // Same name, another type, still no endpoint anywhere: INCONSISTENT_TOPIC on our topic.
    let clash = p
        .create_topic::<Blob>("Clashing", &TopicQos::default())
        .unwrap();
    let _theirs = other
        .create_topic::<ShapeType>("Clashing", &TopicQos::default())
        .unwrap();
    assert!(wait_until(MATCH_TIMEOUT, || {
        clash
            .inconsistent_topic_status()
            .is_ok_and(|s| s.total_count == 1)
    }));
    // Deleted: disposed in DCPSTopic.
    other.delete_topic(&lonely).unwrap();
    assert!(wait_until(MATCH_TIMEOUT, || {
        topics
            .read_instance(seen.info.instance_handle)
            .is_ok_and(|s| {
                s.iter()
                    .any(|s| s.info.instance_state == InstanceState::NotAliveDisposed)
            })
    }));
}

struct OnReaders(Arc<AtomicU32>);

impl SubscriberListener for OnReaders {
    fn on_data_on_readers(&self, _s: &Subscriber) {
        self.0.fetch_add(1, Ordering::SeqCst);
    }
}

/// The built-in readers are `DataReader`s of the built-in subscriber: `lookup_datareader` finds them by
/// topic name, `get_datareaders` lists them, DATA_ON_READERS reaches the subscriber's listener, a query
/// condition filters on their members, and a remote participant that leaves is read by instance state.
#[test]
fn builtin_readers_are_datareaders_of_the_builtin_subscriber() {
    let p = participant(224);
    let builtin = p.get_builtin_subscriber().unwrap();
    let parts = builtin
        .lookup_datareader::<ParticipantBuiltinTopicData>("DCPSParticipant")
        .unwrap()
        .expect("DCPSParticipant reader");
    let pubs = builtin
        .lookup_datareader::<PublicationBuiltinTopicData>("DCPSPublication")
        .unwrap()
        .expect("DCPSPublication reader");
    assert!(builtin
        .lookup_datareader::<SubscriptionBuiltinTopicData>("DCPSSubscription")
        .unwrap()
        .is_some());
    assert!(builtin
        .lookup_datareader::<TopicBuiltinTopicData>("DCPSTopic")
        .unwrap()
        .is_some());
    assert_eq!(
        parts.instance_handle(),
        builtin.participant_reader().instance_handle()
    );
    assert_eq!(pubs.topic().type_name(), "DDS::PublicationBuiltinTopicData");
    let sub_handle = builtin.instance_handle().unwrap();
    assert_eq!(pubs.subscriber().instance_handle().unwrap(), sub_handle);
    // Our own participant: unread, so DCPSParticipant is listed (DCPSPublication is empty).
    let listed = builtin
        .get_datareaders(
            SampleStateMask::NOT_READ,
            ViewStateMask::ANY,
            InstanceStateMask::ANY,
        )
        .unwrap();
    assert!(listed.contains(&parts.instance_handle()));
    // The participant's own instance handle is its DCPSParticipant instance.
    let own = parts.read_instance(p.instance_handle()).unwrap();
    assert_eq!(own.len(), 1);
    assert_eq!(own[0].data.as_ref().unwrap().key, p.guid_prefix());

    let calls = Arc::new(AtomicU32::new(0));
    builtin
        .set_listener(
            Box::new(OnReaders(calls.clone())),
            StatusMask::DATA_ON_READERS,
        )
        .unwrap();
    let q = pubs
        .create_querycondition(
            SampleStateMask::ANY,
            ViewStateMask::ANY,
            InstanceStateMask::ALIVE,
            "topic_name = %0",
            &["Wanted"],
        )
        .unwrap();
    let ws = WaitSet::new();
    ws.attach_condition(q.clone());

    let other = participant(224);
    let _skip = writer::<ShapeType>(&other, "Unwanted", &DataWriterQos::default());
    let w = writer::<ShapeType>(&other, "Wanted", &DataWriterQos::default());
    assert!(!ws.wait(MATCH_TIMEOUT).unwrap().is_empty());
    let got = pubs.read_w_condition(&q).unwrap();
    assert_eq!(got.len(), 1, "only the writer on Wanted passes the query");
    assert_eq!(got[0].data.as_ref().unwrap().key, w.guid());
    assert!(calls.load(Ordering::SeqCst) >= 1, "on_data_on_readers");

    // The other participant leaves: NOT_ALIVE_DISPOSED, read by instance state.
    let other_prefix = other.guid_prefix();
    let gone = InstanceHandle::from_guid(Guid::new(
        other_prefix,
        dds_runtime::rtps::EntityId::PARTICIPANT,
    ));
    drop((w, _skip, other));
    assert!(wait_until(MATCH_TIMEOUT, || {
        parts
            .select()
            .instance_state(InstanceStateMask::NOT_ALIVE)
            .read()
            .unwrap()
            .iter()
            .any(|s| s.info.instance_handle == gone)
    }));
    assert!(parts
        .select()
        .instance_state(InstanceStateMask::ALIVE)
        .read()
        .unwrap()
        .iter()
        .all(|s| s.info.instance_handle != gone));
    assert_eq!(parts.get_key_value(gone).unwrap().key, other_prefix);
}

/// The built-in subscriber and its topics are not entities the participant contains: it can be deleted
/// after asking for them. Readers dropped by the application come back on the next call, with their data.
#[test]
fn builtin_subscriber_is_not_a_contained_entity() {
    let f = DomainParticipantFactory::get_instance();
    let p = participant(224);
    let b = p.get_builtin_subscriber().unwrap();
    assert!(p
        .lookup_topicdescription::<ParticipantBuiltinTopicData>("DCPSParticipant")
        .is_some());
    let h = b.participant_reader().instance_handle();
    drop(b);
    let again = p.get_builtin_subscriber().unwrap();
    assert_eq!(again.participant_reader().instance_handle(), h);
    assert!(
        again
            .participant_reader()
            .read_instance(p.instance_handle())
            .is_ok(),
        "our own participant, still there"
    );
    p.delete_contained_entities().unwrap();
    assert!(again.participant_reader().read().is_ok());
    drop(again);
    f.delete_participant(&p).unwrap();
}

/// A reader the application creates on a built-in topic (here in a subscriber of its own, with its own
/// QoS) is fed like the built-in subscriber's: seeded with what discovery knows when it is created, then
/// every entity that comes and goes. `set_qos` of a built-in reader applies the policies that may change
/// and refuses the others with `ImmutablePolicy`.
#[test]
fn application_readers_on_builtin_topics_are_fed_and_builtin_readers_take_set_qos() {
    let p = participant(33);
    let other = participant(33);
    let first = writer::<ShapeType>(&other, "UserBuiltinA", &DataWriterQos::default());
    let b = p.get_builtin_subscriber().unwrap();
    assert!(wait_until(MATCH_TIMEOUT, || {
        alive(&b.publication_reader().read().unwrap())
            .iter()
            .any(|d| d.key == first.guid())
    }));
    let sub = p.create_subscriber(&SubscriberQos::default()).unwrap();
    let pubs_topic = p
        .lookup_topicdescription::<PublicationBuiltinTopicData>("DCPSPublication")
        .expect("the built-in topic");
    let rq = DataReaderQos::builder()
        .history(History::KeepLast(4))
        .build();
    let pubs = sub.create_datareader(&pubs_topic, &rq).unwrap();
    let parts_topic = p
        .lookup_topicdescription::<ParticipantBuiltinTopicData>("DCPSParticipant")
        .expect("the built-in topic");
    let parts = sub.create_datareader(&parts_topic, &rq).unwrap();
    // Seeded: the writer discovered before, and both participants.
    assert!(alive(&pubs.read().unwrap())
        .iter()
        .any(|d| d.key == first.guid()));
    assert_eq!(alive(&parts.read().unwrap()).len(), 2);
    assert_eq!(pubs.get_qos().unwrap().history, History::KeepLast(4));
    // Fed: a writer that comes, then goes.
    let second = writer::<ShapeType>(&other, "UserBuiltinB", &DataWriterQos::default());
    let h = InstanceHandle::from_guid(second.guid());
    assert!(wait_until(MATCH_TIMEOUT, || pubs.read_instance(h).is_ok()));
    drop(second);
    assert!(wait_until(MATCH_TIMEOUT, || {
        pubs.read_instance(h).is_ok_and(|s| {
            s.iter()
                .any(|s| s.info.instance_state == InstanceState::NotAliveDisposed)
        })
    }));
    // The built-in subscriber's reader saw the same, besides.
    assert!(b.publication_reader().read_instance(h).is_ok());
    // set_qos: a policy that may change is applied, an immutable one refused.
    let builtin = b.publication_reader();
    let mut q = builtin.get_qos().unwrap();
    q.deadline = Deadline(Duration::from_secs(30));
    builtin.set_qos(&q).unwrap();
    assert_eq!(builtin.get_qos().unwrap().deadline, q.deadline);
    q.history = History::KeepLast(8);
    assert!(matches!(
        builtin.set_qos(&q),
        Err(DdsError::ImmutablePolicy(QosPolicyId::History))
    ));
    let mut uq = pubs.get_qos().unwrap();
    uq.time_based_filter.minimum_separation = Duration::from_millis(10);
    pubs.set_qos(&uq).unwrap();
    assert_eq!(
        pubs.get_qos().unwrap().time_based_filter,
        uq.time_based_filter
    );
    // Deleted like any reader; the built-in subscriber's reader stays.
    sub.delete_datareader(&parts).unwrap();
    sub.delete_datareader(&pubs).unwrap();
    assert!(b.participant_reader().read().is_ok());
}
