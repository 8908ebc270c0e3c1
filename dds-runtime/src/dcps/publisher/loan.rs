//! [`DataWriter::loan`] (feature `shm`): a sample written in place, in a buffer of the writer's
//! shared-memory channel, and published from there without a copy.
//!
//! It applies to plain-old-data samples ([`bytemuck::Pod`]) whose CDR encoding is their memory image
//! (a `#[repr(C)]` final struct of numbers and arrays of numbers without padding, typically): checked once
//! per type and data representation, by encoding a probe whose every byte differs from its neighbours
//! and comparing it with its memory. The frame in the channel then holds the encapsulation header and the
//! sample itself, which the user writes through the loan; readers on shared memory decode it in place.
//! A writer with other readers too (on the wire, in its own participant) or a durable history gives the
//! core a copy of the sample for them; the readers on shared memory still get the loaned buffer.

use std::ops::{Deref, DerefMut, Range};
use std::time::{Duration, Instant, SystemTime};

use bytemuck::Pod;

use super::{wire_time, DataWriter};
use crate::cdr::DdsType;
use crate::dcps::error::DdsError;
use crate::dcps::plain::plain_layout_cached;
use crate::dcps::shm::ShmHost;
use crate::dcps::sync::lock;
use crate::rtps::shm::ShmChange;
use crate::rtps::{ChangeKind, Payload, WriteChange};
use crate::transport::shm::{ShmError, ShmLoan};

/// How often a loan is retried while every buffer is taken.
const LOAN_RETRY: Duration = Duration::from_micros(200);

/// Why a writer cannot loan a sample; write the sample with [`DataWriter::write`] instead.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum LoanError {
    /// The type's CDR encoding (in the writer's data representation) is not its memory image.
    #[error(
        "samples of this type are not plain data in this representation: they cannot be loaned"
    )]
    NotPlain,
    /// The participant has no shared memory (`Config::shm` off, or it could not be set up).
    #[error("shared memory is off for this participant")]
    SharedMemoryOff,
    /// No reader is matched with the writer over shared memory.
    #[error("no reader is matched over shared memory")]
    NoSharedMemoryReader,
    /// No buffer could be loaned (too many loans held, or out of shared memory).
    #[error(transparent)]
    Shm(#[from] ShmError),
    /// The writer cannot write (not enabled, deleted).
    #[error(transparent)]
    Dds(#[from] DdsError),
}

/// A sample loaned from a writer's shared-memory channel: write it through `DerefMut`, then publish it
/// with [`write`](Self::write). Dropping it gives the buffer back unpublished. `Send`: it may be filled
/// on one thread and written on another.
pub struct SampleLoan<T: DdsType + Pod> {
    writer: DataWriter<T>,
    buf: ShmLoan,
    /// Where the sample starts in `buf` (aligned for `T`).
    at: usize,
    /// The serialized sample in `buf`: the encapsulation header, the sample, the padding.
    payload: Range<usize>,
}

impl<T: DdsType + Pod> std::fmt::Debug for SampleLoan<T> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("SampleLoan")
            .field("writer", &self.writer)
            .field("bytes", &self.payload.len())
            .finish()
    }
}

