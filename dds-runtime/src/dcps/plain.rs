//! Plain-data samples (feature `shm`): types whose CDR encoding is their memory image, so that a writer
//! can write them in place in shared memory ([`DataWriter::loan`](super::DataWriter::loan)) and a reader
//! can read them where they arrived ([`InPlace`]).
//!
//! Whether a type qualifies is checked once per type and data representation, by encoding a probe whose
//! every byte differs from its neighbours and comparing the encoding with the probe's memory.

use std::any::{Any, TypeId};
use std::ops::Deref;
use std::sync::{Mutex, OnceLock};

use bytemuck::Pod;
use foldhash::{HashMap, HashMapExt};

use crate::cdr::{
    self, ByteOrder, CdrReader, CdrType, CdrWriter, DdsType, DecodeError, EncodeError,
    Extensibility, Layout, TypeDescriptor, XcdrVersion,
};
use crate::dcps::sync::lock;
use crate::filter::{FieldValue, FilterFields, PathSegment};
use crate::rtps::Payload;

/// The encapsulation header and padding of a plain type's samples, or `None`.
pub(crate) type Plain = Option<([u8; 4], usize)>;

/// [`plain_layout`] once per type and version.
pub(crate) fn plain_layout_cached<T: DdsType + Pod>(version: XcdrVersion) -> Plain {
    static CACHE: OnceLock<Mutex<HashMap<(TypeId, bool), Plain>>> = OnceLock::new();
    let key = (TypeId::of::<T>(), version == XcdrVersion::Xcdr2);
    let cache = CACHE.get_or_init(|| Mutex::new(HashMap::new()));
    if let Some(p) = lock(cache).get(&key) {
        return *p;
    }
    let p = plain_layout::<T>(version);
    lock(cache).insert(key, p);
    p
}

/// Whether `T`'s encoding in `version` (native byte order) is its memory image: a probe whose bytes
/// follow a sequence without short periods is encoded, and its body must equal the probe's bytes, with
/// only zero padding after them. Any padding, reordering or byte swapping the encoding does would shift
/// or permute the sequence. The encapsulation header and the padding length are returned.
fn plain_layout<T: DdsType + Pod>(version: XcdrVersion) -> Plain {
    let mut probe: Box<T> = bytemuck::allocation::zeroed_box();
    let mut x: u32 = 0x9e37_79b9;
    for b in bytemuck::bytes_of_mut(&mut *probe) {
        x ^= x << 13;
        x ^= x >> 17;
        x ^= x << 5;
        *b = (x >> 24) as u8;
    }
    let mut out = Vec::new();
    cdr::serialize(&*probe, version, ByteOrder::NATIVE, &mut out).ok()?;
    let size = std::mem::size_of::<T>();
    let (head, rest) = out.split_at_checked(4)?;
    let (body, pad) = rest.split_at_checked(size)?;
    let plain = body == bytemuck::bytes_of(&*probe) && pad.len() < 4 && pad.iter().all(|b| *b == 0);
    plain.then(|| (head.try_into().unwrap_or_default(), pad.len()))
}

/// A plain-data sample read where it arrived: in the writer's shared-memory buffer, with no copy and no
/// decoding, when it came over shared memory in the type's memory layout (what
/// [`DataWriter::loan`](super::DataWriter::loan) writes); otherwise a copy on the heap, never on the
/// stack (so multi-megabyte types need no large thread stacks).
///
/// Read a topic of `T` as `InPlace<T>` to get it: a `DataReader<InPlace<T>>` is a reader of `T`'s type
/// (same type name, type information and encoding; it matches writers of `T` anywhere), whose samples
/// dereference to `T`. Each sample keeps its buffer (a shared-memory chunk, or the buffer it was received
/// in) until it is dropped, which gives the chunk back to the writer: take samples and drop them when
/// done, as with any loan. Once its readers hold a channel's share of chunks, a participant leaves the
/// channel's next frames queued for a few milliseconds (its writer waits if the queue fills), then copies
/// frames out of shared memory instead, so a reader that keeps samples holds its writers back only
/// briefly.
///
/// ```no_run
/// # #[cfg(feature = "shm")] {
/// use dds_runtime::prelude::*;
/// use dds_runtime::dcps::InPlace;
///
/// #[derive(DdsType, Clone, Copy)]
/// #[dds(name = "demo::Frame", final)]
/// #[repr(C)]
/// struct Frame {
///     seq: u64,
///     pixels: [u8; 4 << 20],
/// }
/// // SAFETY: `repr(C)`, no padding, every bit pattern is valid.
/// unsafe impl bytemuck::Zeroable for Frame {}
/// // SAFETY: as above.
/// unsafe impl bytemuck::Pod for Frame {}
///
/// # fn f(p: &DomainParticipant) -> Result<(), DdsError> {
/// let topic = p.create_topic::<InPlace<Frame>>("Frames", &TopicQos::default())?;
/// let reader = p
///     .create_subscriber(&SubscriberQos::default())?
///     .create_datareader(&topic, &DataReaderQos::default())?;
/// for s in reader.take()? {
///     if let Some(frame) = &s.data {
///         println!("{} (in place: {})", frame.seq, frame.in_shared_memory());
///     } // dropping the sample gives its buffer back
/// }
/// # Ok(()) }
/// # }
/// ```
pub struct InPlace<T: DdsType + Pod> {
    repr: Repr<T>,
}

