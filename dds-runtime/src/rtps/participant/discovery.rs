//! SPDP and SEDP processing, builtin endpoint wiring, and matching of user endpoints.

use std::time::Instant;

use tracing::{debug, trace};

use super::{Participant, ProxyParticipant};
use crate::qos::Durability;
use crate::rtps::api::{ChangeKind, Event, ReceivedSample, WriteChange};
use crate::rtps::discovery::matching::{match_endpoints, MatchResult, ReaderView, WriterView};
use crate::rtps::discovery::{builtin, ParticipantData, ReaderData, WriterData};
use crate::rtps::messages::parameter::pid;
use crate::rtps::messages::Data;
use crate::rtps::reader::WriterProxy;
use crate::rtps::types::*;
use crate::rtps::writer::ReaderProxy;

/// Upper bound on remote participants and endpoints, so discovery traffic cannot exhaust memory.
const MAX_PARTICIPANTS: usize = 4096;
const MAX_ENDPOINTS: usize = 65536;

impl Participant {
    pub(super) fn refresh_lease(&mut self, now: Instant, prefix: GuidPrefix) {
        if let Some(p) = self.participants.get_mut(&prefix) {
            p.lease_deadline = now + p.data.lease_duration;
        }
    }

    /// Writes a SEDP announcement (or its dispose) for a local endpoint.
    pub(super) fn announce(
        &mut self,
        now: Instant,
        sedp_writer: EntityId,
        guid: Guid,
        kind: ChangeKind,
        payload: Vec<u8>,
    ) {
        let payload = if kind == ChangeKind::Alive {
            payload
        } else {
            crate::rtps::discovery::encode_endpoint_key(&guid)
        };
        let change = WriteChange {
            kind,
            payload: payload.into(),
            key_hash: Some(guid.to_bytes()),
            source_timestamp: None,
        };
        if let Some(w) = self.writers.get_mut(&sedp_writer) {
            let _ = w.write(now, change, &mut self.out, &mut self.events);
        }
    }

    pub(super) fn on_spdp(&mut self, now: Instant, src: GuidPrefix, d: &Data<'_>) {
        let status = d.inline_qos.and_then(|q| q.status_info()).unwrap_or(0);
        if status & 0x03 != 0 {
            let guid = d
                .inline_qos
                .and_then(|q| q.key_hash())
                .map(|k| Guid::from_bytes(k).prefix)
                .or_else(|| d.payload.and_then(spdp_key_prefix))
                .unwrap_or(src);
            if self.participants.contains_key(&guid) {
                debug!(participant = ?guid, "participant left");
                self.remove_participant(guid);
            }
            return;
        }
        let Some(payload) = d.payload else { return };
        let data = match ParticipantData::decode(payload) {
            Ok(x) => x,
            Err(e) => {
                debug!(error = %e, "dropping SPDP sample");
                return;
            }
        };
        if data.guid_prefix == self.config.guid_prefix {
            return;
        }
        if data.domain_id.is_some_and(|d| d != self.config.domain_id) || !data.domain_tag.is_empty()
        {
            trace!(participant = ?data.guid_prefix, "SPDP from another domain");
            return;
        }
        let lease_deadline = now + data.lease_duration;
        if let Some(p) = self.participants.get_mut(&data.guid_prefix) {
            p.lease_deadline = lease_deadline;
            if p.data != data {
                p.data = data;
            }
            return;
        }
        if self.participants.len() >= MAX_PARTICIPANTS {
            return;
        }
        let prefix = data.guid_prefix;
        debug!(participant = ?prefix, vendor = ?data.vendor_id, "participant discovered");
        let meta: Vec<Locator> = if data.metatraffic_unicast.is_empty() {
            data.metatraffic_multicast.clone()
        } else {
            data.metatraffic_unicast.clone()
        };
        let bits = data.builtin_endpoints;
        self.events
            .push_back(Event::ParticipantDiscovered(Box::new(data.clone())));
        self.participants.insert(
            prefix,
            ProxyParticipant {
                data,
                lease_deadline,
            },
        );
        for (ours, theirs, bit) in builtin::WRITER_PAIRS {
            if bits & bit != 0 {
                if let Some(w) = self.writers.get_mut(&ours) {
                    let proxy = ReaderProxy::new(Guid::new(prefix, theirs), meta.clone(), true);
                    w.add_proxy(now, proxy, true, &mut self.events);
                }
            }
        }
        for (ours, theirs, bit) in builtin::READER_PAIRS {
            if bits & bit != 0 {
                if let Some(r) = self.readers.get_mut(&ours) {
                    r.add_proxy(
                        now,
                        WriterProxy::new(Guid::new(prefix, theirs), meta.clone(), true),
                    );
                    self.readers_by_writer.clear();
                }
            }
        }
        // Answer directly so the newcomer need not wait for our next periodic announcement.
        if !meta.is_empty() {
            self.send_spdp(Some(meta[..1].to_vec()));
        }
    }

