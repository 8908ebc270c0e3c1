//! QoS policies in parameter-list form (DDSI-RTPS 2.5 §9.6.2.2, XTypes 1.3 §7.6.3).

use std::time::Duration;

use super::EndpointQos;
use crate::qos::*;
use crate::rtps::messages::parameter::{pid, put_string, ParameterWriter};
use crate::rtps::messages::{Cursor, WireError};

fn limit(v: Option<u32>) -> i32 {
    v.map(|x| x.min(i32::MAX as u32) as i32).unwrap_or(-1)
}
fn unlimit(v: i32) -> Option<u32> {
    (v >= 0).then_some(v as u32)
}

fn history_kind(h: History) -> (u32, i32) {
    match h {
        History::KeepLast(d) => (0, d.min(i32::MAX as u32) as i32),
        History::KeepAll => (1, -1),
    }
}
fn history_from(kind: u32, depth: i32) -> History {
    if kind == 1 {
        History::KeepAll
    } else {
        History::KeepLast(depth.max(1) as u32)
    }
}

fn write_reliability(w: &mut ParameterWriter<'_>, r: Reliability) {
    let (kind, mbt) = match r {
        Reliability::BestEffort => (1, Duration::ZERO),
        Reliability::Reliable { max_blocking_time } => (2, max_blocking_time),
    };
    w.param(pid::RELIABILITY, |p| {
        p.u32(kind);
        p.duration(mbt);
    });
}

/// Appends the policies that open both a publication's and a subscription's QoS. `$d` is a
/// `DataWriterQos` or a `DataReaderQos`: they name these policies alike.
macro_rules! write_shared {
    ($w:expr, $d:expr) => {{
        let (w, d) = ($w, $d);
        w.u32(pid::DURABILITY, d.durability as u32);
        w.duration(pid::DEADLINE, d.deadline.0);
        w.duration(pid::LATENCY_BUDGET, d.latency_budget.0);
        w.param(pid::LIVELINESS, |p| {
            p.u32(d.liveliness.kind as u32);
            p.duration(d.liveliness.lease_duration);
        });
        write_reliability(w, d.reliability);
        w.u32(pid::DESTINATION_ORDER, d.destination_order as u32);
        w.u32(pid::OWNERSHIP, d.ownership as u32);
    }};
}

/// Appends the group and topic part of a `WriterQos` or `ReaderQos` (they name it alike).
macro_rules! write_group_of {
    ($w:expr, $q:expr) => {
        write_group(
            $w,
            $q.presentation,
            &$q.partition,
            &$q.group_data,
            &$q.topic_data,
        )
    };
}

fn write_group(
    w: &mut ParameterWriter<'_>,
    pres: Presentation,
    part: &Partition,
    group: &GroupData,
    topic: &TopicData,
) {
    w.param(pid::PRESENTATION, |p| {
        p.u32(pres.access_scope as u32);
        p.u8(pres.coherent_access as u8);
        p.u8(pres.ordered_access as u8);
    });
    if !part.0.is_empty() {
        w.param(pid::PARTITION, |p| {
            p.u32(part.0.len() as u32);
            for s in &part.0 {
                put_string(p, s);
                // Each string is 4-aligned relative to the parameter value; the value starts 4-aligned.
                while p.out.len() % 4 != 0 {
                    p.u8(0);
                }
            }
        });
    }
    if !group.0.is_empty() {
        w.octets(pid::GROUP_DATA, &group.0);
    }
    if !topic.0.is_empty() {
        w.octets(pid::TOPIC_DATA, &topic.0);
    }
}

fn write_history(w: &mut ParameterWriter<'_>, h: History, rl: &ResourceLimits) {
    let (k, d) = history_kind(h);
    w.param(pid::HISTORY, |p| {
        p.u32(k);
        p.i32(d);
    });
    w.param(pid::RESOURCE_LIMITS, |p| {
        p.i32(limit(rl.max_samples));
        p.i32(limit(rl.max_instances));
        p.i32(limit(rl.max_samples_per_instance));
    });
}

fn write_data_representation(w: &mut ParameterWriter<'_>, d: &DataRepresentation) {
    let ids = d.ids();
    if ids.is_empty() {
        return;
    }
    w.param(pid::DATA_REPRESENTATION, |p| {
        p.u32(ids.len() as u32);
        for v in ids {
            p.u16(*v as u16);
        }
    });
}

