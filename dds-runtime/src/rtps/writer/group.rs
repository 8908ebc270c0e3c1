//! GROUP access scope on the writer side (RTPS 2.5 §8.7.5, §8.7.6, §9.6.4): the writers of one publisher
//! share a group sequence number and the group coherent set.
//!
//! Every change a group member writes carries `PID_GROUP_SEQ_NUM`, the publisher-wide number of the change
//! (starting at 1, one counter for all the publisher's writers). While a group coherent set is open, its
//! changes also carry `PID_GROUP_COHERENT_SET`: the group sequence number of the set's first change. Each
//! writer's end-of-set marker repeats `PID_GROUP_COHERENT_SET` and adds `PID_WRITER_GROUP_INFO`, the digest
//! of the writers that took part in the set ([`writer_set_digest`]), so that a reader knows when it holds
//! every writer's part. Markers take no group sequence number of their own.
//!
//! Every HEARTBEAT of a member carries GroupInfo (flag G): the group's last group sequence number
//! (`currentGSN`), those of the writer's first and last change, and the digest of the group's members. A
//! reader that holds all of the writer's changes up to the heartbeat's `lastSN` then knows that the writer
//! has no change it lacks numbered up to `currentGSN` (`rtps::participant::group_order`). The group has an
//! entity id of its own (kind 0x08, user-defined writer group), which its members announce in SEDP as
//! `PID_GROUP_ENTITYID`, so that readers know which writers share the numbering.

use std::collections::BTreeSet;
use std::sync::{Arc, Mutex, PoisonError};

use md5::{Digest, Md5};

use super::Writer;
use crate::rtps::messages::parameter::pid;
use crate::rtps::messages::HeartbeatGroupInfo;
use crate::rtps::types::{EntityId, SequenceNumber};

/// The digest of a set of writers (`GroupDigest_t`, 4 octets): the first four octets of the MD5 hash of
/// their entity ids, in increasing order, concatenated. Writers of one participant only (a publisher's).
pub(crate) fn writer_set_digest<'a>(writers: impl IntoIterator<Item = &'a EntityId>) -> [u8; 4] {
    let sorted: BTreeSet<&EntityId> = writers.into_iter().collect();
    let mut h = Md5::new();
    for id in sorted {
        h.update(id.0);
    }
    let d = h.finalize();
    [d[0], d[1], d[2], d[3]]
}

/// How a change belongs to its group (kept with the change, so repairs carry it).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct GroupMark {
    /// The change's group sequence number (none on end-of-set markers).
    pub gsn: Option<SequenceNumber>,
    /// The group sequence number of the first change of the open group coherent set.
    pub set: Option<SequenceNumber>,
    /// On end-of-set markers: the digest of the writers of the group set.
    pub writers: Option<[u8; 4]>,
}

impl GroupMark {
    /// Writes the group parameters (little-endian) at the start of `buf`; returns their length (at most
    /// [`GROUP_QOS_MAX`]).
    pub(crate) fn put(&self, buf: &mut [u8]) -> usize {
        let mut n = 0;
        for (id, v) in [
            (pid::GROUP_SEQ_NUM, self.gsn),
            (pid::GROUP_COHERENT_SET, self.set),
        ] {
            if let Some(sn) = v {
                buf[n..n + 2].copy_from_slice(&id.to_le_bytes());
                buf[n + 2..n + 4].copy_from_slice(&8u16.to_le_bytes());
                buf[n + 4..n + 8].copy_from_slice(&((sn.0 >> 32) as i32).to_le_bytes());
                buf[n + 8..n + 12].copy_from_slice(&(sn.0 as u32).to_le_bytes());
                n += 12;
            }
        }
        if let Some(d) = self.writers {
            buf[n..n + 2].copy_from_slice(&pid::WRITER_GROUP_INFO.to_le_bytes());
            buf[n + 2..n + 4].copy_from_slice(&4u16.to_le_bytes());
            buf[n + 4..n + 8].copy_from_slice(&d);
            n += 8;
        }
        n
    }
}

/// Room for the group parameters of one change.
pub(crate) const GROUP_QOS_MAX: usize = 32;

