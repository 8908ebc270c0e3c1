//! Incoming datagrams: the receiver state (§8.3.4) and dispatch of submessages to writers and readers.

use std::collections::hash_map::Entry;
use std::collections::BTreeMap;
use std::time::Instant;

use foldhash::HashMap;
use tracing::{debug, trace};

use super::timers::lower_floor;
use super::Participant;
use crate::rtps::api::{Event, Payload};
use crate::rtps::discovery::builtin;
use crate::rtps::discovery::topics::TOPIC_READER_PAIR;
use crate::rtps::messages::{id, AckNack, Data, DataFrag, Heartbeat, MessageIter, Submessage};
use crate::rtps::reader::Reader;
use crate::rtps::types::*;

/// Whether the message holds a DATA submessage: a walk over the submessage headers only. A malformed
/// message may give either answer; it is rejected by the parse that follows.
fn holds_data(msg: &[u8]) -> bool {
    const HEADER: usize = 20;
    let mut at = HEADER;
    while let Some(h) = msg.get(at..at + 4) {
        if h[0] == id::DATA {
            return true;
        }
        let len = if h[1] & 1 != 0 {
            u16::from_le_bytes([h[2], h[3]])
        } else {
            u16::from_be_bytes([h[2], h[3]])
        };
        if len == 0 {
            // Runs to the end of the message (or is empty, and then only INFO_TS/PAD may follow).
            if h[0] != id::INFO_TS && h[0] != id::PAD {
                return false;
            }
        }
        at += 4 + usize::from(len);
    }
    false
}

/// The receiver state of one message (§8.3.4): who sent what follows, whether it is for us, the timestamp.
struct Receiver {
    src: GuidPrefix,
    for_us: bool,
    ts: Option<Time>,
}

impl Receiver {
    /// Applies an interpreter submessage (INFO_TS, INFO_SRC, INFO_DST); returns any other one addressed to
    /// `ours`.
    fn interpret<'a>(&mut self, sub: Submessage<'a>, ours: GuidPrefix) -> Option<Submessage<'a>> {
        match sub {
            Submessage::InfoTs(t) => self.ts = t,
            Submessage::InfoSrc(s) => {
                self.src = s.guid_prefix;
                self.for_us = true;
                self.ts = None;
            }
            Submessage::InfoDst(p) => self.for_us = p == ours || p == GuidPrefix::UNKNOWN,
            sub if self.for_us => return Some(sub),
            _ => {}
        }
        None
    }
}

impl Participant {
    /// Processes one datagram. Never panics; malformed input is dropped with a `tracing` event.
    pub fn handle_datagram(&mut self, now: Instant, data: &[u8]) {
        self.receive(now, data, None);
    }

    /// Like [`handle_datagram`](Self::handle_datagram), for a datagram already in shared memory: delivered
    /// samples share its buffer rather than copying their payloads out of it.
    pub fn handle_shared_datagram(&mut self, now: Instant, datagram: &Payload) {
        self.receive(now, datagram, Some(datagram));
    }

    /// Like [`handle_shared_datagram`](Self::handle_shared_datagram) for a datagram in a buffer the caller
    /// reuses: when it holds DATA it is copied into a reusable buffer of the participant's pool, which its
    /// samples share; otherwise it is read where it is, and fragments go straight to their reassembly
    /// buffers (one copy, not two).
    pub fn handle_datagram_sharing(&mut self, now: Instant, data: &[u8]) {
        if holds_data(data) {
            let copy = self
                .rx_pools
                .datagrams
                .fill(|v| {
                    v.extend_from_slice(data);
                    Ok::<_, std::convert::Infallible>(())
                })
                .unwrap_or_default();
            self.receive(now, &copy, Some(&copy));
        } else {
            self.receive(now, data, None);
        }
    }

    fn receive(&mut self, now: Instant, data: &[u8], shared: Option<&Payload>) {
        if !self.enabled {
            return;
        }
        let (header, subs) = match MessageIter::parse(data) {
            Ok(x) => x,
            Err(e) => {
                trace!(error = %e, len = data.len(), "dropping datagram");
                return;
            }
        };
        let mut rx = Receiver {
            src: header.guid_prefix,
            for_us: true,
            ts: None,
        };
        self.refresh_lease(now, rx.src);
        for sub in subs {
            let sub = match sub {
                Ok(s) => s,
                Err(e) => {
                    debug!(error = %e, source = ?rx.src, "invalid submessage; ignoring the rest of the message");
                    break;
                }
            };
            if let Some(sub) = rx.interpret(sub, self.config.guid_prefix) {
                self.dispatch(now, &rx, sub, shared);
            }
            self.route_deliveries(now);
        }
        self.service(now);
    }