    pub(super) fn remove_participant(&mut self, prefix: GuidPrefix) {
        if self.participants.remove(&prefix).is_none() {
            return;
        }
        self.readers_by_writer.retain(|w, _| w.prefix != prefix);
        for (ours, theirs, _) in builtin::WRITER_PAIRS {
            if let Some(w) = self.writers.get_mut(&ours) {
                w.remove_proxy(&Guid::new(prefix, theirs), &mut self.events);
            }
        }
        for (ours, theirs, _) in builtin::READER_PAIRS {
            if let Some(r) = self.readers.get_mut(&ours) {
                r.remove_proxy(&Guid::new(prefix, theirs));
            }
        }
        let writers: Vec<Guid> = self
            .known_writers
            .keys()
            .filter(|g| g.prefix == prefix)
            .copied()
            .collect();
        for g in writers {
            for (id, r) in self
                .readers
                .iter()
                .filter(|(id, _)| self.user_readers.contains(id))
            {
                if r.has_proxy(&g) {
                    self.events.push_back(Event::LivelinessChanged {
                        reader: *id,
                        writer: g,
                        alive: false,
                    });
                }
            }
            self.forget_writer(g);
            self.events.push_back(Event::PublicationRemoved { guid: g });
        }
        let readers: Vec<Guid> = self
            .known_readers
            .keys()
            .filter(|g| g.prefix == prefix)
            .copied()
            .collect();
        for g in readers {
            self.forget_reader(g);
            self.events
                .push_back(Event::SubscriptionRemoved { guid: g });
        }
        self.incompatible.retain(|(_, g)| g.prefix != prefix);
        self.events.push_back(Event::ParticipantLost {
            guid_prefix: prefix,
        });
    }

    pub(super) fn on_builtin_sample(&mut self, now: Instant, s: ReceivedSample) {
        match s.reader {
            EntityId::SEDP_PUBLICATIONS_READER => {
                if s.kind == ChangeKind::Alive {
                    match WriterData::decode(&s.payload) {
                        Ok(d) if d.guid.prefix == s.writer.prefix => {
                            if self.known_writers.len() < MAX_ENDPOINTS
                                || self.known_writers.contains_key(&d.guid)
                            {
                                let new = !self.known_writers.contains_key(&d.guid);
                                if new {
                                    self.events.push_back(Event::PublicationDiscovered(Box::new(
                                        d.clone(),
                                    )));
                                }
                                self.on_writer_known(now, d);
                            }
                        }
                        Ok(_) => {
                            debug!("SEDP publication for another participant's endpoint ignored")
                        }
                        Err(e) => debug!(error = %e, "dropping SEDP publication"),
                    }
                } else if let Some(g) = endpoint_of(&s) {
                    if g.prefix == s.writer.prefix && self.known_writers.contains_key(&g) {
                        self.forget_writer(g);
                        self.events.push_back(Event::PublicationRemoved { guid: g });
                    }
                }
            }
            EntityId::SEDP_SUBSCRIPTIONS_READER => {
                if s.kind == ChangeKind::Alive {
                    match ReaderData::decode(&s.payload) {
                        Ok(d) if d.guid.prefix == s.writer.prefix => {
                            if self.known_readers.len() < MAX_ENDPOINTS
                                || self.known_readers.contains_key(&d.guid)
                            {
                                if !self.known_readers.contains_key(&d.guid) {
                                    self.events
                                        .push_back(Event::SubscriptionDiscovered(Box::new(
                                            d.clone(),
                                        )));
                                }
                                self.on_reader_known(now, d);
                            }
                        }
                        Ok(_) => {
                            debug!("SEDP subscription for another participant's endpoint ignored")
                        }
                        Err(e) => debug!(error = %e, "dropping SEDP subscription"),
                    }
                } else if let Some(g) = endpoint_of(&s) {
                    if g.prefix == s.writer.prefix && self.known_readers.contains_key(&g) {
                        self.forget_reader(g);
                        self.events
                            .push_back(Event::SubscriptionRemoved { guid: g });
                    }
                }
            }
            EntityId::P2P_MESSAGE_READER => {
                if let Some((prefix, _kind)) = builtin::decode_participant_message(&s.payload) {
                    if prefix == s.writer.prefix {
                        self.refresh_lease(now, prefix);
                    }
                }
            }
            _ => {}
        }
    }

