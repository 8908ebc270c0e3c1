//! Packs outgoing submessages into datagrams per (destinations, INFO_DST) up to max_message_size.

use std::collections::VecDeque;

use super::api::Transmit;
use super::messages::{Header, Submessage};
use super::types::*;

/// Whether a submessage depends on the INFO_TS in force.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Ts {
    /// Control submessage: whatever timestamp is in force does not matter.
    Any,
    /// DATA/DATA_FRAG: this timestamp (or none) must be in force.
    Set(Option<Time>),
}

#[derive(Debug)]
struct Pending {
    destinations: Vec<Locator>,
    dst: Option<GuidPrefix>,
    buf: Vec<u8>,
    /// The INFO_TS state the receiver will be in: None = nothing sent yet in this message.
    ts: Option<Option<Time>>,
    preamble: usize,
}

/// Output queue: open messages being packed and finished datagrams.
#[derive(Debug)]
pub(crate) struct Outbox {
    header: Header,
    max: usize,
    pending: Vec<Pending>,
    ready: VecDeque<Transmit>,
    pool: Vec<Vec<u8>>,
}

impl Outbox {
    pub fn new(header: Header, max_message_size: usize) -> Self {
        Outbox { header, max: max_message_size.max(128), pending: Vec::new(), ready: VecDeque::new(), pool: Vec::new() }
    }

    fn open(&mut self, destinations: &[Locator], dst: Option<GuidPrefix>) -> usize {
        if let Some(i) = self.pending.iter().position(|p| p.dst == dst && p.destinations == destinations) {
            return i;
        }
        let mut buf = self.pool.pop().unwrap_or_default();
        buf.clear();
        self.header.write(&mut buf);
        if let Some(d) = dst {
            Submessage::InfoDst(d).encode(&mut buf, true);
        }
        let preamble = buf.len();
        self.pending.push(Pending { destinations: destinations.to_vec(), dst, buf, ts: None, preamble });
        self.pending.len() - 1
    }

    /// Appends `sub` to the message for (destinations, dst); starts a new datagram when it would not fit.
    pub fn push(&mut self, destinations: &[Locator], dst: Option<GuidPrefix>, ts: Ts, sub: &Submessage<'_>) {
        if destinations.is_empty() {
            return;
        }
        let i = self.open(destinations, dst);
        let p = &mut self.pending[i];
        let before = p.buf.len();
        let ts_before = p.ts;
        write_ts(p, ts);
        sub.encode(&mut p.buf, true);
        if p.buf.len() > self.max && before > p.preamble {
            // Did not fit: close the message without it and put it first in a fresh one.
            p.buf.truncate(before);
            p.ts = ts_before;
            let done = self.pending.swap_remove(i);
            self.ready.push_back(Transmit { destinations: done.destinations, payload: done.buf });
            let i = self.open(destinations, dst);
            let p = &mut self.pending[i];
            write_ts(p, ts);
            sub.encode(&mut p.buf, true);
        }
    }

    /// Closes every open message.
    pub fn flush(&mut self) {
        for p in self.pending.drain(..) {
            if p.buf.len() > p.preamble {
                self.ready.push_back(Transmit { destinations: p.destinations, payload: p.buf });
            } else {
                self.pool.push(p.buf);
            }
        }
    }

    pub fn pop(&mut self) -> Option<Transmit> {
        if self.ready.is_empty() {
            self.flush();
        }
        self.ready.pop_front()
    }

    /// Returns a datagram buffer for reuse.
    pub fn recycle(&mut self, buf: Vec<u8>) {
        if self.pool.len() < 64 {
            self.pool.push(buf);
        }
    }
}

fn write_ts(p: &mut Pending, ts: Ts) {
    if let Ts::Set(t) = ts {
        // Nothing sent yet means no timestamp in force at the receiver.
        if p.ts.unwrap_or(None) != t {
            Submessage::InfoTs(t).encode(&mut p.buf, true);
            p.ts = Some(t);
        }
    }
}
