//! What makes a reader typed or dynamic: its sample type and codec, its listener trait and its public
//! handle. One reader machinery ([`ReaderInner`]: queue, decoding, cache, statuses, listeners, status
//! condition, read conditions) serves [`DataReader<T>`] and
//! [`DynamicReader`](crate::dcps::DynamicReader) alike.

use std::marker::PhantomData;
use std::sync::Arc;

use crate::cdr::DdsType;
use crate::filter::FilterFields;
use crate::qos::DataReaderQos;

use super::super::decode::{Derived, SampleCodec};
use super::super::driver::EndpointHandle;
use super::super::error::DdsResult;
use super::super::status::{
    DeadlineMissedStatus, IncompatibleQosStatus, LivelinessChangedStatus, SampleLostStatus,
    SampleRejectedStatus, SubscriptionMatchedStatus,
};
use super::{DataReader, DataReaderListener, ReaderInner, ReaderOwner};

/// Makes an instance's key holder (its key members set, the others defaulted) from a sample.
pub(crate) type KeyHolderFn<T> = fn(&T) -> Option<T>;

/// A flavour of reader.
pub(crate) trait ReaderKind: Sized + Send + Sync + 'static {
    /// The sample type the cache holds.
    type Data: FilterFields + Send + Sync + 'static;
    /// Decodes samples and identifies instances.
    type Codec: SampleCodec<Self::Data> + Send + Sync + 'static;
    /// The listener trait object.
    type Listener: ?Sized + ReaderCallbacks<Self::Reader> + Send + Sync + 'static;
    /// What the reader's handle keeps alive.
    type Owner: Send + Sync + 'static;
    /// The public reader handed to listeners.
    type Reader;
    /// The public reader of `inner`.
    fn reader(
        inner: Arc<ReaderInner<Self>>,
        handle: Arc<EndpointHandle<Self::Owner>>,
    ) -> Self::Reader;
    /// Announces `reader` again with `qos` and its subscriber's and topic's QoS now (they changed).
    fn announce(reader: &Self::Reader, qos: DataReaderQos) -> DdsResult<()>;
    /// Enables `reader` (`enable`).
    fn enable(reader: Self::Reader) -> DdsResult<()>;
    /// What makes the key holder of a new instance from its first sample (for `get_key_value`), if the
    /// kind's cache keeps one that way.
    fn key_holder() -> Option<KeyHolderFn<Self::Data>> {
        None
    }
}

/// The calls a reader makes on its listener, whatever the listener trait (`R` is the public reader).
pub(crate) trait ReaderCallbacks<R> {
    fn data_available(&self, r: &R);
    fn subscription_matched(&self, r: &R, s: SubscriptionMatchedStatus);
    fn requested_incompatible_qos(&self, r: &R, s: IncompatibleQosStatus);
    fn sample_lost(&self, r: &R, s: SampleLostStatus);
    fn sample_rejected(&self, r: &R, s: SampleRejectedStatus);
    fn liveliness_changed(&self, r: &R, s: LivelinessChangedStatus);
    fn requested_deadline_missed(&self, r: &R, s: DeadlineMissedStatus);
}

/// Implements [`ReaderCallbacks`] for a listener trait object whose methods have the standard names.
macro_rules! reader_callbacks {
    ($(@$g:ident: $b:path;)? $listener:ty, $reader:ty) => {
        impl$(<$g: $b>)? $crate::dcps::subscriber::ReaderCallbacks<$reader> for $listener {
            fn data_available(&self, r: &$reader) {
                self.on_data_available(r)
            }
            fn subscription_matched(&self, r: &$reader, s: $crate::dcps::SubscriptionMatchedStatus) {
                self.on_subscription_matched(r, s)
            }
            fn requested_incompatible_qos(&self, r: &$reader, s: $crate::dcps::IncompatibleQosStatus) {
                self.on_requested_incompatible_qos(r, s)
            }
            fn sample_lost(&self, r: &$reader, s: $crate::dcps::SampleLostStatus) {
                self.on_sample_lost(r, s)
            }
            fn sample_rejected(&self, r: &$reader, s: $crate::dcps::SampleRejectedStatus) {
                self.on_sample_rejected(r, s)
            }
            fn liveliness_changed(&self, r: &$reader, s: $crate::dcps::LivelinessChangedStatus) {
                self.on_liveliness_changed(r, s)
            }
            fn requested_deadline_missed(&self, r: &$reader, s: $crate::dcps::DeadlineMissedStatus) {
                self.on_requested_deadline_missed(r, s)
            }
        }
    };
}
pub(crate) use reader_callbacks;

/// The reader of a derived type `T`.
pub(crate) struct Typed<T>(PhantomData<fn() -> T>);

reader_callbacks!(@T: DdsType; dyn DataReaderListener<T>, DataReader<T>);

impl<T: DdsType> ReaderKind for Typed<T> {
    type Data = T;
    type Codec = Derived;
    type Listener = dyn DataReaderListener<T>;
    type Owner = ReaderOwner<T>;
    type Reader = DataReader<T>;
    fn reader(
        inner: Arc<ReaderInner<Self>>,
        handle: Arc<EndpointHandle<ReaderOwner<T>>>,
    ) -> DataReader<T> {
        DataReader { inner, handle }
    }
    fn announce(reader: &DataReader<T>, qos: DataReaderQos) -> DdsResult<()> {
        reader.announce(qos)
    }
    fn enable(reader: DataReader<T>) -> DdsResult<()> {
        reader.enable()
    }
    fn key_holder() -> Option<KeyHolderFn<T>> {
        T::IS_KEYED.then_some(super::ops::key_holder::<T>)
    }
}