    /// Where to reach a known endpoint: its own unicast locators, else its participant's defaults.
    fn endpoint_locators(
        &self,
        prefix: GuidPrefix,
        uc: &[Locator],
        mc: &[Locator],
    ) -> Vec<Locator> {
        if !uc.is_empty() {
            return uc.to_vec();
        }
        if prefix == self.config.guid_prefix {
            return self.config.default_unicast.clone();
        }
        if let Some(p) = self.participants.get(&prefix) {
            if !p.data.default_unicast.is_empty() {
                return p.data.default_unicast.clone();
            }
            if !mc.is_empty() {
                return mc.to_vec();
            }
            return p.data.default_multicast.clone();
        }
        mc.to_vec()
    }

    /// A publication appeared or changed: (re)match it with every local reader.
    pub(super) fn on_writer_known(&mut self, now: Instant, d: WriterData) {
        let guid = d.guid;
        self.known_writers.insert(guid, d);
        let readers: Vec<EntityId> = self.user_readers.iter().copied().collect();
        for r in readers {
            self.match_reader_with(now, r, guid);
        }
        if guid.prefix == self.config.guid_prefix {
            let readers: Vec<Guid> = self.known_readers.keys().copied().collect();
            for r in readers {
                self.match_writer_with(now, guid.entity_id, r);
            }
        }
    }

    /// A subscription appeared or changed: (re)match it with every local writer.
    pub(super) fn on_reader_known(&mut self, now: Instant, d: ReaderData) {
        let guid = d.guid;
        self.known_readers.insert(guid, d);
        let writers: Vec<EntityId> = self.user_writers.iter().copied().collect();
        for w in writers {
            self.match_writer_with(now, w, guid);
        }
        if guid.prefix == self.config.guid_prefix {
            let writers: Vec<Guid> = self.known_writers.keys().copied().collect();
            for w in writers {
                self.match_reader_with(now, guid.entity_id, w);
            }
        }
    }

    fn match_writer_with(&mut self, now: Instant, wid: EntityId, reader: Guid) {
        let wguid = Guid::new(self.config.guid_prefix, wid);
        let (Some(wd), Some(rd)) = (
            self.known_writers.get(&wguid),
            self.known_readers.get(&reader),
        ) else {
            return;
        };
        let res = match_endpoints(
            WriterView {
                topic_name: &wd.topic_name,
                type_name: &wd.type_name,
                qos: &wd.qos,
            },
            ReaderView {
                topic_name: &rd.topic_name,
                type_name: &rd.type_name,
                qos: &rd.qos,
            },
        );
        let reliable = rd.qos.reader.reliability.is_reliable();
        let durable = rd.qos.reader.durability >= Durability::TransientLocal;
        let locators =
            self.endpoint_locators(reader.prefix, &rd.unicast_locators, &rd.multicast_locators);
        // The reader's implementation decides some wire forms (see `ReaderProxy::for_vendor`); our own
        // readers are not in `participants`.
        let vendor = self
            .participants
            .get(&reader.prefix)
            .map_or(VendorId::THIS, |p| p.data.vendor_id);
        let Some(w) = self.writers.get_mut(&wid) else {
            return;
        };
        if w.linger_until.is_some() {
            return;
        }
        let has = w.has_proxy(&reader);
        match res {
            MatchResult::Match => {
                if !has {
                    w.add_proxy(
                        now,
                        ReaderProxy::new(reader, locators, reliable).for_vendor(vendor),
                        durable,
                        &mut self.events,
                    );
                    self.events.push_back(Event::PublicationMatched {
                        writer: wid,
                        reader,
                        matched: true,
                    });
                }
                self.incompatible.remove(&(wid, reader));
            }
            other => {
                if has {
                    w.remove_proxy(&reader, &mut self.events);
                    self.events.push_back(Event::PublicationMatched {
                        writer: wid,
                        reader,
                        matched: false,
                    });
                }
                if let MatchResult::Incompatible(policy) = other {
                    if self.incompatible.insert((wid, reader)) {
                        self.events.push_back(Event::OfferedIncompatibleQos {
                            writer: wid,
                            reader,
                            policy,
                        });
                    }
                }
            }
        }
    }

