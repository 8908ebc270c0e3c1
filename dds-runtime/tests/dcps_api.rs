//! The DCPS API test program: one test per operation of the DCPS PIM (DDS 1.4 §2.2.2) that the other
//! `dcps_*` tests do not already cover, each asserting the operation's effect. docs/dcps-api.md maps every
//! operation to its test. Run inside `scripts/isolated` (loopback only).
mod dcps_util;

use std::sync::{Arc, Mutex};
use std::time::{Duration, SystemTime};

use dcps_util::*;
use dds_runtime::prelude::*;

const SHORT: Duration = Duration::from_millis(300);

/// What listeners saw, as text lines.
#[derive(Clone, Default)]
struct Log(Arc<Mutex<Vec<String>>>);

impl Log {
    fn push(&self, s: impl Into<String>) {
        self.0.lock().unwrap().push(s.into());
    }
    fn lines(&self) -> Vec<String> {
        self.0.lock().unwrap().clone()
    }
    fn has(&self, prefix: &str) -> bool {
        self.lines().iter().any(|l| l.starts_with(prefix))
    }
    fn wait(&self, prefix: &str) -> bool {
        wait_until(MATCH_TIMEOUT, || self.has(prefix))
    }
}

impl DomainParticipantListener for Log {
    fn on_publication_matched(&self, w: InstanceHandle, _s: PublicationMatchedStatus) {
        self.push(format!("participant:publication_matched {}", w.0));
    }
    fn on_subscription_matched(&self, r: InstanceHandle, _s: SubscriptionMatchedStatus) {
        self.push(format!("participant:subscription_matched {}", r.0));
    }
    fn on_data_available(&self, r: InstanceHandle) {
        self.push(format!("participant:data_available {}", r.0));
    }
    fn on_sample_rejected(&self, r: InstanceHandle, s: SampleRejectedStatus) {
        self.push(format!(
            "participant:sample_rejected {} {:?}",
            r.0, s.last_reason
        ));
    }
    fn on_inconsistent_topic(&self, t: InstanceHandle, _s: InconsistentTopicStatus) {
        self.push(format!("participant:inconsistent_topic {}", t.0));
    }
}

impl PublisherListener for Log {
    fn on_publication_matched(&self, w: InstanceHandle, _s: PublicationMatchedStatus) {
        self.push(format!("publisher:publication_matched {}", w.0));
    }
}

impl SubscriberListener for Log {
    fn on_data_on_readers(&self, s: &Subscriber) {
        self.push("subscriber:data_on_readers");
        s.notify_datareaders().unwrap();
    }
    fn on_data_available(&self, r: InstanceHandle) {
        self.push(format!("subscriber:data_available {}", r.0));
    }
    fn on_subscription_matched(&self, r: InstanceHandle, _s: SubscriptionMatchedStatus) {
        self.push(format!("subscriber:subscription_matched {}", r.0));
    }
}

impl TopicListener for Log {
    fn on_inconsistent_topic(&self, t: InstanceHandle, s: InconsistentTopicStatus) {
        self.push(format!(
            "topic:inconsistent_topic {} {}",
            t.0, s.total_count
        ));
    }
}

impl DataWriterListener<ShapeType> for Log {
    fn on_publication_matched(&self, w: &DataWriter<ShapeType>, _s: PublicationMatchedStatus) {
        self.push(format!(
            "writer:publication_matched {}",
            w.instance_handle().0
        ));
    }
}

impl DataReaderListener<ShapeType> for Log {
    fn on_data_available(&self, r: &DataReader<ShapeType>) {
        self.push(format!("reader:data_available {}", r.instance_handle().0));
    }
    fn on_subscription_matched(&self, r: &DataReader<ShapeType>, _s: SubscriptionMatchedStatus) {
        self.push(format!(
            "reader:subscription_matched {}",
            r.instance_handle().0
        ));
    }
}

fn reliable_qos() -> (DataWriterQos, DataReaderQos) {
    reliable_keep_all()
}

/// A reader on `p2` matched with a writer on `p1`, with their publisher and subscriber.
struct Pair {
    publisher: Publisher,
    subscriber: Subscriber,
    writer: DataWriter<ShapeType>,
    reader: DataReader<ShapeType>,
}

fn pair(p1: &DomainParticipant, p2: &DomainParticipant, topic: &str) -> Pair {
    let (wq, rq) = reliable_qos();
    let t1 = p1
        .create_topic::<ShapeType>(topic, &TopicQos::default())
        .unwrap();
    let t2 = p2
        .create_topic::<ShapeType>(topic, &TopicQos::default())
        .unwrap();
    let publisher = p1.create_publisher(&PublisherQos::default()).unwrap();
    let subscriber = p2.create_subscriber(&SubscriberQos::default()).unwrap();
    let writer = publisher.create_datawriter(&t1, &wq).unwrap();
    let reader = subscriber.create_datareader(&t2, &rq).unwrap();
    assert!(wait_until(MATCH_TIMEOUT, || writer
        .matched_subscriptions()
        .len()
        == 1));
    assert!(wait_until(MATCH_TIMEOUT, || reader
        .matched_publications()
        .len()
        == 1));
    Pair {
        publisher,
        subscriber,
        writer,
        reader,
    }
}

// ---- DomainParticipantFactory -------------------------------------------------------------------

#[test]
fn factory_create_and_lookup_participant() {
    require_netns();
    let f = DomainParticipantFactory::get_instance();
    let qos = DomainParticipantQos::builder()
        .user_data(b"hello".to_vec())
        .build();
    let p = f.create_participant(150, &qos).unwrap();
    assert_eq!(p.get_qos().user_data.0, b"hello");
    let found = f.lookup_participant(150).expect("lookup_participant");
    assert_eq!(found.guid_prefix(), p.guid_prefix());
    assert!(f.lookup_participant(151).is_none());
}

#[test]
fn factory_default_participant_qos() {
    require_netns();
    let f = DomainParticipantFactory::get_instance();
    let qos = DomainParticipantQos::builder()
        .user_data(b"dflt".to_vec())
        .build();
    f.set_default_participant_qos(&qos).unwrap();
    assert_eq!(f.default_participant_qos(), qos);
    let p = participant(152);
    assert_eq!(p.get_qos().user_data.0, b"dflt");
    f.set_default_participant_qos(&DomainParticipantQos::default())
        .unwrap();
}

#[test]
fn factory_delete_participant() {
    let p = participant(153);
    let t = p
        .create_topic::<ShapeType>("T", &TopicQos::default())
        .unwrap();
    let f = DomainParticipantFactory::get_instance();
    assert!(matches!(
        f.delete_participant(&p),
        Err(DdsError::PreconditionNotMet(_))
    ));
    p.delete_topic(&t).unwrap();
    f.delete_participant(&p).unwrap();
    assert!(matches!(
        p.create_publisher(&PublisherQos::default()),
        Err(DdsError::AlreadyDeleted)
    ));
    assert!(f.lookup_participant(153).is_none());
}

