//! Coherent sets on the writer side (RTPS 2.5 §8.7.6, §9.6.4.2).
//!
//! Between `begin` and `end` every change the writer sends carries `PID_COHERENT_SET` in its inline QoS,
//! holding the sequence number of the first change of the set. `end` writes one more change, the
//! end-of-set marker: a DATA with neither data nor key (no D or K flag) whose only inline QoS is the same
//! `PID_COHERENT_SET`. It takes a sequence number of its own, so it is repaired like any other change and a
//! reader knows that the set is whole once it holds every number from the set's first to the marker.

use std::collections::VecDeque;
use std::time::Instant;

use super::group::GroupMark;
use super::Writer;
use crate::rtps::api::{ChangeKind, Event, Payload, WriteChange, WriteError};
use crate::rtps::messages::parameter::pid;
use crate::rtps::outbox::Outbox;
use crate::rtps::types::SequenceNumber;

/// How a change belongs to a coherent set (kept with the change in the history, so repairs carry it).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct CoherentMark {
    /// The sequence number of the set's first change.
    pub set: SequenceNumber,
    /// This change is the end-of-set marker.
    pub end: bool,
}

/// What a change of a writer carries in its inline QoS beyond key and status: its coherent set and, for
/// members of a GROUP-scope publisher, its group mark (see `group.rs`).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub(crate) struct Marks {
    pub coherent: Option<CoherentMark>,
    pub group: Option<GroupMark>,
}

impl Marks {
    /// This change is an end-of-set marker.
    pub(crate) fn is_marker(&self) -> bool {
        self.coherent.is_some_and(|m| m.end)
    }
}

/// The writer's coherent-set state.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub(crate) enum CoherentState {
    /// Not in a set.
    #[default]
    Off,
    /// In a set; `start` is its first change, once written; `ending` while the marker is written.
    Open {
        start: Option<SequenceNumber>,
        ending: bool,
    },
}

impl CoherentState {
    /// The mark of change `sn`, written now (opens the set's numbering with its first change).
    pub(crate) fn mark(&mut self, sn: SequenceNumber) -> Option<CoherentMark> {
        match self {
            CoherentState::Off => None,
            CoherentState::Open { start, ending } => Some(CoherentMark {
                set: *start.get_or_insert(sn),
                end: *ending,
            }),
        }
    }
}

/// Writes `PID_COHERENT_SET` and the group parameters (little-endian) at the start of `buf`; returns
/// their length (at most 12 + [`super::group::GROUP_QOS_MAX`]).
pub(crate) fn put_marks(m: &Marks, buf: &mut [u8]) -> usize {
    let mut n = 0;
    if let Some(c) = &m.coherent {
        buf[0..2].copy_from_slice(&pid::COHERENT_SET.to_le_bytes());
        buf[2..4].copy_from_slice(&8u16.to_le_bytes());
        buf[4..8].copy_from_slice(&((c.set.0 >> 32) as i32).to_le_bytes());
        buf[8..12].copy_from_slice(&(c.set.0 as u32).to_le_bytes());
        n = 12;
    }
    if let Some(g) = &m.group {
        n += g.put(&mut buf[n..]);
    }
    n
}

/// The instance key of end-of-set markers in a keyed writer's history (no real instance hashes to it in
/// practice; markers only ever replace older markers under KEEP_LAST).
pub(crate) const MARKER_KEY: [u8; 16] = [0xff; 16];

impl Writer {
    /// The marks of change `sn`, written now: its coherent set, and its group mark when the writer is a
    /// member of a GROUP-scope publisher.
    pub(crate) fn marks(&mut self, sn: SequenceNumber) -> Marks {
        let coherent = self.coherent.mark(sn);
        let marker = coherent.is_some_and(|m| m.end);
        let id = self.guid.entity_id;
        Marks {
            coherent,
            group: self.group.as_ref().map(|g| g.stamp(id, marker)),
        }
    }

    /// Starts a coherent set (nested calls keep the open one).
    pub(crate) fn begin_coherent(&mut self) {
        if self.coherent == CoherentState::Off {
            self.coherent = CoherentState::Open {
                start: None,
                ending: false,
            };
        }
    }

    /// Whether a coherent set is open.
    pub(crate) fn in_coherent_set(&self) -> bool {
        self.coherent != CoherentState::Off
    }

    /// Ends the open coherent set: writes its end-of-set marker when the set holds changes. `WouldBlock`
    /// (flow control or KEEP_ALL limits) leaves the set open: call again.
    pub(crate) fn end_coherent(
        &mut self,
        now: Instant,
        out: &mut Outbox,
        ev: &mut VecDeque<Event>,
    ) -> Result<Option<SequenceNumber>, WriteError> {
        let CoherentState::Open { start, .. } = self.coherent else {
            return Ok(None);
        };
        if start.is_none() {
            self.coherent = CoherentState::Off;
            return Ok(None);
        }
        self.coherent = CoherentState::Open {
            start,
            ending: true,
        };
        let marker = WriteChange {
            kind: ChangeKind::Alive,
            payload: Payload::default(),
            key_hash: self.params.keyed.then_some(MARKER_KEY),
            source_timestamp: None,
        };
        let r = self.write(now, marker, out, ev);
        self.coherent = match r {
            Ok(_) => CoherentState::Off,
            Err(_) => CoherentState::Open {
                start,
                ending: false,
            },
        };
        r.map(Some)
    }
}