    /// Hands one submessage addressed to us to the writers or readers it concerns.
    fn dispatch(
        &mut self,
        now: Instant,
        rx: &Receiver,
        sub: Submessage<'_>,
        shared: Option<&Payload>,
    ) {
        let src = rx.src;
        match sub {
            Submessage::Data(d) if d.writer_id == EntityId::SPDP_WRITER => {
                self.on_spdp(now, src, &d);
                self.timers_changed();
            }
            Submessage::Data(d) => self.on_data_sub(now, rx, &d, shared),
            Submessage::DataFrag(d) => self.on_data_frag_sub(now, rx, &d),
            Submessage::Heartbeat(h) => self.on_heartbeat_sub(now, src, &h),
            Submessage::Gap(g) => {
                let wguid = Guid::new(src, g.writer_id);
                let scratch = &mut self.scratch;
                let readers = &mut self.readers;
                for_readers(
                    readers,
                    &mut self.readers_by_writer,
                    g.reader_id,
                    wguid,
                    |r| r.on_gap(wguid, &g, scratch),
                );
            }
            Submessage::HeartbeatFrag(h) => {
                let wguid = Guid::new(src, h.writer_id);
                self.for_readers_arming(h.reader_id, wguid, |r, _| {
                    r.on_heartbeat_frag(now, wguid, &h)
                });
            }
            Submessage::AckNack(a) => self.on_acknack_sub(now, src, &a),
            Submessage::NackFrag(n) => {
                if let Some(w) = self.writers.get_mut(&n.writer_id) {
                    w.on_nack_frag(now, Guid::new(src, n.reader_id), &n);
                    lower_floor(&self.timer_floor, w.next_timeout());
                }
            }
            Submessage::Unknown { id, .. } => trace!(id, "skipping unknown submessage"),
            Submessage::Pad
            | Submessage::InfoReply(_)
            | Submessage::InfoReplyIp4(_)
            | Submessage::InfoTs(_)
            | Submessage::InfoSrc(_)
            | Submessage::InfoDst(_) => {}
        }
    }

    fn on_data_sub(&mut self, now: Instant, rx: &Receiver, d: &Data<'_>, shared: Option<&Payload>) {
        let wguid = Guid::new(rx.src, d.writer_id);
        self.service_traffic(now, wguid);
        let (scratch, ts) = (&mut self.scratch, rx.ts);
        for_readers(
            &mut self.readers,
            &mut self.readers_by_writer,
            d.reader_id,
            wguid,
            |r| r.on_data(wguid, d, ts, shared, scratch),
        );
        self.writer_asserted(now, wguid);
    }

    fn on_data_frag_sub(&mut self, now: Instant, rx: &Receiver, d: &DataFrag<'_>) {
        let wguid = Guid::new(rx.src, d.writer_id);
        self.service_traffic(now, wguid);
        let (scratch, ts) = (&mut self.scratch, rx.ts);
        let pool = &mut self.rx_pools.samples;
        for_readers(
            &mut self.readers,
            &mut self.readers_by_writer,
            d.reader_id,
            wguid,
            |r| r.on_data_frag(wguid, d, ts, pool, scratch),
        );
        self.writer_asserted(now, wguid);
    }

    fn on_heartbeat_sub(&mut self, now: Instant, src: GuidPrefix, h: &Heartbeat) {
        let wguid = Guid::new(src, h.writer_id);
        if h.last_sn >= h.first_sn {
            // Changes we may have lost: a request or reply.
            self.service_traffic(now, wguid);
        }
        self.for_readers_arming(h.reader_id, wguid, |r, scratch| {
            r.on_heartbeat(now, wguid, h, scratch)
        });
        self.route_deliveries(now);
        self.on_group_heartbeat(wguid, h);
        if h.liveliness_flag {
            self.writer_asserted(now, wguid);
        }
    }

    fn on_acknack_sub(&mut self, now: Instant, src: GuidPrefix, a: &AckNack) {
        let Some(w) = self.writers.get_mut(&a.writer_id) else {
            return;
        };
        w.on_acknack(now, Guid::new(src, a.reader_id), a, &mut self.events);
        if w.linger_until.is_some() {
            // An acknowledged lingering writer is finished at the next pass.
            self.timer_floor.set(Some(now));
        } else {
            lower_floor(&self.timer_floor, w.next_timeout());
        }
    }