#[test]
fn factory_qos_autoenable_false_creates_disabled_participants() {
    require_netns();
    let f = DomainParticipantFactory::get_instance();
    let off = DomainParticipantFactoryQos::builder()
        .autoenable_created_entities(false)
        .build();
    f.set_qos(&off).unwrap();
    assert_eq!(f.qos(), off);
    let disabled = f
        .create_participant(154, &DomainParticipantQos::default())
        .unwrap();
    assert!(!disabled.is_enabled());
    f.set_qos(&DomainParticipantFactoryQos::default()).unwrap();
    assert!(f
        .create_participant(154, &DomainParticipantQos::default())
        .is_ok());
}

// ---- DomainParticipant ----------------------------------------------------------------------------

#[test]
fn participant_set_qos_announces_user_data() {
    let p1 = participant(155);
    let p2 = participant(155);
    assert!(wait_until(MATCH_TIMEOUT, || p2
        .discovered_participant_handles()
        .len()
        == 1));
    let h = p1.instance_handle();
    p1.set_qos(
        &DomainParticipantQos::builder()
            .user_data(b"v2".to_vec())
            .build(),
    )
    .unwrap();
    assert_eq!(p1.get_qos().user_data.0, b"v2");
    assert!(wait_until(MATCH_TIMEOUT, || {
        p2.get_discovered_participant_data(h)
            .is_ok_and(|d| d.user_data == b"v2")
    }));
    let off = DomainParticipantQos::builder()
        .autoenable_created_entities(false)
        .build();
    p1.set_qos(&off).unwrap();
    assert!(!p1.get_qos().autoenable_created_entities);
}

#[test]
fn participant_enable_and_current_time() {
    let p = participant(156);
    assert_eq!(p.domain_id(), 156);
    p.enable().unwrap();
    let t = p.get_current_time().unwrap();
    let d = SystemTime::now().duration_since(t).unwrap_or_default();
    assert!(d < Duration::from_secs(1));
}

#[test]
fn participant_listener_receives_what_no_child_listener_takes() {
    let p = participant(157);
    let log = Log::default();
    p.set_listener(
        Box::new(log.clone()),
        StatusMask::PUBLICATION_MATCHED
            | StatusMask::SUBSCRIPTION_MATCHED
            | StatusMask::DATA_AVAILABLE,
    );
    let pair = pair(&p, &p, "PL");
    let (w, r) = (pair.writer.instance_handle(), pair.reader.instance_handle());
    assert!(log.wait(&format!("participant:publication_matched {}", w.0)));
    assert!(log.wait(&format!("participant:subscription_matched {}", r.0)));
    pair.writer.write(&shape("RED", 1)).unwrap();
    assert!(log.wait(&format!("participant:data_available {}", r.0)));
    p.clear_listener();
}

#[test]
fn participant_listener_gets_sample_rejected() {
    let p = participant(158);
    let log = Log::default();
    p.set_listener(Box::new(log.clone()), StatusMask::SAMPLE_REJECTED);
    let (wq, _) = reliable_qos();
    let rq = DataReaderQos::builder()
        .reliability(reliable())
        .history(History::KeepAll)
        .resource_limits(ResourceLimits {
            max_instances: Some(1),
            ..ResourceLimits::default()
        })
        .build();
    let (w, r) = matched::<ShapeType>(&p, &p, "SR", &wq, &rq);
    w.write(&shape("RED", 1)).unwrap();
    w.write(&shape("BLUE", 1)).unwrap();
    assert!(log.wait(&format!(
        "participant:sample_rejected {}",
        r.instance_handle().0
    )));
    assert!(r.sample_rejected_status().total_count >= 1);
}

#[test]
fn participant_status_condition_triggers() {
    let p = participant(159);
    let ws = WaitSet::new();
    let cond = p.status_condition();
    cond.set_enabled_statuses(StatusMask::PUBLICATION_MATCHED);
    ws.attach_condition(cond.clone());
    let _pair = pair(&p, &p, "PSC");
    let got = ws.wait(MATCH_TIMEOUT).unwrap();
    assert_eq!(got.len(), 1);
    assert!(cond
        .changed_statuses()
        .contains(StatusMask::PUBLICATION_MATCHED));
    _pair.writer.publication_matched_status();
    assert!(!cond.trigger_value());
}

#[test]
fn participant_ignore_participant() {
    let p1 = participant(160);
    let p2 = participant(160);
    let pair = pair(&p1, &p2, "IP");
    p2.ignore_participant(p1.instance_handle()).unwrap();
    assert!(wait_until(MATCH_TIMEOUT, || pair
        .reader
        .matched_publications()
        .is_empty()));
    assert!(p2.discovered_participant_handles().is_empty());
    pair.writer.write(&shape("RED", 1)).unwrap();
    std::thread::sleep(SHORT * 2);
    assert!(pair.reader.take().unwrap().is_empty());
    assert!(
        pair.reader.matched_publications().is_empty(),
        "stays ignored after SPDP renewals"
    );
    assert!(matches!(
        p2.ignore_participant(p2.instance_handle()),
        Err(DdsError::BadParameter(_))
    ));
}

#[test]
fn participant_ignore_publication() {
    let p1 = participant(161);
    let p2 = participant(161);
    let pair = pair(&p1, &p2, "IPub");
    p2.ignore_publication(pair.writer.instance_handle())
        .unwrap();
    assert!(wait_until(MATCH_TIMEOUT, || pair
        .reader
        .matched_publications()
        .is_empty()));
    pair.writer.write(&shape("RED", 1)).unwrap();
    std::thread::sleep(SHORT);
    assert!(pair.reader.take().unwrap().is_empty());
}

#[test]
fn participant_ignore_subscription() {
    let p1 = participant(162);
    let p2 = participant(162);
    let pair = pair(&p1, &p2, "ISub");
    p1.ignore_subscription(pair.reader.instance_handle())
        .unwrap();
    assert!(wait_until(MATCH_TIMEOUT, || pair
        .writer
        .matched_subscriptions()
        .is_empty()));
}

#[test]
fn participant_ignore_topic() {
    let p1 = participant(163);
    let p2 = participant(163);
    let pair = pair(&p1, &p2, "ITopic");
    p2.ignore_topic("ITopic").unwrap();
    assert!(wait_until(MATCH_TIMEOUT, || pair
        .reader
        .matched_publications()
        .is_empty()));
    let w2 = writer::<ShapeType>(&p1, "ITopic", &reliable_qos().0);
    std::thread::sleep(SHORT);
    assert!(pair.reader.matched_publications().is_empty());
    drop(w2);
}

#[test]
fn participant_contains_entity() {
    let p = participant(164);
    let other = participant(164);
    let pair = pair(&p, &p, "CE");
    let t = p.lookup_topicdescription::<ShapeType>("CE").unwrap();
    for h in [
        t.instance_handle().unwrap(),
        pair.publisher.instance_handle().unwrap(),
        pair.subscriber.instance_handle().unwrap(),
        pair.writer.instance_handle(),
        pair.reader.instance_handle(),
    ] {
        assert!(p.contains_entity(h), "{h:?}");
        assert!(!other.contains_entity(h), "{h:?}");
    }
    let h = pair.writer.instance_handle();
    pair.publisher.delete_datawriter(&pair.writer).unwrap();
    assert!(!p.contains_entity(h));
}