    fn match_reader_with(&mut self, now: Instant, rid: EntityId, writer: Guid) {
        let rguid = Guid::new(self.config.guid_prefix, rid);
        let (Some(rd), Some(wd)) = (
            self.known_readers.get(&rguid),
            self.known_writers.get(&writer),
        ) else {
            return;
        };
        let res = match_endpoints(
            WriterView {
                topic_name: &wd.topic_name,
                type_name: &wd.type_name,
                qos: &wd.qos,
            },
            ReaderView {
                topic_name: &rd.topic_name,
                type_name: &rd.type_name,
                qos: &rd.qos,
            },
        );
        let reliable = wd.qos.writer.reliability.is_reliable();
        let locators =
            self.endpoint_locators(writer.prefix, &wd.unicast_locators, &wd.multicast_locators);
        let Some(r) = self.readers.get_mut(&rid) else {
            return;
        };
        let has = r.has_proxy(&writer);
        match res {
            MatchResult::Match => {
                if !has {
                    r.add_proxy(now, WriterProxy::new(writer, locators, reliable));
                    self.readers_by_writer.clear();
                    self.events.push_back(Event::SubscriptionMatched {
                        reader: rid,
                        writer,
                        matched: true,
                    });
                }
                self.incompatible.remove(&(rid, writer));
            }
            other => {
                if has {
                    r.remove_proxy(&writer);
                    self.events.push_back(Event::SubscriptionMatched {
                        reader: rid,
                        writer,
                        matched: false,
                    });
                }
                if let MatchResult::Incompatible(policy) = other {
                    if self.incompatible.insert((rid, writer)) {
                        self.events.push_back(Event::RequestedIncompatibleQos {
                            reader: rid,
                            writer,
                            policy,
                        });
                    }
                }
            }
        }
    }

    /// A publication is gone: unmatch it from local readers.
    pub(super) fn forget_writer(&mut self, g: Guid) {
        self.known_writers.remove(&g);
        self.readers_by_writer.remove(&g);
        for (id, r) in self.readers.iter_mut() {
            if self.user_readers.contains(id) && r.remove_proxy(&g) {
                self.events.push_back(Event::SubscriptionMatched {
                    reader: *id,
                    writer: g,
                    matched: false,
                });
            }
        }
        self.incompatible.retain(|(_, x)| *x != g);
    }

    /// A subscription is gone: unmatch it from local writers.
    pub(super) fn forget_reader(&mut self, g: Guid) {
        self.known_readers.remove(&g);
        for (id, w) in self.writers.iter_mut() {
            if self.user_writers.contains(id) && w.remove_proxy(&g, &mut self.events) {
                self.events.push_back(Event::PublicationMatched {
                    writer: *id,
                    reader: g,
                    matched: false,
                });
            }
        }
        self.incompatible.retain(|(_, x)| *x != g);
    }
}

/// The endpoint GUID of a SEDP dispose/unregister: the key hash (the GUID itself) or the key payload.
fn endpoint_of(s: &ReceivedSample) -> Option<Guid> {
    s.key_hash
        .map(Guid::from_bytes)
        .or_else(|| crate::rtps::discovery::endpoint_guid_of(&s.payload))
}

/// The participant prefix in an SPDP key-only payload.
fn spdp_key_prefix(payload: &[u8]) -> Option<GuidPrefix> {
    let pl = crate::rtps::discovery::pl_payload(payload).ok()?;
    let v = pl.get(pid::PARTICIPANT_GUID)?;
    pl.cursor(v).guid().ok().map(|g| g.prefix)
}
