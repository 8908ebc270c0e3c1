//! Listener traits. Listeners run on the thread that processed the triggering datagram or timeout (a
//! receive thread or the timer thread), after every internal lock has been released, so they may call
//! back into the entities (read, take, write). Keep them short: they delay the processing of later traffic.
//!
//! The traits are defined next to the entity they serve and re-exported here. A status goes to the most
//! specific listener enabled for it (DDS 1.4 §2.2.4.1): the reader's or writer's own (see
//! `set_listener_with_mask`), else its subscriber's or publisher's, else its participant's.
//! DATA_ON_READERS (subscriber, then participant) takes precedence over DATA_AVAILABLE.

pub use super::dynamic::{DynamicReaderListener, DynamicWriterListener};
pub use super::participant::DomainParticipantListener;
pub use super::publisher::{DataWriterListener, PublisherListener};
pub use super::subscriber::{DataReaderListener, SubscriberListener};
pub use super::topic::TopicListener;
