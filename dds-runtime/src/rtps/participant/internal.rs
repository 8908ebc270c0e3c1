//! Service-internal endpoints (see [`EndpointSpec::internal`](crate::rtps::api::EndpointSpec::internal)):
//! a service inside the participant (the durability service's channel readers and stand-in writers) matches the
//! participant's user endpoints like any endpoint, but those matches are the service's business: the user
//! endpoints' matched and incompatible statuses, and their liveliness counts, never report them. Peers see the
//! service's endpoints as ordinary endpoints, and the service's own endpoints still get every event.

use crate::rtps::api::Event;
use crate::rtps::types::{EntityId, Guid};

use super::Participant;

impl Participant {
    /// Records `id` as a service-internal endpoint. Entity ids are never reused, so an id stays recorded
    /// after its endpoint is deleted: the unmatch events that trail a deletion stay hidden too.
    pub(super) fn mark_internal(&mut self, id: EntityId) {
        self.internal.insert(id);
    }

    /// Whether `ev` reports an internal endpoint of this participant to a local endpoint that is not one.
    pub(super) fn hides(&self, ev: &Event) -> bool {
        let (local, remote) = match ev {
            Event::PublicationMatched { writer, reader, .. }
            | Event::OfferedIncompatibleQos { writer, reader, .. } => (*writer, *reader),
            Event::SubscriptionMatched { reader, writer, .. }
            | Event::RequestedIncompatibleQos { reader, writer, .. }
            | Event::LivelinessChanged { reader, writer, .. } => (*reader, *writer),
            _ => return false,
        };
        self.is_own_internal(remote) && !self.internal.contains(&local)
    }

    fn is_own_internal(&self, g: Guid) -> bool {
        g.prefix == self.config.guid_prefix && self.internal.contains(&g.entity_id)
    }
}