#[test]
fn participant_delete_contained_entities() {
    let p1 = participant(165);
    let p2 = participant(165);
    let pair = pair(&p1, &p2, "DCE");
    let far = reader::<ShapeType>(&p2, "DCE", &reliable_qos().1);
    assert!(wait_until(MATCH_TIMEOUT, || far
        .matched_publications()
        .len()
        == 1));
    p2.delete_contained_entities().unwrap();
    assert!(matches!(pair.reader.take(), Err(DdsError::AlreadyDeleted)));
    assert!(wait_until(MATCH_TIMEOUT, || pair
        .writer
        .matched_subscriptions()
        .is_empty()));
    p1.delete_contained_entities().unwrap();
    assert!(matches!(
        pair.writer.write(&shape("RED", 1)),
        Err(DdsError::AlreadyDeleted)
    ));
    assert!(matches!(
        pair.publisher.create_datawriter(
            &p1.create_topic::<ShapeType>("X", &TopicQos::default())
                .unwrap(),
            &DataWriterQos::default()
        ),
        Err(DdsError::AlreadyDeleted)
    ));
    // Nothing is left, so the participant itself can go.
    DomainParticipantFactory::get_instance()
        .delete_participant(&p1)
        .unwrap();
}

#[test]
fn participant_default_publisher_subscriber_topic_qos() {
    let p = participant(166);
    let pq = PublisherQos::builder().partition(["A"]).build();
    p.set_default_publisher_qos(&pq).unwrap();
    assert_eq!(p.default_publisher_qos(), pq);
    let sq = SubscriberQos::builder().partition(["B"]).build();
    p.set_default_subscriber_qos(&sq).unwrap();
    assert_eq!(p.default_subscriber_qos(), sq);
    let tq = TopicQos::builder().topic_data(b"td".to_vec()).build();
    p.set_default_topic_qos(&tq).unwrap();
    assert_eq!(p.default_topic_qos(), tq);
    let publ = p.create_publisher(&p.default_publisher_qos()).unwrap();
    assert_eq!(publ.get_qos().unwrap().partition.0, vec!["A".to_string()]);
}

#[test]
fn participant_delete_publisher() {
    let p = participant(167);
    let t = p
        .create_topic::<ShapeType>("DP", &TopicQos::default())
        .unwrap();
    let publ = p.create_publisher(&PublisherQos::default()).unwrap();
    let w = publ
        .create_datawriter(&t, &DataWriterQos::default())
        .unwrap();
    assert!(matches!(
        p.delete_publisher(&publ),
        Err(DdsError::PreconditionNotMet(_))
    ));
    publ.delete_datawriter(&w).unwrap();
    p.delete_publisher(&publ).unwrap();
    assert!(matches!(
        publ.create_datawriter(&t, &DataWriterQos::default()),
        Err(DdsError::AlreadyDeleted)
    ));
    assert!(matches!(
        p.delete_publisher(&publ),
        Err(DdsError::AlreadyDeleted)
    ));
}

#[test]
fn participant_delete_subscriber() {
    let p = participant(168);
    let t = p
        .create_topic::<ShapeType>("DS", &TopicQos::default())
        .unwrap();
    let sub = p.create_subscriber(&SubscriberQos::default()).unwrap();
    let r = sub
        .create_datareader(&t, &DataReaderQos::default())
        .unwrap();
    assert!(matches!(
        p.delete_subscriber(&sub),
        Err(DdsError::PreconditionNotMet(_))
    ));
    sub.delete_datareader(&r).unwrap();
    p.delete_subscriber(&sub).unwrap();
    assert!(matches!(
        sub.create_datareader(&t, &DataReaderQos::default()),
        Err(DdsError::AlreadyDeleted)
    ));
}

#[test]
fn participant_delete_topic() {
    let p = participant(169);
    let t = p
        .create_topic::<ShapeType>("DT", &TopicQos::default())
        .unwrap();
    let w = writer::<ShapeType>(&p, "DT", &DataWriterQos::default());
    assert!(matches!(
        p.delete_topic(&t),
        Err(DdsError::PreconditionNotMet(_))
    ));
    assert_eq!(w.topic().name(), "DT");
    w.publisher().delete_datawriter(&w).unwrap();
    p.delete_topic(&t).unwrap();
    assert!(
        p.lookup_topicdescription::<ShapeType>("DT").is_some(),
        "the writer's own topic remains"
    );
    assert!(matches!(t.get_qos(), Err(DdsError::AlreadyDeleted)));
    let publ = p.create_publisher(&PublisherQos::default()).unwrap();
    assert!(matches!(
        publ.create_datawriter(&t, &DataWriterQos::default()),
        Err(DdsError::AlreadyDeleted)
    ));
}

#[test]
fn participant_lookup_topicdescription() {
    let p = participant(170);
    let t = p
        .create_topic::<ShapeType>("LT", &TopicQos::default())
        .unwrap();
    let found = p.lookup_topicdescription::<ShapeType>("LT").unwrap();
    assert_eq!(
        found.instance_handle().unwrap(),
        t.instance_handle().unwrap()
    );
    assert!(p.lookup_topicdescription::<Blob>("LT").is_none());
    assert!(p.lookup_topicdescription::<ShapeType>("nope").is_none());
}

#[test]
fn participant_find_topic() {
    let p1 = participant(171);
    let p2 = participant(171);
    let _w = writer::<ShapeType>(&p2, "Remote", &DataWriterQos::default());
    let t = p1.find_topic::<ShapeType>("Remote", MATCH_TIMEOUT).unwrap();
    assert_eq!(t.name(), "Remote");
    assert_eq!(t.type_name(), "ShapeType");
    assert_eq!(t.participant().guid_prefix(), p1.guid_prefix());
    assert!(p1
        .discovered_topics()
        .contains(&("Remote".to_string(), "ShapeType".to_string())));
    assert!(p1.contains_entity(t.instance_handle().unwrap()));
    assert!(matches!(
        p1.find_topic::<ShapeType>("Absent", Duration::from_millis(200)),
        Err(DdsError::Timeout)
    ));
    assert!(matches!(
        p1.find_topic::<Blob>("Remote", Duration::from_millis(200)),
        Err(DdsError::PreconditionNotMet(_))
    ));
}

#[test]
fn participant_multitopic_unsupported() {
    let p = participant(172);
    assert!(matches!(
        p.create_multitopic("M", "T", "SELECT * FROM T"),
        Err(DdsError::Unsupported(_))
    ));
}

// ---- Topic ---------------------------------------------------------------------------------------

