//! enable() and ENTITY_FACTORY.autoenable_created_entities (DDS 1.4 §2.2.2.1.1.7): entities created
//! disabled announce nothing and match nothing, refuse their other operations with `NotEnabled`, cannot
//! be enabled before their factory (`PreconditionNotMet`), and an enabled factory that autoenables enables
//! what it created disabled. Run inside `scripts/isolated` (loopback only).
mod dcps_util;

use std::time::Duration;

use dcps_util::*;
use dds_runtime::prelude::*;

/// Long enough for discovery to have happened had anything been announced (SPDP every 200 ms).
const QUIET: Duration = Duration::from_millis(1200);

/// A subscriber whose readers are created disabled.
fn subscriber_without_autoenable(p: &DomainParticipant) -> Subscriber {
    p.create_subscriber(
        &SubscriberQos::builder()
            .autoenable_created_entities(false)
            .build(),
    )
    .unwrap()
}

fn no_autoenable_participant() -> DomainParticipantQos {
    DomainParticipantQos::builder()
        .autoenable_created_entities(false)
        .build()
}

#[test]
fn factory_without_autoenable_creates_a_silent_participant() {
    let f = DomainParticipantFactory::get_instance();
    let off = DomainParticipantFactoryQos::builder()
        .autoenable_created_entities(false)
        .build();
    f.set_qos(&off).unwrap();
    let quiet = participant(224);
    f.set_qos(&DomainParticipantFactoryQos::default()).unwrap();
    let other = participant(224);
    assert!(!quiet.is_enabled());
    assert!(other.is_enabled());
    assert!(matches!(
        quiet.assert_liveliness(),
        Err(DdsError::NotEnabled)
    ));
    // Not announced, and deaf: neither side discovers the other.
    std::thread::sleep(QUIET);
    assert!(other.discovered_participants().is_empty());
    assert!(quiet.discovered_participants().is_empty());
    // Children of a disabled participant are disabled whatever its QoS says, and cannot be enabled.
    let publisher = quiet.create_publisher(&PublisherQos::default()).unwrap();
    assert!(!publisher.is_enabled());
    assert!(matches!(
        publisher.enable(),
        Err(DdsError::PreconditionNotMet(_))
    ));
    quiet.enable().unwrap();
    quiet.enable().unwrap();
    assert!(quiet.is_enabled());
    // Its QoS autoenables: enabling it enabled the publisher too.
    assert!(publisher.is_enabled());
    assert!(wait_until(MATCH_TIMEOUT, || other
        .discovered_participants()
        .len()
        == 1));
    assert!(wait_until(MATCH_TIMEOUT, || quiet
        .discovered_participants()
        .len()
        == 1));
}

#[test]
fn disabled_writer_is_not_announced_until_enabled() {
    let pw = participant(225);
    let pr = participant(225);
    let r = reader::<ShapeType>(&pr, "Enable", &DataReaderQos::default());
    let t = pw
        .create_topic::<ShapeType>("Enable", &TopicQos::default())
        .unwrap();
    let publisher = pw
        .create_publisher(
            &PublisherQos::builder()
                .autoenable_created_entities(false)
                .build(),
        )
        .unwrap();
    assert!(publisher.is_enabled());
    let w = publisher
        .create_datawriter(&t, &DataWriterQos::default())
        .unwrap();
    assert!(!w.is_enabled());
    assert!(matches!(
        w.write(&shape("RED", 1)),
        Err(DdsError::NotEnabled)
    ));
    assert!(matches!(w.assert_liveliness(), Err(DdsError::NotEnabled)));
    // QoS, listener and status condition are allowed on a disabled entity.
    w.set_qos(&DataWriterQos::builder().user_data(b"late".to_vec()).build())
        .unwrap();
    let _ = w.status_condition();
    assert!(wait_until(MATCH_TIMEOUT, || pr
        .discovered_participants()
        .len()
        == 1));
    std::thread::sleep(QUIET);
    assert_eq!(r.subscription_matched_status().current_count, 0);
    assert_eq!(w.publication_matched_status().current_count, 0);
    w.enable().unwrap();
    assert!(w.is_enabled());
    assert!(wait_until(MATCH_TIMEOUT, || {
        w.publication_matched_status().current_count == 1
    }));
    assert!(wait_until(MATCH_TIMEOUT, || {
        r.subscription_matched_status().current_count == 1
    }));
    // The QoS set while disabled is what was announced.
    let seen = r.get_matched_publication_data(w.instance_handle()).unwrap();
    assert_eq!(seen.qos.writer.user_data.0, b"late");
    w.write(&shape("RED", 2)).unwrap();
    assert!(r.wait_for_data(MATCH_TIMEOUT).unwrap());
    assert_eq!(r.take().unwrap()[0].data.as_ref().unwrap().x, 2);
}