/// Decodes one of the policies a publication and a subscription share into `$q` (a `WriterQos` or a
/// `ReaderQos`; `$own` names its endpoint part, `writer` or `reader`), and evaluates to `Ok(true)`;
/// returns `Ok(false)` from the enclosing function when `$id` is not one of them.
macro_rules! read_shared {
    ($id:expr, $c:expr, $q:expr, $own:ident) => {{
        match $id {
            pid::DURABILITY => {
                $q.$own.durability = match $c.u32()? {
                    0 => Durability::Volatile,
                    1 => Durability::TransientLocal,
                    2 => Durability::Transient,
                    3 => Durability::Persistent,
                    _ => return Err(WireError::Invalid("durability kind")),
                }
            }
            pid::DEADLINE => $q.$own.deadline.0 = $c.duration()?,
            pid::LATENCY_BUDGET => $q.$own.latency_budget.0 = $c.duration()?,
            pid::LIVELINESS => {
                let kind = match $c.u32()? {
                    0 => crate::qos::LivelinessKind::Automatic,
                    1 => crate::qos::LivelinessKind::ManualByParticipant,
                    2 => crate::qos::LivelinessKind::ManualByTopic,
                    _ => return Err(WireError::Invalid("liveliness kind")),
                };
                $q.$own.liveliness = Liveliness {
                    kind,
                    lease_duration: $c.duration()?,
                };
            }
            pid::RELIABILITY => {
                let kind = $c.u32()?;
                let mbt = $c.duration().unwrap_or(Duration::from_millis(100));
                $q.$own.reliability = match kind {
                    1 => Reliability::BestEffort,
                    // 3 was RELIABLE in some pre-2.0 implementations.
                    2 | 3 => Reliability::Reliable {
                        max_blocking_time: mbt,
                    },
                    _ => return Err(WireError::Invalid("reliability kind")),
                };
            }
            pid::DESTINATION_ORDER => {
                $q.$own.destination_order = if $c.u32()? == 1 {
                    DestinationOrder::BySourceTimestamp
                } else {
                    DestinationOrder::ByReceptionTimestamp
                }
            }
            pid::OWNERSHIP => {
                $q.$own.ownership = if $c.u32()? == 1 {
                    Ownership::Exclusive
                } else {
                    Ownership::Shared
                }
            }
            pid::HISTORY => {
                let k = $c.u32()?;
                let d = $c.i32()?;
                $q.$own.history = history_from(k, d);
            }
            pid::RESOURCE_LIMITS => {
                $q.$own.resource_limits = ResourceLimits {
                    max_samples: unlimit($c.i32()?),
                    max_instances: unlimit($c.i32()?),
                    max_samples_per_instance: unlimit($c.i32()?),
                }
            }
            pid::USER_DATA => $q.$own.user_data.0 = $c.octets()?.to_vec(),
            pid::TOPIC_DATA => $q.topic_data.0 = $c.octets()?.to_vec(),
            pid::GROUP_DATA => $q.group_data.0 = $c.octets()?.to_vec(),
            pid::DATA_REPRESENTATION => {
                let n = $c.u32()? as usize;
                // Bound the allocation by what the parameter actually holds.
                if n > $c.remaining() / 2 {
                    return Err(WireError::Truncated);
                }
                let mut v = Vec::with_capacity(n);
                for _ in 0..n {
                    v.push($c.i16()?);
                }
                $q.$own.data_representation = DataRepresentation::any_of(v);
            }
            pid::PRESENTATION => {
                let scope = match $c.u32()? {
                    0 => crate::qos::PresentationAccessScope::Instance,
                    1 => crate::qos::PresentationAccessScope::Topic,
                    2 => crate::qos::PresentationAccessScope::Group,
                    _ => return Err(WireError::Invalid("presentation scope")),
                };
                $q.presentation = Presentation {
                    access_scope: scope,
                    coherent_access: $c.u8()? != 0,
                    ordered_access: $c.u8()? != 0,
                };
            }
            pid::PARTITION => {
                let n = $c.u32()? as usize;
                if n > $c.remaining() / 4 {
                    return Err(WireError::Truncated);
                }
                let mut v = Vec::with_capacity(n);
                for _ in 0..n {
                    $c.align(4)?;
                    v.push($c.string()?.to_owned());
                }
                $q.partition.0 = v;
            }
            _ => return Ok(false),
        }
        Ok(true)
    }};
}

impl EndpointQos for WriterQos {
    /// Appends the QoS parameters of a publication (DiscoveredWriterData).
    fn write_params(&self, w: &mut ParameterWriter<'_>) {
        let q = self;
        let d = &q.writer;
        write_shared!(&mut *w, d);
        let ds = d.durability_service;
        let (hk, hd) = history_kind(ds.history);
        w.param(pid::DURABILITY_SERVICE, |p| {
            p.duration(ds.service_cleanup_delay);
            p.u32(hk);
            p.i32(hd);
            p.i32(limit(ds.max_samples));
            p.i32(limit(ds.max_instances));
            p.i32(limit(ds.max_samples_per_instance));
        });
        w.i32(pid::OWNERSHIP_STRENGTH, d.ownership_strength.0);
        w.duration(pid::LIFESPAN, d.lifespan.0);
        write_history(w, d.history, &d.resource_limits);
        if d.transport_priority.0 != 0 {
            w.i32(pid::TRANSPORT_PRIORITY, d.transport_priority.0);
        }
        if !d.user_data.0.is_empty() {
            w.octets(pid::USER_DATA, &d.user_data.0);
        }
        write_data_representation(w, &d.data_representation);
        write_group_of!(w, q);
    }