#[test]
fn topic_inconsistent_topic() {
    let p1 = participant(173);
    let p2 = participant(173);
    let t = p1
        .create_topic::<ShapeType>("Clash", &TopicQos::default())
        .unwrap();
    let log = Log::default();
    t.set_listener(Box::new(log.clone()), StatusMask::INCONSISTENT_TOPIC)
        .unwrap();
    let plog = Log::default();
    p1.set_listener(Box::new(plog.clone()), StatusMask::INCONSISTENT_TOPIC);
    let cond = t.status_condition().unwrap();
    let _w = writer::<Blob>(&p2, "Clash", &DataWriterQos::default());
    assert!(log.wait("topic:inconsistent_topic"));
    assert!(cond.trigger_value());
    assert!(
        !plog.has("participant:inconsistent_topic"),
        "the topic's listener is more specific"
    );
    let s = t.inconsistent_topic_status().unwrap();
    assert_eq!(s.total_count, 1, "counted once per remote endpoint");
    assert!(!cond.trigger_value());
    // A topic created after the remote endpoint was discovered starts inconsistent.
    let late = p1
        .create_topic::<ShapeType>("Clash", &TopicQos::default())
        .unwrap();
    assert!(late.status_condition().unwrap().trigger_value());
    assert_eq!(late.inconsistent_topic_status().unwrap().total_count, 1);
}

#[test]
fn topic_set_qos() {
    let p1 = participant(174);
    let p2 = participant(174);
    let pair = pair(&p1, &p2, "TQ");
    let t = pair.writer.topic().clone();
    assert_eq!(t.get_qos().unwrap(), TopicQos::default());
    let new = TopicQos::builder().topic_data(b"new".to_vec()).build();
    t.set_qos(&new).unwrap();
    assert_eq!(t.get_qos().unwrap(), new);
    let h = pair.writer.instance_handle();
    assert!(wait_until(MATCH_TIMEOUT, || {
        pair.reader
            .get_matched_publication_data(h)
            .is_ok_and(|d| d.qos.topic_data.0 == b"new")
    }));
    let bad = TopicQos::builder()
        .durability(Durability::TransientLocal)
        .build();
    assert!(matches!(
        t.set_qos(&bad),
        Err(DdsError::ImmutablePolicy(QosPolicyId::Durability))
    ));
    t.enable().unwrap();
}

// ---- Publisher -----------------------------------------------------------------------------------

#[test]
fn publisher_set_qos_partition_rematches() {
    let p = participant(175);
    let t = p
        .create_topic::<ShapeType>("Part", &TopicQos::default())
        .unwrap();
    let publ = p
        .create_publisher(&PublisherQos::builder().partition(["A"]).build())
        .unwrap();
    let sub = p
        .create_subscriber(&SubscriberQos::builder().partition(["B"]).build())
        .unwrap();
    let w = publ
        .create_datawriter(&t, &DataWriterQos::default())
        .unwrap();
    let r = sub
        .create_datareader(&t, &DataReaderQos::default())
        .unwrap();
    std::thread::sleep(SHORT);
    assert!(w.matched_subscriptions().is_empty());
    publ.set_qos(&PublisherQos::builder().partition(["B"]).build())
        .unwrap();
    assert!(wait_until(MATCH_TIMEOUT, || w
        .matched_subscriptions()
        .len()
        == 1));
    assert_eq!(publ.get_qos().unwrap().partition.0, vec!["B".to_string()]);
    sub.set_qos(&SubscriberQos::builder().partition(["C"]).build())
        .unwrap();
    assert!(wait_until(MATCH_TIMEOUT, || r
        .matched_publications()
        .is_empty()));
    let pres = PublisherQos::builder()
        .partition(["B"])
        .presentation(Presentation {
            access_scope: PresentationAccessScope::Topic,
            coherent_access: true,
            ordered_access: false,
        })
        .build();
    assert!(matches!(
        publ.set_qos(&pres),
        Err(DdsError::ImmutablePolicy(QosPolicyId::Presentation))
    ));
}

#[test]
fn publisher_listener_and_most_specific_listener() {
    let p = participant(176);
    let plog = Log::default();
    p.set_listener(Box::new(plog.clone()), StatusMask::PUBLICATION_MATCHED);
    let t = p
        .create_topic::<ShapeType>("PubL", &TopicQos::default())
        .unwrap();
    let publ = p.create_publisher(&PublisherQos::default()).unwrap();
    let log = Log::default();
    publ.set_listener(Box::new(log.clone()), StatusMask::PUBLICATION_MATCHED)
        .unwrap();
    let plain = publ
        .create_datawriter(&t, &DataWriterQos::default())
        .unwrap();
    let own = publ
        .create_datawriter(&t, &DataWriterQos::default())
        .unwrap();
    let wlog = Log::default();
    own.set_listener(Box::new(wlog.clone()));
    let _r = reader::<ShapeType>(&p, "PubL", &DataReaderQos::default());
    assert!(log.wait(&format!(
        "publisher:publication_matched {}",
        plain.instance_handle().0
    )));
    assert!(wlog.wait(&format!(
        "writer:publication_matched {}",
        own.instance_handle().0
    )));
    assert!(!log.has(&format!(
        "publisher:publication_matched {}",
        own.instance_handle().0
    )));
    assert!(
        !plog.has("participant:publication_matched"),
        "the publisher's listener is more specific"
    );
    // A writer listener without PUBLICATION_MATCHED in its mask lets the status go up.
    let masked = publ
        .create_datawriter(&t, &DataWriterQos::default())
        .unwrap();
    masked.set_listener_with_mask(Box::new(wlog.clone()), StatusMask::OFFERED_DEADLINE_MISSED);
    let _r2 = reader::<ShapeType>(&p, "PubL", &DataReaderQos::default());
    assert!(log.wait(&format!(
        "publisher:publication_matched {}",
        masked.instance_handle().0
    )));
    publ.clear_listener().unwrap();
}

#[test]
fn publisher_status_condition() {
    let p = participant(177);
    let t = p
        .create_topic::<ShapeType>("PubC", &TopicQos::default())
        .unwrap();
    let publ = p.create_publisher(&PublisherQos::default()).unwrap();
    let cond = publ.status_condition().unwrap();
    let w = publ
        .create_datawriter(&t, &DataWriterQos::default())
        .unwrap();
    assert!(!cond.trigger_value());
    let _r = reader::<ShapeType>(&p, "PubC", &DataReaderQos::default());
    assert!(wait_until(MATCH_TIMEOUT, || cond.trigger_value()));
    w.publication_matched_status();
    assert!(!cond.trigger_value());
    publ.enable().unwrap();
}