#[test]
fn disabled_reader_matches_once_enabled_and_deleting_it_announces_nothing() {
    let pw = participant(226);
    let pr = participant(226);
    let w = writer::<ShapeType>(&pw, "EnableR", &DataWriterQos::default());
    let t = pr
        .create_topic::<ShapeType>("EnableR", &TopicQos::default())
        .unwrap();
    let sub = subscriber_without_autoenable(&pr);
    let gone = sub
        .create_datareader::<ShapeType, _>(&t, &DataReaderQos::default())
        .unwrap();
    sub.delete_datareader(&gone).unwrap();
    let r = sub
        .create_datareader::<ShapeType, _>(&t, &DataReaderQos::default())
        .unwrap();
    assert!(matches!(r.take(), Err(DdsError::NotEnabled)));
    assert!(matches!(
        r.wait_for_data(Duration::ZERO),
        Err(DdsError::NotEnabled)
    ));
    std::thread::sleep(QUIET);
    assert_eq!(w.publication_matched_status().current_count, 0);
    // The subscriber is enabled already (only its children start disabled): enabling it changes nothing.
    sub.enable().unwrap();
    assert!(!r.is_enabled());
    r.enable().unwrap();
    assert!(wait_until(MATCH_TIMEOUT, || {
        w.publication_matched_status().current_count == 1
    }));
    assert_eq!(r.take().unwrap().len(), 0);
}

#[test]
fn enabling_follows_the_factory_chain() {
    let p = participant(227);
    p.set_qos(&no_autoenable_participant()).unwrap();
    let t = p
        .create_topic::<ShapeType>("Chain", &TopicQos::default())
        .unwrap();
    let publisher = p.create_publisher(&PublisherQos::default()).unwrap();
    assert!(!t.is_enabled() && !publisher.is_enabled());
    let w = publisher
        .create_datawriter(&t, &DataWriterQos::default())
        .unwrap();
    assert!(!w.is_enabled());
    // The writer's publisher is disabled.
    assert!(matches!(w.enable(), Err(DdsError::PreconditionNotMet(_))));
    // The publisher autoenables: enabling it enables the writer, but not while the topic is disabled.
    publisher.enable().unwrap();
    assert!(publisher.is_enabled());
    assert!(!w.is_enabled());
    assert!(matches!(w.enable(), Err(DdsError::PreconditionNotMet(_))));
    t.enable().unwrap();
    w.enable().unwrap();
    assert!(w.is_enabled());
    w.write(&shape("RED", 1)).unwrap();
    // Entities created after autoenable is switched back on are enabled.
    p.set_qos(&DomainParticipantQos::default()).unwrap();
    assert!(p
        .create_subscriber(&SubscriberQos::default())
        .unwrap()
        .is_enabled());
}

/// Immutable policies may change until the entity is enabled (DDS 1.4 §2.2.2.1.1.7): a disabled writer
/// and reader take a new durability, history and data representation, and behave by them once enabled;
/// after that the same change is `ImmutablePolicy`.
#[test]
fn immutable_policies_change_until_enabled() {
    let pw = participant(207);
    let pr = participant(207);
    let no_autoenable = || {
        PublisherQos::builder()
            .autoenable_created_entities(false)
            .build()
    };
    let tw = pw
        .create_topic::<ShapeType>("Respecify", &TopicQos::default())
        .unwrap();
    let w = pw
        .create_publisher(&no_autoenable())
        .unwrap()
        .create_datawriter(&tw, &DataWriterQos::default())
        .unwrap();
    // ShapeType is appendable: XCDR2 unless told otherwise.
    assert_eq!(w.data_representation(), XcdrVersion::Xcdr2);
    let durable = DataWriterQos {
        durability: Durability::TransientLocal,
        history: History::KeepLast(5),
        data_representation: DataRepresentation::xcdr1(),
        ..w.get_qos().unwrap()
    };
    w.set_qos(&durable).unwrap();
    assert_eq!(w.get_qos().unwrap().history, History::KeepLast(5));
    assert_eq!(w.data_representation(), XcdrVersion::Xcdr1);
    w.enable().unwrap();
    let volatile = DataWriterQos {
        durability: Durability::Volatile,
        ..durable.clone()
    };
    assert!(matches!(
        w.set_qos(&volatile),
        Err(DdsError::ImmutablePolicy(QosPolicyId::Durability))
    ));
    for x in 0..8 {
        w.write(&shape("RED", x)).unwrap();
    }

    assert!(wait_until(MATCH_TIMEOUT, || !pr
        .discovered_participants()
        .is_empty()));
    let tr = pr
        .create_topic::<ShapeType>("Respecify", &TopicQos::default())
        .unwrap();
    let sub = subscriber_without_autoenable(&pr);
    let r = sub
        .create_datareader::<ShapeType, _>(&tr, &DataReaderQos::default())
        .unwrap();
    // Reliable as well: a best-effort late joiner gets the history once, with no repair, and loses it when
    // the history arrives before the reader has matched the writer (about one run in three).
    let late_joiner = DataReaderQos {
        durability: Durability::TransientLocal,
        history: History::KeepAll,
        reliability: Reliability::RELIABLE,
        ..r.get_qos().unwrap()
    };
    r.set_qos(&late_joiner).unwrap();
    r.enable().unwrap();
    // The writer's history kept the last 5 of the 8 (KEEP_LAST 5, not the default 1), and the reader,
    // TRANSIENT_LOCAL, reliable and KEEP_ALL by now, gets all of them.
    let got = take_n(&r, 5);
    let xs: Vec<i32> = got
        .iter()
        .filter_map(|s| s.data.as_ref())
        .map(|d| d.x)
        .collect();
    assert_eq!(xs, vec![3, 4, 5, 6, 7]);
    assert!(matches!(
        r.set_qos(&DataReaderQos {
            durability: Durability::Volatile,
            ..late_joiner
        }),
        Err(DdsError::ImmutablePolicy(QosPolicyId::Durability))
    ));
}

