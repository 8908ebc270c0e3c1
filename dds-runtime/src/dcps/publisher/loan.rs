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

use std::mem::MaybeUninit;
use std::ops::{Deref, DerefMut, Range};
use std::sync::atomic::Ordering;
use std::time::{Duration, Instant, SystemTime};

use bytemuck::Pod;

use super::{wire_time, with_scratch, DataWriter};
use crate::cdr::{self, ByteOrder, DdsType};
use crate::dcps::error::DdsError;
use crate::dcps::error::DdsResult;
use crate::dcps::plain::plain_layout_cached;
use crate::dcps::shm::{LoanReservation, ShmHost};
use crate::dcps::sync::{lock, read};
use crate::rtps::shm::ShmChange;
use crate::rtps::{ChangeKind, Payload, SequenceNumber, WriteChange};
use crate::transport::shm::{ShmError, ShmLoan};

/// Samples whose serialized form is at least this long are serialized straight into shared memory when
/// every reader is there ([`DataWriter::write_direct`]); smaller ones cost too little to copy to be worth
/// a lock of the core to check that.
const DIRECT_MIN: usize = 64 * 1024;

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
    /// No buffer could be loaned (too many loans held, or out of shared memory). A writer lends at most
    /// `max_loans - 1` buffers at once (3): the last is kept for its ordinary writes.
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
    /// Counts `buf` among the writer's lent buffers until it is parked or dropped.
    reserved: LoanReservation,
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
        self.lend(true)
    }

    /// [`loan`](Self::loan) without zeroing the sample: its bytes are unspecified (those of an earlier
    /// sample of this writer, of another frame of its channel, or zeros). Write every field you publish;
    /// what you leave is published as found. For a sample that is rewritten whole, or whose large parts
    /// are meant to stay as they are, this saves a `memset` of the sample's size per loan (1 MiB takes
    /// about as long to zero as to copy).
    ///
    /// Sound because `T` is [`Pod`]: every byte pattern is a valid `T`, and the buffer is initialized
    /// memory (shared memory only ever written as bytes). The frame's header and the encapsulation
    /// header are written by the writer, and the padding after the sample (if its encoding has any) is
    /// zeroed, so readers never see stale bytes outside the sample itself.
    ///
    /// Errors: as [`loan`](Self::loan).
    pub fn loan_unzeroed(&self) -> Result<SampleLoan<T>, LoanError> {
        self.lend(false)
    }

    /// [`loan`](Self::loan) (`zeroed`) or [`loan_unzeroed`](Self::loan_unzeroed).
    fn lend(&self, zeroed: bool) -> Result<SampleLoan<T>, LoanError> {
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
        // room in a reader's queue), or lent (one is always kept for ordinary writes): wait for them as
        // a write waits for flow control.
        let deadline = Instant::now() + self.inner.fixed.max_block();
        let (buf, reserved) = loop {
            let got = link
                .reserve(id)
                .ok_or_else(|| ShmError::Loan("every loan this writer may lend is taken".into()))
                .and_then(|r| Ok((link.loan(id, reliable, len, zeroed)?, r)));
            match got {
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
            reserved,
        };
        let head = plain_layout_cached::<T>(self.data_representation()).map(|(h, _)| h);
        let Range { start, end } = loan.payload;
        loan.buf[start..start + 4].copy_from_slice(&head.unwrap_or_default());
        // The encoding's padding after the sample is zero (an unzeroed buffer holds older bytes there).
        // The bytes before the encapsulation header (the frame header, written when the frame is sent,
        // and the alignment gap) and after the payload are outside the range readers decode.
        loan.buf[end - pad..end].fill(0);
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
            reserved,
        } = self;
        let sample: &T = bytemuck::from_bytes(&buf[at..at + std::mem::size_of::<T>()]);
        let written = writer.submit_loaned(&buf[payload.clone()], sample, timestamp)?;
        writer.park_loaned(written, buf, payload);
        drop(reserved);
        Ok(())
    }

    /// The loaned sample's serialized bytes (encapsulation header, sample, padding), as readers get them.
    pub fn serialized(&self) -> &[u8] {
        &self.buf[self.payload.clone()]
    }
}

impl<T: DdsType> DataWriter<T> {
    /// `bytes` in a buffer of the writer's pool.
    fn pooled(&self, bytes: &[u8]) -> Payload {
        let mut b = lock(&self.inner.payloads).take();
        std::sync::Arc::make_mut(&mut b).extend_from_slice(bytes);
        lock(&self.inner.payloads).share(b)
    }

