//! A writer asserting its liveliness on the wire (MANUAL_BY_TOPIC, RTPS 2.5 §8.4.13): a HEARTBEAT with the
//! liveliness flag to every matched reader.

use super::Writer;
use crate::rtps::messages::Submessage;
use crate::rtps::outbox::{Outbox, Ts};
use crate::rtps::types::{EntityId, Locator};

impl Writer {
    /// Sends a final HEARTBEAT with the liveliness flag set to each matched reader's locator.
    pub(crate) fn send_liveliness(&mut self, out: &mut Outbox) {
        let mut dest: Vec<Locator> = self
            .proxies
            .values()
            .filter_map(|p| p.destination().first().copied())
            .collect();
        dest.sort();
        dest.dedup();
        if dest.is_empty() {
            return;
        }
        let mut hb = self.heartbeat(EntityId::UNKNOWN, true);
        if let Submessage::Heartbeat(h) = &mut hb {
            h.liveliness_flag = true;
        }
        out.push(&dest, None, Ts::Any, &hb);
    }
}
