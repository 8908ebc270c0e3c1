//! Writers and readers of any variant behind one type-erased interface, created by variant number.

use dds_runtime::prelude::*;

use super::*;

/// A writer of some variant, its type erased.
pub(crate) trait AnyWriter {
    /// Matched readers now.
    fn matched(&self) -> i32;
    /// Writes `f` in the writer's type.
    fn write(&self, f: &Fields);
    /// The offered-incompatible-QoS status.
    fn incompatible(&self) -> IncompatibleQosStatus;
    /// The variant's (`z`, `angle`).
    fn has(&self) -> (bool, bool);
}

/// A reader of some variant, its type erased.
pub(crate) trait AnyReader {
    /// Matched writers now.
    fn matched(&self) -> i32;
    /// Takes the samples with data, as [`Fields`].
    fn take(&self) -> Vec<Fields>;
    /// The requested-incompatible-QoS status.
    fn incompatible(&self) -> IncompatibleQosStatus;
    /// The variant's (`z`, `angle`).
    fn has(&self) -> (bool, bool);
}

impl<T: Variant> AnyWriter for DataWriter<T> {
    fn matched(&self) -> i32 {
        self.publication_matched_status().current_count as i32
    }
    fn write(&self, f: &Fields) {
        DataWriter::write(self, &T::from_fields(f)).expect("write");
    }
    fn incompatible(&self) -> IncompatibleQosStatus {
        self.offered_incompatible_qos_status()
    }
    fn has(&self) -> (bool, bool) {
        T::HAS
    }
}

impl<T: Variant> AnyReader for DataReader<T> {
    fn matched(&self) -> i32 {
        self.subscription_matched_status().current_count as i32
    }
    fn take(&self) -> Vec<Fields> {
        DataReader::take(self)
            .expect("take")
            .into_iter()
            .filter_map(|s| s.data().map(|d| d.fields()))
            .collect()
    }
    fn incompatible(&self) -> IncompatibleQosStatus {
        self.requested_incompatible_qos_status()
    }
    fn has(&self) -> (bool, bool) {
        T::HAS
    }
}

/// Variant `k`'s (`z`, `angle`).
pub(crate) fn has(k: usize) -> (bool, bool) {
    macro_rules! check {
        ($t:ty) => {
            if <$t>::INDEX == k {
                return <$t>::HAS;
            }
        };
    }
    for_each_variant!(check);
    panic!("no shape variant {k}")
}

/// A writer of variant `k` on topic `topic` (created on `p`), in `publisher`.
pub(crate) fn new_writer(
    k: usize,
    p: &DomainParticipant,
    publisher: &Publisher,
    topic: &str,
    qos: &DataWriterQos,
) -> Box<dyn AnyWriter> {
    macro_rules! make {
        ($t:ty) => {
            if <$t>::INDEX == k {
                let t = p
                    .create_topic::<$t>(topic, &TopicQos::default())
                    .expect("topic");
                return Box::new(publisher.create_datawriter(&t, qos).expect("writer"));
            }
        };
    }
    for_each_variant!(make);
    panic!("no shape variant {k}")
}

/// A reader of variant `k` on topic `topic` (created on `p`), in `subscriber`.
pub(crate) fn new_reader(
    k: usize,
    p: &DomainParticipant,
    subscriber: &Subscriber,
    topic: &str,
    qos: &DataReaderQos,
) -> Box<dyn AnyReader> {
    macro_rules! make {
        ($t:ty) => {
            if <$t>::INDEX == k {
                let t = p
                    .create_topic::<$t>(topic, &TopicQos::default())
                    .expect("topic");
                return Box::new(subscriber.create_datareader(&t, qos).expect("reader"));
            }
        };
    }
    for_each_variant!(make);
    panic!("no shape variant {k}")
}