    /// `for_readers` for a submessage that may arm reader timers: the timer floor follows.
    fn for_readers_arming(
        &mut self,
        reader_id: EntityId,
        writer: Guid,
        mut f: impl FnMut(&mut Reader, &mut Vec<Event>),
    ) {
        let scratch = &mut self.scratch;
        let floor = &self.timer_floor;
        for_readers(
            &mut self.readers,
            &mut self.readers_by_writer,
            reader_id,
            writer,
            |r| {
                f(r, scratch);
                lower_floor(floor, r.next_timeout());
            },
        );
    }

    /// Hands what readers delivered to discovery (builtin readers) or to the application (events).
    /// Inlined for the check: it runs after every submessage, most of which delivered nothing, and the
    /// routing's entry and exit cost more than the check.
    #[inline]
    fn route_deliveries(&mut self, now: Instant) {
        if !self.scratch.is_empty() {
            self.route_scratch(now);
        }
    }

    fn route_scratch(&mut self, now: Instant) {
        self.group_order.tick(now);
        let mut batch = std::mem::take(&mut self.scratch);
        for ev in batch.drain(..) {
            match ev {
                Event::Sample(s) if s.reader.is_builtin() => {
                    self.on_builtin_sample(now, s);
                    self.timers_changed();
                }
                Event::SampleLost { reader, .. } if reader.is_builtin() => {}
                e => self.push_delivery(e),
            }
        }
        self.scratch = batch;
    }
}

/// Runs `f` on the addressed reader, or on every reader matched with `writer` when the reader id is UNKNOWN
/// (looked up through `index`, which is filled here and only for writers some reader is matched with, so that
/// unknown writers cannot grow it).
fn for_readers(
    readers: &mut BTreeMap<EntityId, Reader>,
    index: &mut HashMap<Guid, Vec<EntityId>>,
    reader_id: EntityId,
    writer: Guid,
    mut f: impl FnMut(&mut Reader),
) {
    if reader_id != EntityId::UNKNOWN {
        if let Some(r) = readers.get_mut(&reader_id) {
            if r.has_proxy(&writer) {
                f(r);
            }
        }
        return;
    }
    if let Some(id) = builtin_reader_of(writer.entity_id) {
        // A builtin writer has one reader of ours: no index entry per remote builtin writer (about ten per
        // discovered participant).
        if let Some(r) = readers.get_mut(&id) {
            if r.has_proxy(&writer) {
                f(r);
            }
        }
        return;
    }
    // A known writer (every sample but the first) is found without the entry's room check.
    let ids = match index.get_mut(&writer) {
        Some(ids) => ids,
        None => match index.entry(writer) {
            Entry::Occupied(e) => e.into_mut(),
            Entry::Vacant(e) => {
                let ids: Vec<EntityId> = readers
                    .iter()
                    .filter(|(_, r)| r.has_proxy(&writer))
                    .map(|(id, _)| *id)
                    .collect();
                if ids.is_empty() {
                    return;
                }
                e.insert(ids)
            }
        },
    };
    for id in ids.iter() {
        if let Some(r) = readers.get_mut(id) {
            if r.has_proxy(&writer) {
                f(r);
            }
        }
    }
}

/// Our builtin reader that listens to the remote builtin writer `writer`, if it is one.
fn builtin_reader_of(writer: EntityId) -> Option<EntityId> {
    if !writer.is_builtin() {
        return None;
    }
    builtin::READER_PAIRS
        .iter()
        .chain([&TOPIC_READER_PAIR])
        .find(|(_, theirs, _)| *theirs == writer)
        .map(|(ours, _, _)| *ours)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A message: the 20-byte header, then (id, little-endian length, body length) submessages.
    fn msg(subs: &[(u8, u16, usize)]) -> Vec<u8> {
        let mut m = vec![0u8; 20];
        for &(id, len, body) in subs {
            m.extend_from_slice(&[id, 1]);
            m.extend_from_slice(&len.to_le_bytes());
            m.resize(m.len() + body, 0);
        }
        m
    }

    #[test]
    fn holds_data_scans_submessage_headers_only() {
        assert!(holds_data(&msg(&[(id::INFO_TS, 8, 8), (id::DATA, 4, 4)])));
        assert!(holds_data(&msg(&[(id::INFO_TS, 0, 0), (id::DATA, 0, 12)])));
        assert!(!holds_data(&msg(&[
            (id::INFO_TS, 8, 8),
            (id::DATA_FRAG, 4, 4)
        ])));
        // A submessage of length 0 other than INFO_TS/PAD runs to the end: nothing follows it.
        assert!(!holds_data(&msg(&[
            (id::HEARTBEAT_FRAG, 0, 0),
            (id::DATA, 4, 4)
        ])));
        assert!(!holds_data(&[0u8; 10]));
        // A length past the end stops the scan.
        assert!(!holds_data(&msg(&[(id::DATA_FRAG, 900, 4)])));
    }
}