    /// Decodes one publication QoS parameter; `Ok(false)` when it is not one.
    fn read_param(
        &mut self,
        id: u16,
        value: &[u8],
        little_endian: bool,
    ) -> Result<bool, WireError> {
        let q = self;
        let mut c = Cursor::new(value, little_endian);
        let d = &mut q.writer;
        match id {
            pid::DURABILITY_SERVICE => {
                let delay = c.duration()?;
                let k = c.u32()?;
                let depth = c.i32()?;
                d.durability_service = DurabilityService {
                    service_cleanup_delay: delay,
                    history: history_from(k, depth),
                    max_samples: unlimit(c.i32()?),
                    max_instances: unlimit(c.i32()?),
                    max_samples_per_instance: unlimit(c.i32()?),
                };
                Ok(true)
            }
            pid::OWNERSHIP_STRENGTH => {
                d.ownership_strength.0 = c.i32()?;
                Ok(true)
            }
            pid::LIFESPAN => {
                d.lifespan.0 = c.duration()?;
                Ok(true)
            }
            pid::TRANSPORT_PRIORITY => {
                d.transport_priority.0 = c.i32()?;
                Ok(true)
            }
            _ => read_shared!(id, c, q, writer),
        }
    }
}

impl EndpointQos for ReaderQos {
    /// Appends the QoS parameters of a subscription (DiscoveredReaderData).
    fn write_params(&self, w: &mut ParameterWriter<'_>) {
        let q = self;
        let d = &q.reader;
        write_shared!(&mut *w, d);
        w.duration(
            pid::TIME_BASED_FILTER,
            d.time_based_filter.minimum_separation,
        );
        write_history(w, d.history, &d.resource_limits);
        if !d.user_data.0.is_empty() {
            w.octets(pid::USER_DATA, &d.user_data.0);
        }
        write_data_representation(w, &d.data_representation);
        let tc = d.type_consistency;
        w.param(pid::TYPE_CONSISTENCY, |p| {
            p.u16(match tc.kind {
                TypeConsistencyKind::DisallowTypeCoercion => 0,
                TypeConsistencyKind::AllowTypeCoercion => 1,
            });
            for b in [
                tc.ignore_sequence_bounds,
                tc.ignore_string_bounds,
                tc.ignore_member_names,
                tc.prevent_type_widening,
                tc.force_type_validation,
            ] {
                p.u8(b as u8);
            }
        });
        write_group_of!(w, q);
    }

    /// Decodes one subscription QoS parameter; `Ok(false)` when it is not one.
    fn read_param(
        &mut self,
        id: u16,
        value: &[u8],
        little_endian: bool,
    ) -> Result<bool, WireError> {
        let q = self;
        let mut c = Cursor::new(value, little_endian);
        let d = &mut q.reader;
        match id {
            pid::TIME_BASED_FILTER => {
                d.time_based_filter.minimum_separation = c.duration()?;
                Ok(true)
            }
            pid::TYPE_CONSISTENCY => {
                let kind = c.u16()?;
                let mut b = [false; 5];
                for x in b.iter_mut() {
                    // Older senders stop after the kind; absent flags keep their defaults.
                    match c.u8() {
                        Ok(v) => *x = v != 0,
                        Err(_) => break,
                    }
                }
                let dflt = TypeConsistencyEnforcement::default();
                let full = value.len() >= 7;
                d.type_consistency = TypeConsistencyEnforcement {
                    kind: if kind == 0 {
                        TypeConsistencyKind::DisallowTypeCoercion
                    } else {
                        TypeConsistencyKind::AllowTypeCoercion
                    },
                    ignore_sequence_bounds: if full {
                        b[0]
                    } else {
                        dflt.ignore_sequence_bounds
                    },
                    ignore_string_bounds: if full {
                        b[1]
                    } else {
                        dflt.ignore_string_bounds
                    },
                    ignore_member_names: if full { b[2] } else { dflt.ignore_member_names },
                    prevent_type_widening: if full {
                        b[3]
                    } else {
                        dflt.prevent_type_widening
                    },
                    force_type_validation: if full {
                        b[4]
                    } else {
                        dflt.force_type_validation
                    },
                };
                Ok(true)
            }
            _ => read_shared!(id, c, q, reader),
        }
    }
}
