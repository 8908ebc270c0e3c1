//! `Topic<T>` and `ContentFilteredTopic<T>`.

mod ops;

use std::marker::PhantomData;
use std::sync::{Arc, Mutex, RwLock};

use crate::cdr::DdsType;
use crate::qos::TopicQos;
use crate::rtps::discovery::ContentFilterProperty;
use crate::rtps::EntityId;

use super::error::{DdsError, DdsResult};
use super::filter::{ContentFilter, FilterFields};
use super::participant::DomainParticipant;
use super::sync::{lock, read, write};

pub use ops::TopicListener;

struct TopicInner {
    participant: DomainParticipant,
    name: String,
    qos: TopicQos,
}

impl Drop for TopicInner {
    /// The last handle is gone: the topic's SEDP announcement is withdrawn.
    fn drop(&mut self) {
        self.participant
            .withdraw_topic(self as *const TopicInner as *const ());
    }
}

/// A named topic of type `T` in a participant.
pub struct Topic<T> {
    inner: Arc<TopicInner>,
    _t: PhantomData<fn() -> T>,
}

impl<T> Clone for Topic<T> {
    fn clone(&self) -> Self {
        Topic {
            inner: self.inner.clone(),
            _t: PhantomData,
        }
    }
}

impl<T: DdsType> std::fmt::Debug for Topic<T> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Topic")
            .field("name", &self.inner.name)
            .field("type", &T::TYPE_NAME)
            .finish()
    }
}

impl<T: DdsType> Topic<T> {
    /// The topic name.
    pub fn name(&self) -> &str {
        &self.inner.name
    }
    /// The IDL type name (`T::TYPE_NAME`).
    pub fn type_name(&self) -> &'static str {
        T::TYPE_NAME
    }
    /// The QoS the topic was created with; `get_qos` returns the one in effect after `set_qos`.
    pub fn qos(&self) -> &TopicQos {
        &self.inner.qos
    }
    /// The participant.
    pub fn participant(&self) -> &DomainParticipant {
        &self.inner.participant
    }
}

type SampleFilter<T> = Box<dyn Fn(&T) -> bool + Send + Sync>;

/// What a reader can be created on: a [`Topic`] or a [`ContentFilteredTopic`].
pub trait TopicDescription<T: DdsType> {
    /// The underlying topic.
    fn topic(&self) -> &Topic<T>;
    /// The sample filter, if any.
    #[doc(hidden)]
    fn sample_filter(&self) -> Option<SampleFilter<T>> {
        None
    }
    /// The filter readers announce in SEDP (PID_CONTENT_FILTER_PROPERTY), if any.
    #[doc(hidden)]
    fn content_filter_property(&self) -> Option<ContentFilterProperty> {
        None
    }
    /// A reader was created on this description (a content-filtered topic re-announces it when its
    /// parameters change).
    #[doc(hidden)]
    fn reader_created(&self, _reader: EntityId) {}
}

impl<T: DdsType> TopicDescription<T> for Topic<T> {
    fn topic(&self) -> &Topic<T> {
        self
    }
}

/// A topic whose readers only see samples for which the filter expression holds. The filter runs in the
/// reader on every sample that arrives; readers also announce it in SEDP (PID_CONTENT_FILTER_PROPERTY, class
/// `DDSSQL`) with the parameters they were created with.
pub struct ContentFilteredTopic<T> {
    topic: Topic<T>,
    name: String,
    filter: Arc<RwLock<ContentFilter>>,
    /// The readers created on it, to re-announce when the parameters change.
    readers: Arc<Mutex<Vec<EntityId>>>,
}

impl<T> Clone for ContentFilteredTopic<T> {
    fn clone(&self) -> Self {
        ContentFilteredTopic {
            topic: self.topic.clone(),
            name: self.name.clone(),
            filter: self.filter.clone(),
            readers: self.readers.clone(),
        }
    }
}

impl<T: DdsType + FilterFields> ContentFilteredTopic<T> {
    /// The name of this filtered topic.
    pub fn name(&self) -> &str {
        &self.name
    }
    /// The filter expression.
    pub fn filter_expression(&self) -> String {
        read(&self.filter).expression().to_string()
    }
    /// The current parameters.
    pub fn expression_parameters(&self) -> Vec<String> {
        read(&self.filter).parameters().to_vec()
    }
    /// Changes the parameters; readers created on this topic apply them to samples received from now on,
    /// and announce them again in SEDP so that writers filtering for them use them too (a writer that has
    /// not yet seen the new announcement may still skip a sample that the new parameters accept).
    pub fn set_expression_parameters<S: AsRef<str>>(&self, params: &[S]) -> DdsResult<()> {
        write(&self.filter).set_parameters(params)?;
        let property = self.content_filter_property();
        let readers = lock(&self.readers).clone();
        self.topic.participant().driver().with_core(|c, now| {
            for r in readers {
                c.set_reader_content_filter(now, r, property.clone());
            }
        });
        Ok(())
    }
}

impl<T: DdsType + FilterFields> TopicDescription<T> for ContentFilteredTopic<T> {
    fn topic(&self) -> &Topic<T> {
        &self.topic
    }
    fn sample_filter(&self) -> Option<SampleFilter<T>> {
        let f = self.filter.clone();
        Some(Box::new(move |s: &T| read(&f).matches(s)))
    }
    fn reader_created(&self, reader: EntityId) {
        lock(&self.readers).push(reader);
    }
    fn content_filter_property(&self) -> Option<ContentFilterProperty> {
        let f = read(&self.filter);
        Some(ContentFilterProperty::ddssql(
            &self.name,
            self.topic.name(),
            f.expression(),
            f.parameters().to_vec(),
        ))
    }
}

impl DomainParticipant {
    /// Creates a topic of type `T`.
    pub fn create_topic<T: DdsType>(&self, name: &str, qos: &TopicQos) -> DdsResult<Topic<T>> {
        self.driver().check_alive()?;
        if name.is_empty() || name.len() > 256 {
            return Err(DdsError::BadParameter(format!("topic name {name:?}")));
        }
        let topic = Topic {
            inner: Arc::new(TopicInner {
                participant: self.clone(),
                name: name.to_string(),
                qos: qos.clone(),
            }),
            _t: PhantomData,
        };
        ops::register_topic(&topic);
        Ok(topic)
    }

    /// A content-filtered view of `topic` (SQL subset, see [`crate::dcps::filter`]); `%N` in the expression
    /// refers to `params[N]`.
    pub fn create_content_filtered_topic<T: DdsType + FilterFields, S: AsRef<str>>(
        &self,
        name: &str,
        topic: &Topic<T>,
        expression: &str,
        params: &[S],
    ) -> DdsResult<ContentFilteredTopic<T>> {
        if name.is_empty() {
            return Err(DdsError::BadParameter(
                "empty content-filtered topic name".into(),
            ));
        }
        let params: Vec<String> = params.iter().map(|s| s.as_ref().to_string()).collect();
        let filter = ContentFilter::new(expression, &params)?;
        Ok(ContentFilteredTopic {
            topic: topic.clone(),
            name: name.to_string(),
            filter: Arc::new(RwLock::new(filter)),
            readers: Arc::new(Mutex::new(Vec::new())),
        })
    }
}
