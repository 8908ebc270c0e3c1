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

use crate::rtps::api::{Event, ReceivedSample};
use crate::rtps::types::{EntityId, Guid, SequenceNumber};

/// How a received change belongs to a coherent set.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct SetMark {
    /// The sequence number of the set's first change.
    pub set: SequenceNumber,
    /// The change is the end-of-set marker (no data).
    pub end: bool,
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
}

/// One matched writer's open coherent set.
#[derive(Debug)]
pub(crate) struct Assembler {
    open: Option<OpenSet>,
    limits: SetLimits,
}

impl Default for Assembler {
    fn default() -> Self {
        Assembler::new(SetLimits {
            max_samples: 4096,
            max_bytes: 16 << 20,
        })
    }
}

impl Assembler {
    /// An assembler holding at most `limits` of one set.
    pub(crate) fn new(limits: SetLimits) -> Self {
        Assembler { open: None, limits }
    }

    /// Takes the next change delivered in order from the writer, `sn` being its sequence number.
    pub(crate) fn offer(
        &mut self,
        sn: SequenceNumber,
        mark: Option<SetMark>,
        sample: ReceivedSample,
        out: &mut Vec<Event>,
    ) {
        match mark {
            None => {
                self.close(sn, sample.reader, sample.writer, out);
                out.push(Event::Sample(sample));
            }
            Some(m) if m.end => self.close(sn, sample.reader, sample.writer, out),
            Some(m) => {
                if self.open.as_ref().is_some_and(|o| o.set != m.set) {
                    self.close(sn, sample.reader, sample.writer, out);
                }
                let o = self.open.get_or_insert_with(|| OpenSet {
                    set: m.set,
                    last: SequenceNumber(m.set.0 - 1),
                    whole: true,
                    count: 0,
                    bytes: 0,
                    samples: Vec::new(),
                });
                o.whole &= sn == o.last.next();
                o.last = sn;
                o.count += 1;
                o.bytes += sample.payload.len();
                if o.samples.len() >= self.limits.max_samples || o.bytes > self.limits.max_bytes {
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
    /// nothing is missing between its last change and `next`, else reports its changes lost.
    fn close(
        &mut self,
        next: SequenceNumber,
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
            });
        } else {
            tracing::debug!(?writer, set = o.set.0, "incomplete coherent set discarded");
            out.push(Event::SampleLost {
                reader,
                writer,
                count: o.count,
            });
        }
    }

    /// Whether a set is being assembled.
    pub(crate) fn is_open(&self) -> bool {
        self.open.is_some()
    }
}