/// Reading one writer's (or reader's) status leaves its publisher's (subscriber's) condition raised while a
/// sibling still has the same status unread; reading the sibling's clears it.
#[test]
fn group_status_condition_stays_raised_for_an_unread_sibling() {
    let p = participant(228);
    let t = p
        .create_topic::<ShapeType>("Siblings", &TopicQos::default())
        .unwrap();
    let publ = p.create_publisher(&PublisherQos::default()).unwrap();
    let sub = p.create_subscriber(&SubscriberQos::default()).unwrap();
    let (pc, sc) = (
        publ.status_condition().unwrap(),
        sub.status_condition().unwrap(),
    );
    let wq = DataWriterQos::default();
    let (a, b) = (
        publ.create_datawriter(&t, &wq).unwrap(),
        publ.create_datawriter(&t, &wq).unwrap(),
    );
    let rq = DataReaderQos::default();
    let (ra, rb) = (
        sub.create_datareader::<ShapeType, _>(&t, &rq).unwrap(),
        sub.create_datareader::<ShapeType, _>(&t, &rq).unwrap(),
    );
    assert!(wait_until(MATCH_TIMEOUT, || {
        a.publication_matched_status().current_count == 2
            && b.publication_matched_status().current_count == 2
            && ra.subscription_matched_status().current_count == 2
            && rb.subscription_matched_status().current_count == 2
    }));
    // Everything read once: now raise PUBLICATION_MATCHED on both writers again with a third reader.
    let _ = (
        ra.liveliness_changed_status(),
        rb.liveliness_changed_status(),
    );
    assert!(!pc
        .changed_statuses()
        .contains(StatusMask::PUBLICATION_MATCHED));
    let _rc = reader::<ShapeType>(&p, "Siblings", &rq);
    assert!(wait_until(MATCH_TIMEOUT, || {
        pc.changed_statuses()
            .contains(StatusMask::PUBLICATION_MATCHED)
            && a.matched_subscriptions().len() == 3
            && b.matched_subscriptions().len() == 3
    }));
    a.publication_matched_status();
    assert!(
        pc.changed_statuses()
            .contains(StatusMask::PUBLICATION_MATCHED),
        "b's change is unread"
    );
    b.publication_matched_status();
    assert!(!pc
        .changed_statuses()
        .contains(StatusMask::PUBLICATION_MATCHED));
    // The same on the subscriber, with a new writer matching both readers.
    assert!(!sc
        .changed_statuses()
        .contains(StatusMask::SUBSCRIPTION_MATCHED));
    let _wc = writer::<ShapeType>(&p, "Siblings", &wq);
    assert!(wait_until(MATCH_TIMEOUT, || {
        ra.matched_publications().len() == 3 && rb.matched_publications().len() == 3
    }));
    ra.subscription_matched_status();
    assert!(sc
        .changed_statuses()
        .contains(StatusMask::SUBSCRIPTION_MATCHED));
    rb.subscription_matched_status();
    assert!(!sc
        .changed_statuses()
        .contains(StatusMask::SUBSCRIPTION_MATCHED));
}

#[test]
fn publisher_default_datawriter_qos_and_copy_from_topic_qos() {
    let p = participant(178);
    let publ = p.create_publisher(&PublisherQos::default()).unwrap();
    assert_eq!(publ.participant().guid_prefix(), p.guid_prefix());
    let q = DataWriterQos::builder()
        .history(History::KeepLast(7))
        .build();
    publ.set_default_datawriter_qos(&q).unwrap();
    assert_eq!(publ.default_datawriter_qos().unwrap(), q);
    let tq = TopicQos::builder()
        .durability(Durability::TransientLocal)
        .history(History::KeepLast(3))
        .build();
    let mut wq = DataWriterQos::builder().ownership_strength(9).build();
    publ.copy_from_topic_qos(&mut wq, &tq);
    assert_eq!(wq.durability, Durability::TransientLocal);
    assert_eq!(wq.history, History::KeepLast(3));
    assert_eq!(wq.ownership_strength.0, 9);
}

#[test]
fn publisher_delete_datawriter() {
    let p1 = participant(179);
    let p2 = participant(179);
    let pair = pair(&p1, &p2, "DDW");
    pair.writer.write(&shape("RED", 1)).unwrap();
    assert_eq!(take_n(&pair.reader, 1).len(), 1);
    pair.publisher.delete_datawriter(&pair.writer).unwrap();
    assert!(matches!(
        pair.writer.write(&shape("RED", 2)),
        Err(DdsError::AlreadyDeleted)
    ));
    assert!(wait_until(MATCH_TIMEOUT, || pair
        .reader
        .matched_publications()
        .is_empty()));
    let s = take_n(&pair.reader, 1);
    assert!(
        s.iter()
            .any(|s| s.info.instance_state != InstanceState::Alive),
        "instance unregistered"
    );
    let other = p1.create_publisher(&PublisherQos::default()).unwrap();
    let w2 = writer::<ShapeType>(&p1, "DDW", &DataWriterQos::default());
    assert!(matches!(
        other.delete_datawriter(&w2),
        Err(DdsError::PreconditionNotMet(_))
    ));
}

/// `create_datawriter` with a listener: the listener gets the match with a reader that already exists, made
/// inside the create call, with the writer's own handle.
#[test]
fn publisher_create_datawriter_with_listener() {
    let p = participant(205);
    let t = p
        .create_topic::<ShapeType>("CWL", &TopicQos::default())
        .unwrap();
    let (wq, rq) = reliable_qos();
    let _reader = reader::<ShapeType>(&p, "CWL", &rq);
    let log = Log::default();
    let publ = p.create_publisher(&PublisherQos::default()).unwrap();
    let w = publ
        .create_datawriter_with_listener(&t, &wq, Box::new(log.clone()), StatusMask::all())
        .unwrap();
    let expected = format!("writer:publication_matched {}", w.instance_handle().0);
    assert!(log.wait(&expected), "listener saw {:?}", log.lines());
    assert_eq!(w.publication_matched_status().total_count, 1);
}

/// `create_datareader` with a listener: a TRANSIENT_LOCAL writer of the same participant hands its history
/// over inside the create call; the listener gets that match and the data, with the reader's own handle.
#[test]
fn subscriber_create_datareader_with_listener() {
    let p = participant(206);
    let t = p
        .create_topic::<ShapeType>("CRL", &TopicQos::default())
        .unwrap();
    let (wq, rq) = reliable_qos();
    let (wq, rq) = (
        DataWriterQos {
            durability: Durability::TransientLocal,
            ..wq
        },
        DataReaderQos {
            durability: Durability::TransientLocal,
            ..rq
        },
    );
    let w = writer::<ShapeType>(&p, "CRL", &wq);
    for i in 0..3 {
        w.write(&shape("RED", i)).unwrap();
    }
    let log = Log::default();
    let sub = p.create_subscriber(&SubscriberQos::default()).unwrap();
    let r = sub
        .create_datareader_with_listener(&t, &rq, Box::new(log.clone()), StatusMask::all())
        .unwrap();
    let h = r.instance_handle().0;
    assert!(
        log.wait(&format!("reader:subscription_matched {h}")),
        "listener saw {:?}",
        log.lines()
    );
    assert!(
        log.wait(&format!("reader:data_available {h}")),
        "listener saw {:?}",
        log.lines()
    );
    assert_eq!(take_n(&r, 3).len(), 3);
}