    /// Hands the core the change of `sample`, whose serialized form (`serialized`) is in a buffer loaned
    /// from the writer's channel: readers on shared memory get that buffer; the core gets a copy only when
    /// something else needs the bytes ([`Participant::loan_needs_payload`](crate::rtps::Participant::loan_needs_payload)).
    /// Give the result and the buffer to [`park_loaned`](Self::park_loaned).
    fn submit_loaned(
        &self,
        serialized: &[u8],
        sample: &T,
        timestamp: SystemTime,
    ) -> Result<(SequenceNumber, bool), DdsError> {
        let id = self.id();
        let key_hash = self.written_instance(sample)?;
        let mut copy: Option<Payload> = None;
        let mut attempt = |c: &mut crate::rtps::Participant, now| {
            let rejected = self.rejected_by_filters(c, Some(sample));
            let needed = c.loan_needs_payload(id);
            self.inner.direct_ok.store(!needed, Ordering::Relaxed);
            let payload = if needed {
                copy.get_or_insert_with(|| self.pooled(serialized)).clone()
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
        self.submit_with(&mut attempt, || Ok(()))
    }

    /// After [`submit_loaned`](Self::submit_loaned): when the core queued the change for the channel, its
    /// buffer waits for its turn there (which may have come already: the change waited for its buffer).
    fn park_loaned(&self, written: (SequenceNumber, bool), buf: ShmLoan, payload: Range<usize>) {
        if let (sn, true) = written {
            if let Some(link) = self.inner.state.driver.shm_link() {
                link.park(self.id(), sn.0, buf, payload);
                link.flush();
            }
        }
    }

    /// Records the serialized length of a sample written as usual: the next write of a sample at least
    /// [`DIRECT_MIN`] long tries [`write_direct`](Self::write_direct) with a buffer of that length.
    pub(super) fn note_len(&self, len: usize) {
        if len >= DIRECT_MIN {
            self.inner.direct_len.store(len, Ordering::Relaxed);
        }
    }

    /// [`write_w_timestamp`](DataWriter::write_w_timestamp) of a large sample (the last one was at least
    /// [`DIRECT_MIN`] long) when every reader of the writer is on shared memory and the history keeps no
    /// bytes (volatile: [`Participant::loan_needs_payload`](crate::rtps::Participant::loan_needs_payload)
    /// is false; asked before loaning only when the last loaned write found otherwise): the sample is
    /// serialized straight into a buffer loaned from the writer's channel (its long byte runs copied
    /// once, from the sample to shared memory), and written as a loaned sample.
    /// `None` (nothing done): write as usual; so when the sample does not fit in a buffer of the last
    /// length, or no buffer is free.
    pub(super) fn write_direct(&self, sample: &T, timestamp: SystemTime) -> Option<DdsResult<()>> {
        let len = self.inner.direct_len.load(Ordering::Relaxed);
        if len < DIRECT_MIN {
            return None;
        }
        let driver = &self.inner.state.driver;
        let link = driver.shm_link()?;
        let id = self.id();
        // The core is asked once per sample: when the last loaned write found that it needed no copy,
        // the answer comes with this write's (`submit_loaned`, which copies should it have changed).
        let asked = || driver.query_core(|c| c.loan_needs_payload(id));
        if !self.inner.direct_ok.load(Ordering::Relaxed) && asked() {
            return None;
        }
        // Counts the buffer among the lent ones until it is parked (`None`: it would take the last loan).
        let reserved = link.reserve(id)?;
        let reliable = read(&self.inner.current).reliability.is_reliable();
        let head = ShmChange::HEADER_LEN;
        let mut buf = link.loan_uninit(id, reliable, head + len).ok()?;
        let version = self.data_representation();
        let placed = with_scratch(|scratch| {
            cdr::serialize_placed(
                sample,
                version,
                ByteOrder::NATIVE,
                scratch,
                &mut buf.buf()[head..],
            )
        });
        let n = match placed {
            Ok(Some(n)) => n,
            Ok(None) => {
                // Larger than the last one: written as usual, which records its length.
                self.inner.direct_len.store(0, Ordering::Relaxed);
                return None;
            }
            Err(e) => return Some(Err(e.into())),
        };
        // A small sample goes the usual way next time (until a large one again).
        let next = if n >= DIRECT_MIN { n } else { 0 };
        self.inner.direct_len.store(next, Ordering::Relaxed);
        // The header is written when the frame is sent; a shorter sample leaves a tail.
        let bytes = buf.buf();
        bytes[..head].fill(MaybeUninit::new(0));
        bytes[head + n..].fill(MaybeUninit::new(0));
        // SAFETY: the header and the tail were zeroed just above, `serialize_placed` wrote the rest.
        let buf = unsafe { buf.assume_init() };
        let payload = head..head + n;
        let done = self
            .submit_loaned(&buf[payload.clone()], sample, timestamp)
            .map(|written| self.park_loaned(written, buf, payload));
        drop(reserved);
        Some(done)
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