impl<T: DdsType + Pod> DataWriter<T> {
    /// Loans a sample in the writer's shared-memory channel, zeroed: fill it in place and
    /// [`write`](SampleLoan::write) it. Readers on shared memory get that buffer, with no copy on the
    /// way (the sample is not serialized: its memory is its encoding). Readers elsewhere get it too,
    /// from a copy.
    ///
    /// Errors (then use [`write`](Self::write)): the type's encoding is not its memory image
    /// ([`LoanError::NotPlain`]); the participant has no shared memory; no reader is matched over
    /// shared memory; every buffer stayed taken for the reliability's `max_blocking_time` (changes
    /// waiting for their turn hold theirs).
    pub fn loan(&self) -> Result<SampleLoan<T>, LoanError> {
        self.inner.state.check_enabled()?;
        let (_, pad) =
            plain_layout_cached::<T>(self.data_representation()).ok_or(LoanError::NotPlain)?;
        let driver = &self.inner.state.driver;
        let link = driver.shm_link().ok_or(LoanError::SharedMemoryOff)?;
        let id = self.id();
        if !driver.query_core(|c| c.has_shm_readers(id)) {
            return Err(LoanError::NoSharedMemoryReader);
        }
        let (size, align) = (std::mem::size_of::<T>(), std::mem::align_of::<T>());
        // Header, encapsulation header, then the sample where its alignment needs it.
        let first = ShmChange::HEADER_LEN + 4;
        let len = first + (align - 1) + size + pad;
        let reliable = self.qos().reliability.is_reliable();
        // Every buffer may be taken by changes waiting for their turn (for readers to connect, or for
        // room in a reader's queue): wait for them as a write waits for flow control.
        let deadline = Instant::now() + self.inner.fixed.max_block();
        let buf = loop {
            match link.loan(id, reliable, len) {
                Ok(b) => break b,
                Err(e) if Instant::now() >= deadline => return Err(e.into()),
                Err(_) => {
                    link.flush();
                    std::thread::sleep(LOAN_RETRY);
                }
            }
        };
        let base = buf.as_ptr() as usize;
        let at = (base + first).next_multiple_of(align) - base;
        let payload = at - 4..at + size + pad;
        if payload.end > buf.len() || bytemuck::try_from_bytes::<T>(&buf[at..at + size]).is_err() {
            return Err(ShmError::Loan("misaligned loan".into()).into());
        }
        let mut loan = SampleLoan {
            writer: self.clone(),
            buf,
            at,
            payload,
        };
        let head = plain_layout_cached::<T>(self.data_representation()).map(|(h, _)| h);
        let start = loan.payload.start;
        loan.buf[start..start + 4].copy_from_slice(&head.unwrap_or_default());
        Ok(loan)
    }
}

impl<T: DdsType + Pod> SampleLoan<T> {
    /// Publishes the sample with the current time as source timestamp.
    pub fn write(self) -> Result<(), DdsError> {
        self.write_w_timestamp(SystemTime::now())
    }

    /// Publishes the sample with the given source timestamp. Should the writer have lost its readers
    /// on shared memory since the loan, the sample is written as by [`DataWriter::write`].
    pub fn write_w_timestamp(self, timestamp: SystemTime) -> Result<(), DdsError> {
        let SampleLoan {
            writer,
            buf,
            at,
            payload,
        } = self;
        let w = &writer;
        let id = w.id();
        let sample: &T = bytemuck::from_bytes(&buf[at..at + std::mem::size_of::<T>()]);
        let key_hash = w.written_instance(sample)?;
        let mut copy: Option<Payload> = None;
        let mut attempt = |c: &mut crate::rtps::Participant, now| {
            let rejected = w.rejected_by_filters(c, Some(sample));
            let payload = if c.loan_needs_payload(id) {
                copy.get_or_insert_with(|| w.pooled(&buf[payload.clone()]))
                    .clone()
            } else {
                Payload::default()
            };
            let change = WriteChange {
                kind: ChangeKind::Alive,
                payload,
                key_hash,
                source_timestamp: Some(wire_time(timestamp)),
            };
            Some(c.write_loaned(now, id, change, rejected))
        };
        let written = w.submit_with(&mut attempt, || Ok(()))?;
        // The core queued the change for the channel (its turn may have come already: the change
        // waited for its buffer, which it gets now).
        if let (sn, true) = written {
            if let Some(link) = w.inner.state.driver.shm_link() {
                link.park(id, sn.0, buf, payload);
                link.flush();
            }
        }
        Ok(())
    }

    /// The loaned sample's serialized bytes (encapsulation header, sample, padding), as readers get them.
    pub fn serialized(&self) -> &[u8] {
        &self.buf[self.payload.clone()]
    }
}

impl<T: DdsType + Pod> DataWriter<T> {
    /// `bytes` in a buffer of the writer's pool.
    fn pooled(&self, bytes: &[u8]) -> Payload {
        let mut b = lock(&self.inner.payloads).take();
        std::sync::Arc::make_mut(&mut b).extend_from_slice(bytes);
        lock(&self.inner.payloads).share(b)
    }
}

impl<T: DdsType + Pod> Deref for SampleLoan<T> {
    type Target = T;
    fn deref(&self) -> &T {
        // Checked when loaned: in bounds and aligned.
        bytemuck::from_bytes(&self.buf[self.at..self.at + std::mem::size_of::<T>()])
    }
}

impl<T: DdsType + Pod> DerefMut for SampleLoan<T> {
    fn deref_mut(&mut self) -> &mut T {
        let size = std::mem::size_of::<T>();
        bytemuck::from_bytes_mut(&mut self.buf[self.at..self.at + size])
    }
}