#[test]
fn publisher_lookup_datawriter() {
    let p = participant(180);
    let t = p
        .create_topic::<ShapeType>("LW", &TopicQos::default())
        .unwrap();
    let publ = p.create_publisher(&PublisherQos::default()).unwrap();
    let w = publ
        .create_datawriter(&t, &DataWriterQos::default())
        .unwrap();
    let found = publ.lookup_datawriter::<ShapeType>("LW").unwrap().unwrap();
    assert_eq!(found.guid(), w.guid());
    assert!(publ.lookup_datawriter::<Blob>("LW").unwrap().is_none());
    assert!(publ
        .lookup_datawriter::<ShapeType>("other")
        .unwrap()
        .is_none());
}

#[test]
fn publisher_delete_contained_entities() {
    let p = participant(181);
    let t = p
        .create_topic::<ShapeType>("PDCE", &TopicQos::default())
        .unwrap();
    let publ = p.create_publisher(&PublisherQos::default()).unwrap();
    let w = publ
        .create_datawriter(&t, &DataWriterQos::default())
        .unwrap();
    publ.delete_contained_entities().unwrap();
    assert!(matches!(
        w.write(&shape("RED", 1)),
        Err(DdsError::AlreadyDeleted)
    ));
    p.delete_publisher(&publ).unwrap();
}

#[test]
fn publisher_wait_for_acknowledgments() {
    let p1 = participant(182);
    let p2 = participant(182);
    let pair = pair(&p1, &p2, "WFA");
    for i in 0..10 {
        pair.writer.write(&shape("RED", i)).unwrap();
    }
    pair.publisher
        .wait_for_acknowledgments(MATCH_TIMEOUT)
        .unwrap();
    assert_eq!(
        pair.reader.take().unwrap().len(),
        10,
        "acknowledged means received"
    );
}

#[test]
fn publisher_suspend_and_resume_publications() {
    let p1 = participant(183);
    let p2 = participant(183);
    let pair = pair(&p1, &p2, "SR");
    assert!(matches!(
        pair.publisher.resume_publications(),
        Err(DdsError::PreconditionNotMet(_))
    ));
    pair.publisher.suspend_publications().unwrap();
    pair.publisher.suspend_publications().unwrap();
    for i in 0..3 {
        pair.writer.write(&shape("RED", i)).unwrap();
    }
    pair.publisher.resume_publications().unwrap();
    pair.publisher.resume_publications().unwrap();
    assert_eq!(take_n(&pair.reader, 3).len(), 3);
}

// ---- DataWriter ----------------------------------------------------------------------------------

#[test]
fn writer_set_qos() {
    let p1 = participant(184);
    let p2 = participant(184);
    let pair = pair(&p1, &p2, "WQ");
    let mut q = pair.writer.get_qos().unwrap();
    q.ownership_strength = OwnershipStrength(42);
    q.deadline = Deadline(Duration::from_millis(50));
    pair.writer.set_qos(&q).unwrap();
    assert_eq!(pair.writer.get_qos().unwrap().ownership_strength.0, 42);
    let h = pair.writer.instance_handle();
    assert!(wait_until(MATCH_TIMEOUT, || {
        pair.reader
            .get_matched_publication_data(h)
            .is_ok_and(|d| d.qos.writer.ownership_strength.0 == 42)
    }));
    pair.writer.write(&shape("RED", 1)).unwrap();
    assert!(wait_until(MATCH_TIMEOUT, || pair
        .writer
        .offered_deadline_missed_status()
        .total_count
        > 0));
    q.history = History::KeepLast(5);
    assert!(matches!(
        pair.writer.set_qos(&q),
        Err(DdsError::ImmutablePolicy(QosPolicyId::History))
    ));
    pair.writer.enable().unwrap();
}

#[test]
fn writer_write_w_handle() {
    let p = participant(185);
    let (wq, rq) = reliable_qos();
    let (w, r) = matched::<ShapeType>(&p, &p, "WWH", &wq, &rq);
    let red = w.register_instance(&shape("RED", 0)).unwrap();
    w.write_w_handle(&shape("RED", 5), red).unwrap();
    w.write_w_handle_timestamp(&shape("RED", 6), red, SystemTime::now())
        .unwrap();
    assert!(matches!(
        w.write_w_handle(&shape("BLUE", 5), red),
        Err(DdsError::PreconditionNotMet(_))
    ));
    let got = take_n(&r, 2);
    assert_eq!(
        got.iter()
            .filter_map(|s| s.data.as_ref())
            .map(|d| d.x)
            .collect::<Vec<_>>(),
        vec![5, 6]
    );
}

#[test]
fn writer_register_instance_w_timestamp() {
    let p = participant(186);
    let w = writer::<ShapeType>(&p, "RIT", &DataWriterQos::default());
    let h = w
        .register_instance_w_timestamp(&shape("RED", 0), SystemTime::now())
        .unwrap();
    assert!(!h.is_nil());
    assert_eq!(w.lookup_instance(&shape("RED", 9)).unwrap(), Some(h));
}

#[test]
fn writer_unregister_instance_w_timestamp() {
    let p = participant(187);
    let (wq, rq) = reliable_qos();
    let (w, r) = matched::<ShapeType>(&p, &p, "UIT", &wq, &rq);
    w.write(&shape("RED", 1)).unwrap();
    w.write(&shape("BLUE", 1)).unwrap();
    assert_eq!(take_n(&r, 2).len(), 2);
    let ts = SystemTime::UNIX_EPOCH + Duration::from_secs(2_000_000_000);
    w.unregister_instance_w_timestamp(&shape("RED", 0), ts)
        .unwrap();
    let blue = w.lookup_instance(&shape("BLUE", 0)).unwrap().unwrap();
    w.unregister_instance_w_handle_timestamp(blue, ts).unwrap();
    let got = take_n(&r, 2);
    assert_eq!(got.len(), 2);
    for s in got {
        assert_eq!(s.info.instance_state, InstanceState::NotAliveDisposed);
        assert_eq!(s.info.source_timestamp, ts);
    }
}

#[test]
fn writer_get_key_value() {
    let p = participant(188);
    let w = writer::<ShapeType>(&p, "GKV", &DataWriterQos::default());
    let h = w.register_instance(&shape("RED", 7)).unwrap();
    let k = w.get_key_value(h).unwrap();
    assert_eq!(k.color, "RED");
    assert_eq!(k.x, 0, "non-key members are defaulted");
    assert!(matches!(
        w.get_key_value(InstanceHandle(12345)),
        Err(DdsError::BadParameter(_))
    ));
}

#[test]
fn writer_get_matched_subscription_data() {
    let p1 = participant(189);
    let p2 = participant(189);
    let pair = pair(&p1, &p2, "GMS");
    let d = pair
        .writer
        .get_matched_subscription_data(pair.reader.instance_handle())
        .unwrap();
    assert_eq!(d.key, pair.reader.guid());
    assert_eq!(d.topic_name, "GMS");
    assert_eq!(d.type_name, "ShapeType");
    assert!(d.qos.reader.reliability.is_reliable());
    assert!(matches!(
        pair.writer.get_matched_subscription_data(InstanceHandle(1)),
        Err(DdsError::BadParameter(_))
    ));
}