/// Topics, publishers and subscribers created disabled take every policy, immutable ones included, until
/// enabled; then those give `ImmutablePolicy`. What was set before `enable()` is what the readers and
/// writers announce and match with: a PRESENTATION changed on a disabled publisher lets its writers (one
/// created before the change, one after) match a reader requesting coherent TOPIC access, and one changed
/// on a disabled subscriber makes its reader refuse a writer that offers less.
#[test]
fn group_and_topic_policies_change_until_enabled() {
    let pw = participant(225);
    let pr = participant(225);
    pw.set_qos(&no_autoenable_participant()).unwrap();
    let coherent = Presentation {
        access_scope: PresentationAccessScope::Topic,
        coherent_access: true,
        ordered_access: false,
    };
    // The topic.
    let topic = pw
        .create_topic::<ShapeType>("GroupBeforeEnable", &TopicQos::default())
        .unwrap();
    assert!(!topic.is_enabled());
    let durable = TopicQos::builder()
        .durability(Durability::TransientLocal)
        .build();
    topic.set_qos(&durable).unwrap();
    assert_eq!(topic.get_qos().unwrap(), durable);
    topic.enable().unwrap();
    assert!(matches!(
        topic.set_qos(&TopicQos::default()),
        Err(DdsError::ImmutablePolicy(QosPolicyId::Durability))
    ));
    // The publisher: one writer before the change, one after.
    let publisher = pw.create_publisher(&PublisherQos::default()).unwrap();
    assert!(!publisher.is_enabled());
    let early = publisher
        .create_datawriter(&topic, &DataWriterQos::default())
        .unwrap();
    let pq = PublisherQos::builder().presentation(coherent).build();
    publisher.set_qos(&pq).unwrap();
    assert_eq!(publisher.get_qos().unwrap().presentation, coherent);
    let late = publisher
        .create_datawriter(&topic, &DataWriterQos::default())
        .unwrap();
    publisher.enable().unwrap();
    assert!(early.is_enabled() && late.is_enabled());
    assert!(matches!(
        publisher.set_qos(&PublisherQos::default()),
        Err(DdsError::ImmutablePolicy(QosPolicyId::Presentation))
    ));
    // The subscriber.
    let subscriber = pw.create_subscriber(&SubscriberQos::default()).unwrap();
    subscriber
        .set_qos(&SubscriberQos::builder().presentation(coherent).build())
        .unwrap();
    let strict = subscriber
        .create_datareader::<ShapeType, _>(&topic, &DataReaderQos::default())
        .unwrap();
    subscriber.enable().unwrap();
    assert!(matches!(
        subscriber.set_qos(&SubscriberQos::default()),
        Err(DdsError::ImmutablePolicy(QosPolicyId::Presentation))
    ));

    // The other participant: a reader requesting coherent TOPIC access, a writer offering the default.
    let tr = pr
        .create_topic::<ShapeType>("GroupBeforeEnable", &TopicQos::default())
        .unwrap();
    let wants = pr
        .create_subscriber(&SubscriberQos::builder().presentation(coherent).build())
        .unwrap()
        .create_datareader::<ShapeType, _>(&tr, &DataReaderQos::default())
        .unwrap();
    let plain = writer_on::<ShapeType>(&pr, &tr);
    assert!(
        wait_until(MATCH_TIMEOUT, || wants.matched_publications().len() == 2),
        "both writers of the changed publisher match: {:?}",
        wants.requested_incompatible_qos_status()
    );
    assert!(wait_until(MATCH_TIMEOUT, || {
        strict.requested_incompatible_qos_status().total_count >= 1
    }));
    assert!(!strict.matched_publication_guids().contains(&plain.guid()));
    assert!(!wants.matched_publication_guids().contains(&plain.guid()));
    assert!(wants.matched_publication_guids().contains(&early.guid()));
}

fn writer_on<T: DdsType>(p: &DomainParticipant, t: &Topic<T>) -> DataWriter<T> {
    p.create_publisher(&PublisherQos::default())
        .unwrap()
        .create_datawriter(t, &DataWriterQos::default())
        .unwrap()
}
