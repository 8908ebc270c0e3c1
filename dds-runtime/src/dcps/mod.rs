//! The typed DCPS API (DDS 1.4 §2.2.2): [`DomainParticipant`], [`Topic`], [`Publisher`], [`Subscriber`],
//! [`DataWriter`], [`DataReader`], conditions and waitsets, listeners and content filters.
//!
//! ```no_run
//! use dds_runtime::prelude::*;
//! # fn demo<T: DdsType + Clone>(sample: T) -> Result<(), DdsError> {
//! let participant = DomainParticipant::builder().domain_id(0).build()?;
//! let topic = participant.create_topic::<T>("Square", &TopicQos::default())?;
//! let publisher = participant.create_publisher(&PublisherQos::default())?;
//! let writer = publisher.create_datawriter(&topic, &DataWriterQos::default())?;
//! writer.write(&sample)?;
//! let subscriber = participant.create_subscriber(&SubscriberQos::default())?;
//! let reader = subscriber.create_datareader(&topic, &DataReaderQos::default())?;
//! if reader.wait_for_data(std::time::Duration::from_secs(1))? {
//!     for s in reader.take()? {
//!         println!("{:?} valid={}", s.info.instance_state, s.info.valid_data);
//!     }
//! }
//! # Ok(()) }
//! ```
//!
//! Threads: each participant runs one receive thread per socket and one timer thread. Writes send on the
//! calling thread (the core lock is never held across a socket call). Listeners run on the receive or
//! timer thread, with no internal lock held.
//!
//! Instances are identified by the serialized key ([`crate::cdr::instance_key`]), never by the key hash
//! alone; a key-only dispose/unregister is mapped to its instance through its key payload, or through its
//! key hash when a sample of that instance carrying the same hash was seen before.

pub mod builtin;
mod builtin_cdr;
mod builtin_subscriber;
mod cache;
mod chain;
pub mod condition;
mod data_on_readers;
mod decode;
mod driver;
pub mod durability;
mod dynamic;
mod enable;
mod endpoint;
mod error;
pub mod filter;
pub mod listener;
mod participant;
#[cfg(feature = "shm")]
mod plain;
mod presentation;
mod process_info;
mod publisher;
mod registry;
pub mod sample;
#[cfg(feature = "shm")]
mod shm;
mod stand_in;
pub mod status;
mod subscriber;
mod sync;
mod topic;
mod writer_filter;

/// GUIDs name entities in the DCPS API ([`DataWriter::guid`], [`SampleInfo::publication_guid`], ...).
pub use crate::rtps::{Guid, GuidPrefix};
pub use builtin::{
    EndpointBuiltinTopicData, ParticipantBuiltinTopicData, PublicationBuiltinTopicData,
    SubscriptionBuiltinTopicData, TopicBuiltinTopicData,
};
pub use builtin_subscriber::BuiltinSubscriber;
pub use chain::StatusChange;
pub use condition::{
    Condition, GuardCondition, QueryCondition, ReadCondition, StatusCondition, WaitSet,
};
pub use durability::{DurabilityServiceConfig, DurabilityServiceMode};
pub use dynamic::{
    DynamicReader, DynamicReaderListener, DynamicSample, DynamicTopic, DynamicWriter,
    DynamicWriterListener,
};
pub use error::{DdsError, DdsResult};
pub use filter::{ContentFilter, FieldValue, FilterError, FilterFields};
pub use listener::{
    DataReaderListener, DataWriterListener, DomainParticipantListener, PublisherListener,
    SubscriberListener, TopicListener,
};
pub use participant::{
    DiscoveredParticipant, DiscoveredType, DomainParticipant, DomainParticipantBuilder,
    DomainParticipantFactory, WriteBatching,
};
#[cfg(feature = "shm")]
pub use plain::InPlace;
pub use publisher::{DataWriter, Publisher};
#[cfg(feature = "shm")]
pub use publisher::{LoanError, SampleLoan};
pub use sample::{
    InstanceHandle, InstanceState, InstanceStateMask, Sample, SampleInfo, SampleState,
    SampleStateMask, ViewState, ViewStateMask,
};
pub use status::*;
pub use subscriber::{DataReader, SampleStream, Selector, Subscriber};
pub use topic::{ContentFilteredTopic, Topic, TopicDescription};