// ---- Subscriber ----------------------------------------------------------------------------------

#[test]
fn subscriber_data_on_readers_takes_precedence() {
    let p = participant(190);
    let t = p
        .create_topic::<ShapeType>("DOR", &TopicQos::default())
        .unwrap();
    let sub = p.create_subscriber(&SubscriberQos::default()).unwrap();
    let log = Log::default();
    sub.set_listener(Box::new(log.clone()), StatusMask::DATA_ON_READERS)
        .unwrap();
    let (wq, rq) = reliable_qos();
    let r = sub.create_datareader(&t, &rq).unwrap();
    r.set_listener(Box::new(log.clone()));
    let w = writer::<ShapeType>(&p, "DOR", &wq);
    assert!(wait_until(MATCH_TIMEOUT, || r.matched_publications().len() == 1));
    w.write(&shape("RED", 1)).unwrap();
    assert!(log.wait("subscriber:data_on_readers"));
    // The reader's own on_data_available only runs through notify_datareaders, after on_data_on_readers.
    assert!(log.wait("reader:data_available"));
    let lines = log.lines();
    let dor = lines
        .iter()
        .position(|l| l == "subscriber:data_on_readers")
        .unwrap();
    let da = lines
        .iter()
        .position(|l| l.starts_with("reader:data_available"))
        .unwrap();
    assert!(dor < da, "{lines:?}");
}

#[test]
fn subscriber_status_condition_data_on_readers() {
    let p = participant(191);
    let (wq, rq) = reliable_qos();
    let (w, r) = matched::<ShapeType>(&p, &p, "SDOR", &wq, &rq);
    assert_eq!(r.topic().name(), "SDOR");
    let cond = r.subscriber().status_condition().unwrap();
    cond.set_enabled_statuses(StatusMask::DATA_ON_READERS);
    assert!(!cond.trigger_value());
    w.write(&shape("RED", 1)).unwrap();
    assert!(wait_until(MATCH_TIMEOUT, || cond.trigger_value()));
    r.take().unwrap();
    assert!(!cond.trigger_value());
}

#[test]
fn subscriber_get_datareaders() {
    let p = participant(192);
    let (wq, rq) = reliable_qos();
    let (w, r) = matched::<ShapeType>(&p, &p, "GDR", &wq, &rq);
    let sub = r.subscriber().clone();
    assert_eq!(sub.participant().guid_prefix(), p.guid_prefix());
    let any = (
        SampleStateMask::NOT_READ,
        ViewStateMask::ANY,
        InstanceStateMask::ANY,
    );
    assert!(sub.get_datareaders(any.0, any.1, any.2).unwrap().is_empty());
    w.write(&shape("RED", 1)).unwrap();
    assert!(wait_until(MATCH_TIMEOUT, || {
        sub.get_datareaders(any.0, any.1, any.2).unwrap() == vec![r.instance_handle()]
    }));
    r.take().unwrap();
    assert!(sub.get_datareaders(any.0, any.1, any.2).unwrap().is_empty());
}

#[test]
fn subscriber_listener_for_reader_statuses() {
    let p = participant(193);
    let t = p
        .create_topic::<ShapeType>("SubL", &TopicQos::default())
        .unwrap();
    let sub = p.create_subscriber(&SubscriberQos::default()).unwrap();
    let log = Log::default();
    sub.set_listener(
        Box::new(log.clone()),
        StatusMask::SUBSCRIPTION_MATCHED | StatusMask::DATA_AVAILABLE,
    )
    .unwrap();
    let r = sub
        .create_datareader(&t, &DataReaderQos::default())
        .unwrap();
    // The reader's own listener takes DATA_AVAILABLE only; SUBSCRIPTION_MATCHED goes up.
    r.set_listener_with_mask(Box::new(log.clone()), StatusMask::DATA_AVAILABLE);
    let w = writer::<ShapeType>(&p, "SubL", &DataWriterQos::default());
    let h = r.instance_handle().0;
    assert!(log.wait(&format!("subscriber:subscription_matched {h}")));
    assert!(!log.has("reader:subscription_matched"));
    w.write(&shape("RED", 1)).unwrap();
    assert!(log.wait(&format!("reader:data_available {h}")));
    assert!(!log.has("subscriber:data_available"));
    sub.clear_listener().unwrap();
}

#[test]
fn subscriber_default_datareader_qos_and_copy_from_topic_qos() {
    let p = participant(194);
    let sub = p.create_subscriber(&SubscriberQos::default()).unwrap();
    let q = DataReaderQos::builder()
        .history(History::KeepLast(4))
        .build();
    sub.set_default_datareader_qos(&q).unwrap();
    assert_eq!(sub.default_datareader_qos().unwrap(), q);
    let tq = TopicQos::builder().reliability(reliable()).build();
    let mut rq = DataReaderQos::builder().user_data(b"u".to_vec()).build();
    sub.copy_from_topic_qos(&mut rq, &tq);
    assert!(rq.reliability.is_reliable());
    assert_eq!(rq.user_data.0, b"u");
    sub.enable().unwrap();
}

#[test]
fn subscriber_delete_datareader() {
    let p1 = participant(195);
    let p2 = participant(195);
    let pair = pair(&p1, &p2, "DDR");
    pair.subscriber.delete_datareader(&pair.reader).unwrap();
    assert!(matches!(pair.reader.take(), Err(DdsError::AlreadyDeleted)));
    assert!(wait_until(MATCH_TIMEOUT, || pair
        .writer
        .matched_subscriptions()
        .is_empty()));
    assert!(matches!(
        pair.subscriber.delete_datareader(&pair.reader),
        Err(DdsError::AlreadyDeleted)
    ));
}

#[test]
fn subscriber_lookup_datareader() {
    let p = participant(196);
    let t = p
        .create_topic::<ShapeType>("LR", &TopicQos::default())
        .unwrap();
    let sub = p.create_subscriber(&SubscriberQos::default()).unwrap();
    let r = sub
        .create_datareader(&t, &DataReaderQos::default())
        .unwrap();
    assert_eq!(
        sub.lookup_datareader::<ShapeType>("LR")
            .unwrap()
            .unwrap()
            .guid(),
        r.guid()
    );
    assert!(sub.lookup_datareader::<Blob>("LR").unwrap().is_none());
}

#[test]
fn subscriber_delete_contained_entities() {
    let p = participant(197);
    let t = p
        .create_topic::<ShapeType>("SDCE", &TopicQos::default())
        .unwrap();
    let sub = p.create_subscriber(&SubscriberQos::default()).unwrap();
    let r = sub
        .create_datareader(&t, &DataReaderQos::default())
        .unwrap();
    sub.delete_contained_entities().unwrap();
    assert!(matches!(r.take(), Err(DdsError::AlreadyDeleted)));
    p.delete_subscriber(&sub).unwrap();
}