#[derive(Debug)]
struct GroupSeq {
    next_gsn: i64,
    /// A group coherent set is open; its first change, once written.
    open: Option<Option<SequenceNumber>>,
    /// The writers that wrote in the open set.
    writers: BTreeSet<EntityId>,
    /// Every writer that joined the group.
    members: BTreeSet<EntityId>,
    /// The group's entity id, once a participant gave it one.
    entity: Option<EntityId>,
}

/// The state the writers of one publisher with GROUP access scope share: the group sequence number and
/// the open group coherent set. Cloning shares it. Create one per publisher, join its writers with
/// [`crate::rtps::Participant::join_writer_group`].
#[derive(Debug, Clone)]
pub struct WriterGroup(Arc<Mutex<GroupSeq>>);

impl Default for WriterGroup {
    fn default() -> Self {
        WriterGroup(Arc::new(Mutex::new(GroupSeq {
            next_gsn: 1,
            open: None,
            writers: BTreeSet::new(),
            members: BTreeSet::new(),
            entity: None,
        })))
    }
}

impl WriterGroup {
    fn with<R>(&self, f: impl FnOnce(&mut GroupSeq) -> R) -> R {
        f(&mut self.0.lock().unwrap_or_else(PoisonError::into_inner))
    }

    /// The group's entity id, if it has one.
    pub(crate) fn entity(&self) -> Option<EntityId> {
        self.with(|g| g.entity)
    }

    /// Adds a member; gives the group the entity id `entity` when it has none. Returns the group's id.
    pub(crate) fn join(&self, writer: EntityId, entity: Option<EntityId>) -> Option<EntityId> {
        self.with(|g| {
            g.members.insert(writer);
            if g.entity.is_none() {
                g.entity = entity;
            }
            g.entity
        })
    }

    /// The last group sequence number written (0: none yet).
    pub(crate) fn current_gsn(&self) -> SequenceNumber {
        self.with(|g| SequenceNumber(g.next_gsn - 1))
    }

    /// The digest of the group's members.
    fn member_digest(&self) -> [u8; 4] {
        self.with(|g| writer_set_digest(&g.members))
    }

    /// Opens a group coherent set (nothing when one is open).
    pub(crate) fn begin_set(&self) {
        self.with(|g| {
            if g.open.is_none() {
                g.open = Some(None);
                g.writers.clear();
            }
        });
    }

    /// Closes the open group coherent set (after every member sent its end-of-set marker).
    pub(crate) fn end_set(&self) {
        self.with(|g| {
            g.open = None;
            g.writers.clear();
        });
    }

    /// The group mark of a change `writer` writes now: a new group sequence number, and the open set
    /// (which the writer joins). `marker`: an end-of-set marker (no number; the digest of the set).
    pub(crate) fn stamp(&self, writer: EntityId, marker: bool) -> GroupMark {
        self.with(|g| {
            if marker {
                return GroupMark {
                    gsn: None,
                    set: g.open.flatten(),
                    writers: Some(writer_set_digest(&g.writers)),
                };
            }
            let gsn = SequenceNumber(g.next_gsn);
            g.next_gsn += 1;
            let set = g.open.as_mut().map(|start| *start.get_or_insert(gsn));
            if set.is_some() {
                g.writers.insert(writer);
            }
            GroupMark {
                gsn: Some(gsn),
                set,
                writers: None,
            }
        })
    }
}

impl Writer {
    /// The GroupInfo of this writer's HEARTBEAT announcing `first..=last`, when it is a group member.
    pub(crate) fn group_info(
        &self,
        first: SequenceNumber,
        last: SequenceNumber,
    ) -> Option<HeartbeatGroupInfo> {
        let group = self.group.as_ref()?;
        let current_gsn = group.current_gsn();
        let gsn = |sn| self.history.get(sn).and_then(|c| c.marks.group?.gsn);
        let last_gsn = gsn(last).unwrap_or(current_gsn);
        let first_gsn = gsn(first)
            .unwrap_or(SequenceNumber(last_gsn.0 + 1))
            .min(SequenceNumber(last_gsn.0 + 1));
        Some(HeartbeatGroupInfo {
            current_gsn,
            first_gsn: first_gsn.max(SequenceNumber(1)),
            last_gsn,
            writer_set: group.member_digest(),
            secure_writer_set: [0; 4],
        })
    }
}