enum Repr<T> {
    /// The sample is at `at` in the payload's bytes, aligned for `T` (checked when made).
    Shared {
        payload: Payload,
        at: usize,
    },
    Boxed(Box<T>),
}

impl<T: DdsType + Pod> InPlace<T> {
    /// A sample on the heap.
    pub fn new(value: Box<T>) -> Self {
        InPlace {
            repr: Repr::Boxed(value),
        }
    }

    /// Whether the sample is read in place in the writer's shared memory (rather than in a buffer of
    /// this process: a received datagram's, or a copy).
    pub fn in_shared_memory(&self) -> bool {
        matches!(&self.repr, Repr::Shared { payload, .. } if payload.is_from_owner())
    }

    /// A copy of the sample on the heap.
    pub fn to_box(&self) -> Box<T> {
        let mut b: Box<T> = bytemuck::allocation::zeroed_box();
        bytemuck::bytes_of_mut(&mut *b).copy_from_slice(bytemuck::bytes_of(&**self));
        b
    }

    /// The sample of a serialized payload in `T`'s memory layout: in place when its bytes are aligned for
    /// `T`, else copied to the heap; `None` when the payload is not in that layout (another byte order,
    /// representation or type), to be decoded as usual.
    fn from_payload(payload: &Payload) -> Option<Self> {
        let size = std::mem::size_of::<T>();
        let head = payload.get(..4)?;
        let plain = [XcdrVersion::Xcdr1, XcdrVersion::Xcdr2]
            .into_iter()
            .filter_map(plain_layout_cached::<T>)
            .any(|(h, _)| h[..2] == head[..2]);
        let body = payload.get(4..4 + size).filter(|_| plain)?;
        if bytemuck::try_from_bytes::<T>(body).is_ok() {
            return Some(InPlace {
                repr: Repr::Shared {
                    payload: payload.clone(),
                    at: 4,
                },
            });
        }
        let mut b: Box<T> = bytemuck::allocation::zeroed_box();
        bytemuck::bytes_of_mut(&mut *b).copy_from_slice(body);
        Some(InPlace::new(b))
    }
}

impl<T: DdsType + Pod> Deref for InPlace<T> {
    type Target = T;
    fn deref(&self) -> &T {
        match &self.repr {
            // In bounds and aligned: checked when made, and the payload's bytes never change.
            Repr::Shared { payload, at } => {
                bytemuck::from_bytes(&payload[*at..*at + std::mem::size_of::<T>()])
            }
            Repr::Boxed(b) => b,
        }
    }
}

impl<T: DdsType + Pod> Clone for InPlace<T> {
    /// Shares the same buffer (no copy of the sample).
    fn clone(&self) -> Self {
        InPlace {
            repr: match &self.repr {
                Repr::Shared { payload, at } => Repr::Shared {
                    payload: payload.clone(),
                    at: *at,
                },
                Repr::Boxed(_) => Repr::Boxed(self.to_box()),
            },
        }
    }
}

impl<T: DdsType + Pod + std::fmt::Debug> std::fmt::Debug for InPlace<T> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        (**self).fmt(f)
    }
}

impl<T: DdsType + Pod> CdrType for InPlace<T> {
    const LAYOUT: Layout = T::LAYOUT;
    const MIN_SIZE: usize = T::MIN_SIZE;
    const KEY_HAS_MUTABLE: bool = T::KEY_HAS_MUTABLE;
    const NEXT_MEMBER_ID: u32 = T::NEXT_MEMBER_ID;
    const XCDR1_PLAIN: bool = T::XCDR1_PLAIN;

    fn encode(&self, w: &mut CdrWriter<'_>) -> Result<(), EncodeError> {
        (**self).encode(w)
    }

    /// Decodes into a zeroed sample on the heap, member by member where `T` allows it.
    fn decode(r: &mut CdrReader<'_>) -> Result<Self, DecodeError> {
        let mut b: Box<T> = bytemuck::allocation::zeroed_box();
        b.decode_in_place(r, usize::MAX)?;
        Ok(InPlace::new(b))
    }

    fn default_value() -> Self {
        InPlace::new(bytemuck::allocation::zeroed_box())
    }

    fn key_max_end(start: usize, version: XcdrVersion, bound: Option<usize>) -> Option<usize> {
        T::key_max_end(start, version, bound)
    }
}

impl<T: DdsType + Pod> FilterFields for InPlace<T> {
    fn field_value(&self, path: &[PathSegment]) -> Option<FieldValue<'_>> {
        (**self).field_value(path)
    }
}

impl<T: DdsType + Pod> DdsType for InPlace<T> {
    const TYPE_NAME: &'static str = T::TYPE_NAME;
    const EXTENSIBILITY: Extensibility = T::EXTENSIBILITY;
    const IS_KEYED: bool = T::IS_KEYED;
    const DEFAULT_VERSION: XcdrVersion = T::DEFAULT_VERSION;

    fn type_descriptor() -> TypeDescriptor {
        T::type_descriptor()
    }

    fn type_information() -> Option<&'static [u8]> {
        T::type_information()
    }

    fn type_mapping() -> Option<&'static [u8]> {
        T::type_mapping()
    }

    fn decode_shared(shared: &dyn Any) -> Option<Self> {
        InPlace::from_payload(shared.downcast_ref::<Payload>()?)
    }

    fn holds_received_buffer(&self) -> bool {
        matches!(self.repr, Repr::Shared { .. })
    }
}
