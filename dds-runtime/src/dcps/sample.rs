//! Samples, their [`SampleInfo`], states and instance handles.

use std::time::SystemTime;

use crate::rtps::Guid;

/// Identifies an instance (in a reader or writer), a publication or a subscription. [`InstanceHandle::NIL`]
/// is "no handle". Instance handles are local to the entity that returned them; publication and
/// subscription handles are derived from the remote entity's GUID and are stable within the process.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Default)]
pub struct InstanceHandle(pub u64);

impl InstanceHandle {
    /// `HANDLE_NIL`.
    pub const NIL: InstanceHandle = InstanceHandle(0);

    /// Whether this is [`InstanceHandle::NIL`].
    pub fn is_nil(self) -> bool {
        self.0 == 0
    }

    /// The handle for an RTPS GUID, never NIL: its two 8-byte halves mixed by the 64-bit finaliser of
    /// MurmurHash3 (a bijection, so two GUIDs that differ in one half never share a handle). Computed for
    /// every received sample (its publication handle), so it costs a few multiplications, not a loop.
    pub fn from_guid(g: Guid) -> Self {
        fn mix(mut h: u64) -> u64 {
            h ^= h >> 33;
            h = h.wrapping_mul(0xff51_afd7_ed55_8ccd);
            h ^= h >> 33;
            h = h.wrapping_mul(0xc4ce_b9fe_1a85_ec53);
            h ^ (h >> 33)
        }
        let b = g.to_bytes();
        let (lo, hi) = b.split_at(8);
        let lo = u64::from_le_bytes(lo.try_into().unwrap_or_default());
        let hi = u64::from_le_bytes(hi.try_into().unwrap_or_default());
        InstanceHandle(mix(lo ^ mix(hi)).max(1))
    }
}

/// Whether the sample has been read before.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum SampleState {
    /// Returned by an earlier read.
    Read,
    /// Never returned before.
    NotRead,
}

/// Whether the reader has seen this instance (generation) before.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum ViewState {
    /// First samples of the instance (or of a new generation).
    New,
    /// Samples of this instance have been read before.
    NotNew,
}

/// Lifecycle state of an instance.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum InstanceState {
    /// Some writer is alive for it and it is not disposed.
    Alive,
    /// A writer disposed it.
    NotAliveDisposed,
    /// All writers unregistered it (or were lost).
    NotAliveNoWriters,
}

/// A set of sample states (`ANY` by default).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SampleStateMask {
    /// Include read samples.
    pub read: bool,
    /// Include not-read samples.
    pub not_read: bool,
}
impl SampleStateMask {
    /// Both states.
    pub const ANY: Self = SampleStateMask {
        read: true,
        not_read: true,
    };
    /// Only `Read`.
    pub const READ: Self = SampleStateMask {
        read: true,
        not_read: false,
    };
    /// Only `NotRead`.
    pub const NOT_READ: Self = SampleStateMask {
        read: false,
        not_read: true,
    };
    /// Whether `s` is in the set.
    pub fn contains(self, s: SampleState) -> bool {
        match s {
            SampleState::Read => self.read,
            SampleState::NotRead => self.not_read,
        }
    }
}
impl Default for SampleStateMask {
    fn default() -> Self {
        Self::ANY
    }
}

/// A set of view states.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ViewStateMask {
    /// Include `New`.
    pub new: bool,
    /// Include `NotNew`.
    pub not_new: bool,
}
impl ViewStateMask {
    /// Both states.
    pub const ANY: Self = ViewStateMask {
        new: true,
        not_new: true,
    };
    /// Only `New`.
    pub const NEW: Self = ViewStateMask {
        new: true,
        not_new: false,
    };
    /// Only `NotNew`.
    pub const NOT_NEW: Self = ViewStateMask {
        new: false,
        not_new: true,
    };
    /// Whether `s` is in the set.
    pub fn contains(self, s: ViewState) -> bool {
        match s {
            ViewState::New => self.new,
            ViewState::NotNew => self.not_new,
        }
    }
}
impl Default for ViewStateMask {
    fn default() -> Self {
        Self::ANY
    }
}

/// A set of instance states.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct InstanceStateMask {
    /// Include `Alive`.
    pub alive: bool,
    /// Include `NotAliveDisposed`.
    pub disposed: bool,
    /// Include `NotAliveNoWriters`.
    pub no_writers: bool,
}
impl InstanceStateMask {
    /// All states.
    pub const ANY: Self = InstanceStateMask {
        alive: true,
        disposed: true,
        no_writers: true,
    };
    /// Only `Alive`.
    pub const ALIVE: Self = InstanceStateMask {
        alive: true,
        disposed: false,
        no_writers: false,
    };
    /// Both not-alive states.
    pub const NOT_ALIVE: Self = InstanceStateMask {
        alive: false,
        disposed: true,
        no_writers: true,
    };
    /// Whether `s` is in the set.
    pub fn contains(self, s: InstanceState) -> bool {
        match s {
            InstanceState::Alive => self.alive,
            InstanceState::NotAliveDisposed => self.disposed,
            InstanceState::NotAliveNoWriters => self.no_writers,
        }
    }
}
impl Default for InstanceStateMask {
    fn default() -> Self {
        Self::ANY
    }
}

/// Everything the reader knows about one sample (DDS 1.4 §2.2.2.5.5).
#[derive(Debug, Clone, PartialEq, Eq)]
#[non_exhaustive]
pub struct SampleInfo {
    /// Read before or not.
    pub sample_state: SampleState,
    /// Instance seen before or not.
    pub view_state: ViewState,
    /// Instance lifecycle state at the time of the read/take.
    pub instance_state: InstanceState,
    /// Writer's timestamp (reception time when the writer sent none).
    pub source_timestamp: SystemTime,
    /// Local time of reception.
    pub reception_timestamp: SystemTime,
    /// The instance.
    pub instance_handle: InstanceHandle,
    /// The writer (derived from its GUID).
    pub publication_handle: InstanceHandle,
    /// The writer's GUID.
    pub publication_guid: Guid,
    /// Times the instance went from disposed to alive before this sample.
    pub disposed_generation_count: u32,
    /// Times the instance went from no-writers to alive before this sample.
    pub no_writers_generation_count: u32,
    /// Samples of the same instance following this one in the returned collection.
    pub sample_rank: u32,
    /// Generations between this sample and the most recent sample of the instance in the collection.
    pub generation_rank: u32,
    /// Generations between this sample and the most recent sample of the instance in the reader.
    pub absolute_generation_rank: u32,
    /// `false` for samples that only carry an instance state change (dispose, unregister).
    pub valid_data: bool,
}

/// One sample: the data (absent when `info.valid_data` is false) and its info.
#[derive(Debug, Clone, PartialEq)]
pub struct Sample<T> {
    /// The data; `None` for a dispose/unregister notification.
    pub data: Option<T>,
    /// Its info.
    pub info: SampleInfo,
}

impl<T> Sample<T> {
    /// The data, if valid.
    pub fn data(&self) -> Option<&T> {
        self.data.as_ref()
    }
    /// Consumes the sample and returns its data, if valid.
    pub fn into_data(self) -> Option<T> {
        self.data
    }
}
