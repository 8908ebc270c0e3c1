//! Coherent sets on the reader side (RTPS 2.5 §8.7.6): changes of a set are held per writer until the set
//! is known whole, then delivered together as one [`Event::CoherentSet`]; a set with a hole is discarded.
//!
//! A set is whole when the reader received, in order and without a skipped number, every change from the
//! set's first sequence number (the value of `PID_COHERENT_SET`) up to its end: the end-of-set marker (a
//! DATA without data carrying only `PID_COHERENT_SET`), or, from writers that send no marker, the first
//! change that is not in the set. Changes reach this module in sequence order (reliable readers deliver in
//! order; a best-effort reader's losses show as jumps), so a hole is a jump in the numbers. A writer that
//! goes away takes its open set with it. Memory is bounded: a set larger than the reorder limits is
//! counted as lost instead of held.

use crate::rtps::api::{Event, GroupSetId, ReceivedSample};
use crate::rtps::messages::ParameterList;
use crate::rtps::types::{EntityId, Guid, SequenceNumber};

/// The group set an end-of-set marker names: `PID_GROUP_COHERENT_SET` and `PID_WRITER_GROUP_INFO`, both
/// needed (a marker of a writer-scope set has neither).
pub(crate) fn group_set(q: Option<&ParameterList<'_>>) -> Option<GroupSetId> {
    let q = q?;
    Some(GroupSetId {
        set: q.group_coherent_set()?,
        writers: q.writer_group_info()?,
    })
}

/// How a received change belongs to a coherent set.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct SetMark {
    /// The sequence number of the set's first change.
    pub set: SequenceNumber,
    /// The change is the end-of-set marker (no data).
    pub end: bool,
    /// On an end-of-set marker of a group coherent set: the group set.
    pub group: Option<GroupSetId>,
    /// On a change of a group coherent set: the set's first group sequence number.
    pub group_set: Option<SequenceNumber>,
}

/// Limits on what one writer's open set may hold.
#[derive(Debug, Clone, Copy)]
pub(crate) struct SetLimits {
    pub max_samples: usize,
    pub max_bytes: usize,
}

#[derive(Debug)]
struct OpenSet {
    set: SequenceNumber,
    last: SequenceNumber,
    /// No hole so far and within the limits.
    whole: bool,
    /// Changes of the set received (held or not).
    count: u64,
    bytes: usize,
    samples: Vec<ReceivedSample>,
    /// The group set the changes named (`PID_GROUP_COHERENT_SET`), if any.
    group_set: Option<SequenceNumber>,
    /// The reader's limits on what the set may hold.
    max_samples: u32,
    max_bytes: u32,
}

/// One matched writer's open coherent set.
///
/// Kept in a matched writer's backlog (made on first use), so small (8 bytes): the open set is boxed (most
/// writers never send one) and holds the limits it was opened with.
#[derive(Debug, Default)]
pub(crate) struct Assembler {
    open: Option<Box<OpenSet>>,
}

impl Assembler {
    /// Takes the next change delivered in order from the writer, `sn` being its sequence number; a set it
    /// opens holds at most `limits` (a limit beyond `u32::MAX` is `u32::MAX`).
    pub(crate) fn offer(
        &mut self,
        sn: SequenceNumber,
        mark: Option<SetMark>,
        sample: ReceivedSample,
        limits: SetLimits,
        out: &mut Vec<Event>,
    ) {
        match mark {
            None => {
                self.close(sn, None, sample.reader, sample.writer, out);
                out.push(Event::Sample(sample));
            }
            Some(m) if m.end => self.close(sn, m.group, sample.reader, sample.writer, out),
            Some(m) => {
                if self.open.as_ref().is_some_and(|o| o.set != m.set) {
                    self.close(sn, None, sample.reader, sample.writer, out);
                }
                let cap = |n: usize| u32::try_from(n).unwrap_or(u32::MAX);
                let o = self.open.get_or_insert_with(|| {
                    Box::new(OpenSet {
                        max_samples: cap(limits.max_samples),
                        max_bytes: cap(limits.max_bytes),
                        set: m.set,
                        last: SequenceNumber(m.set.0 - 1),
                        whole: true,
                        count: 0,
                        bytes: 0,
                        samples: Vec::new(),
                        group_set: m.group_set,
                    })
                });
                o.whole &= sn == o.last.next();
                o.last = sn;
                o.count += 1;
                o.bytes += sample.payload.len();
                if o.samples.len() >= o.max_samples as usize || o.bytes > o.max_bytes as usize {
                    o.whole = false;
                }
                if o.whole {
                    o.samples.push(sample);
                } else {
                    o.samples = Vec::new();
                }
            }
        }
    }

    /// Ends the open set at change `next` (the marker, or the first change not in the set): delivers it when
    /// nothing is missing between its last change and `next`, else reports its changes lost. `group`: the
    /// group set the closing marker named.
    fn close(
        &mut self,
        next: SequenceNumber,
        group: Option<GroupSetId>,
        reader: EntityId,
        writer: Guid,
        out: &mut Vec<Event>,
    ) {
        let Some(o) = self.open.take() else {
            return;
        };
        if o.whole && next == o.last.next() {
            out.push(Event::CoherentSet {
                reader,
                writer,
                samples: o.samples,
                group,
            });
        } else {
            tracing::debug!(?writer, set = o.set.0, "incomplete coherent set discarded");
            out.push(Event::SampleLost {
                reader,
                writer,
                count: o.count,
            });
            // A part of a group set that will never be whole: the rest of the set waits for nothing. Said
            // with an empty part (the participant's group assembly takes it; it never reaches the
            // application).
            if let Some(set) = group.map(|g| g.set).or(o.group_set) {
                out.push(Event::CoherentSet {
                    reader,
                    writer,
                    samples: Vec::new(),
                    group: Some(GroupSetId {
                        set,
                        writers: [0; 4],
                    }),
                });
            }
        }
    }

    /// Whether a set is being assembled.
    pub(crate) fn is_open(&self) -> bool {
        self.open.is_some()
    }
}