// ---- DataReader ----------------------------------------------------------------------------------

#[test]
fn reader_set_qos() {
    let p1 = participant(198);
    let p2 = participant(198);
    let pair = pair(&p1, &p2, "RQ");
    let mut q = pair.reader.get_qos().unwrap();
    q.user_data = UserData(b"ud".to_vec());
    pair.reader.set_qos(&q).unwrap();
    assert_eq!(pair.reader.get_qos().unwrap().user_data.0, b"ud");
    let h = pair.reader.instance_handle();
    assert!(wait_until(MATCH_TIMEOUT, || {
        pair.writer
            .get_matched_subscription_data(h)
            .is_ok_and(|d| d.qos.reader.user_data.0 == b"ud")
    }));
    // A requested deadline the writer offers (once it offers one) applies at once.
    let mut wq = pair.writer.get_qos().unwrap();
    wq.deadline = Deadline(Duration::from_millis(50));
    pair.writer.set_qos(&wq).unwrap();
    // Once the reader's side has seen the new offer (SEDP), a 100 ms request is compatible with it.
    let wh = pair.writer.instance_handle();
    assert!(wait_until(MATCH_TIMEOUT, || pair
        .reader
        .get_matched_publication_data(wh)
        .is_ok_and(|d| d.qos.writer.deadline == wq.deadline)));
    q.deadline = Deadline(Duration::from_millis(100));
    pair.reader.set_qos(&q).unwrap();
    std::thread::sleep(SHORT);
    assert_eq!(
        pair.reader.matched_publications().len(),
        1,
        "still compatible"
    );
    pair.writer.write(&shape("RED", 1)).unwrap();
    assert!(wait_until(MATCH_TIMEOUT, || pair
        .reader
        .requested_deadline_missed_status()
        .total_count
        > 0));
    // A requested deadline shorter than the offered one unmatches (REQUESTED_INCOMPATIBLE_QOS).
    q.deadline = Deadline(Duration::from_millis(10));
    pair.reader.set_qos(&q).unwrap();
    assert!(wait_until(MATCH_TIMEOUT, || pair
        .reader
        .matched_publications()
        .is_empty()));
    assert_eq!(
        pair.reader
            .requested_incompatible_qos_status()
            .last_policy_id,
        Some(QosPolicyId::Deadline)
    );
    let mut slow = q.clone();
    slow.time_based_filter = TimeBasedFilter {
        minimum_separation: Duration::from_secs(1),
    };
    assert!(matches!(
        pair.reader.set_qos(&slow),
        Err(DdsError::InconsistentPolicy(_))
    ));
    q.reliability = Reliability::BestEffort;
    assert!(matches!(
        pair.reader.set_qos(&q),
        Err(DdsError::ImmutablePolicy(QosPolicyId::Reliability))
    ));
    pair.reader.enable().unwrap();
}

#[test]
fn reader_get_key_value() {
    let p = participant(199);
    let (wq, rq) = reliable_qos();
    let (w, r) = matched::<ShapeType>(&p, &p, "RGKV", &wq, &rq);
    w.write(&shape("RED", 3)).unwrap();
    let s = take_n(&r, 1);
    let k = r.get_key_value(s[0].info.instance_handle).unwrap();
    assert_eq!(k.color, "RED");
    assert!(matches!(
        r.get_key_value(InstanceHandle(999_999)),
        Err(DdsError::BadParameter(_))
    ));
}

#[test]
fn reader_get_matched_publication_data() {
    let p1 = participant(200);
    let p2 = participant(200);
    let pair = pair(&p1, &p2, "GMP");
    let d = pair
        .reader
        .get_matched_publication_data(pair.writer.instance_handle())
        .unwrap();
    assert_eq!(d.key, pair.writer.guid());
    assert_eq!(d.topic_name, "GMP");
    assert_eq!(d.participant_key.map(|g| g.prefix), Some(p1.guid_prefix()));
}

#[test]
fn reader_delete_readcondition() {
    let p = participant(201);
    let r1 = reader::<ShapeType>(&p, "DRC", &DataReaderQos::default());
    let r2 = reader::<ShapeType>(&p, "DRC", &DataReaderQos::default());
    let c = r1.create_readcondition(
        SampleStateMask::ANY,
        ViewStateMask::ANY,
        InstanceStateMask::ANY,
    );
    assert!(matches!(
        r2.delete_readcondition(&c),
        Err(DdsError::PreconditionNotMet(_))
    ));
    r1.delete_readcondition(&c).unwrap();
    r1.delete_contained_entities().unwrap();
}

#[test]
fn reader_read_and_take_w_condition() {
    let p = participant(202);
    let (wq, rq) = reliable_qos();
    let (w, r) = matched::<ShapeType>(&p, &p, "RWC", &wq, &rq);
    w.write(&shape("RED", 1)).unwrap();
    w.write(&shape("BLUE", 2)).unwrap();
    assert!(wait_until(MATCH_TIMEOUT, || r.sample_count() == 2));
    let unread = r.create_readcondition(
        SampleStateMask::NOT_READ,
        ViewStateMask::ANY,
        InstanceStateMask::ANY,
    );
    let read = r.create_readcondition(
        SampleStateMask::READ,
        ViewStateMask::ANY,
        InstanceStateMask::ANY,
    );
    assert!(unread.trigger_value() && !read.trigger_value());
    assert_eq!(r.read_w_condition(&unread).unwrap().len(), 2);
    assert!(!unread.trigger_value() && read.trigger_value());
    assert_eq!(r.take_w_condition(&read).unwrap().len(), 2);
    assert_eq!(r.sample_count(), 0);
}

#[test]
fn reader_next_instance_and_next_sample() {
    let p = participant(203);
    let (wq, rq) = reliable_qos();
    let (w, r) = matched::<ShapeType>(&p, &p, "RNI", &wq, &rq);
    for (c, x) in [("RED", 1), ("BLUE", 2), ("RED", 3)] {
        w.write(&shape(c, x)).unwrap();
    }
    assert!(wait_until(MATCH_TIMEOUT, || r.sample_count() == 3));
    let one = r.read_next_sample().unwrap().expect("an unread sample");
    assert_eq!(one.info.sample_state, SampleState::NotRead);
    let first = r.read_next_instance(InstanceHandle::NIL).unwrap();
    assert!(!first.is_empty());
    let h = first[0].info.instance_handle;
    assert!(first.iter().all(|s| s.info.instance_handle == h));
    // read/take_next_instance_w_condition: the selector with a state filter.
    let next = r
        .select()
        .next_instance(h)
        .sample_state(SampleStateMask::NOT_READ)
        .take()
        .unwrap();
    assert!(!next.is_empty() && next.iter().all(|s| s.info.instance_handle != h));
    assert_eq!(r.take_instance(h).unwrap().len(), first.len());
    assert_eq!(first.len() + next.len(), 3);
    assert!(r.take_next_sample().unwrap().is_none());
}
