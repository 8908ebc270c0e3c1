//! Listener traits. Listeners run on the thread that processed the triggering datagram or timeout (a
//! receive thread or the timer thread), after every internal lock has been released, so they may call
//! back into the entities (read, take, write). Keep them short: they delay the processing of later traffic.

use super::publisher::DataWriter;
use super::status::{
    DeadlineMissedStatus, IncompatibleQosStatus, LivelinessChangedStatus, PublicationMatchedStatus,
    SampleLostStatus, SampleRejectedStatus, SubscriptionMatchedStatus,
};
use super::subscriber::DataReader;
use crate::cdr::DdsType;

/// Callbacks of a [`DataReader`]. Every method has an empty default.
#[allow(unused_variables)]
pub trait DataReaderListener<T: DdsType>: Send + Sync {
    /// New samples (or instance state changes) are available.
    fn on_data_available(&self, reader: &DataReader<T>) {}
    /// A writer matched or unmatched.
    fn on_subscription_matched(&self, reader: &DataReader<T>, status: SubscriptionMatchedStatus) {}
    /// A writer was found with incompatible QoS.
    fn on_requested_incompatible_qos(&self, reader: &DataReader<T>, status: IncompatibleQosStatus) {
    }
    /// Samples were lost.
    fn on_sample_lost(&self, reader: &DataReader<T>, status: SampleLostStatus) {}
    /// A sample was rejected by a resource limit.
    fn on_sample_rejected(&self, reader: &DataReader<T>, status: SampleRejectedStatus) {}
    /// A matched writer's liveliness changed.
    fn on_liveliness_changed(&self, reader: &DataReader<T>, status: LivelinessChangedStatus) {}
    /// An instance missed its deadline.
    fn on_requested_deadline_missed(&self, reader: &DataReader<T>, status: DeadlineMissedStatus) {}
}

/// Callbacks of a [`DataWriter`]. Every method has an empty default.
#[allow(unused_variables)]
pub trait DataWriterListener<T: DdsType>: Send + Sync {
    /// A reader matched or unmatched.
    fn on_publication_matched(&self, writer: &DataWriter<T>, status: PublicationMatchedStatus) {}
    /// A reader was found with incompatible QoS.
    fn on_offered_incompatible_qos(&self, writer: &DataWriter<T>, status: IncompatibleQosStatus) {}
    /// The writer missed its offered deadline for an instance.
    fn on_offered_deadline_missed(&self, writer: &DataWriter<T>, status: DeadlineMissedStatus) {}
}
