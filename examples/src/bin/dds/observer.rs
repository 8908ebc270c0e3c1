//! A bare participant (no endpoints, no durability service): what it discovers through SPDP and SEDP is what
//! `dds ls` and `dds ps` show, every writer and reader, not only those matched with an endpoint of its own.

use std::time::Duration;

use dds_runtime::prelude::*;

use crate::snapshot::Snapshot;

/// The observing participant.
pub(crate) struct Observer {
    participant: DomainParticipant,
}

impl Observer {
    /// Joins `domain` (else `DDS_DOMAIN_ID`, else 0; the other `DDS_*` variables apply too) and starts SPDP.
    pub(crate) fn join(domain: Option<u32>) -> DdsResult<Self> {
        let mut builder = DomainParticipant::builder()
            .name("dds")
            .durability_service(DurabilityServiceConfig::off());
        if let Some(d) = domain {
            builder = builder.domain_id(d);
        }
        Ok(Observer {
            participant: builder.build()?,
        })
    }

    /// Lets discovery run for `d`.
    pub(crate) fn run_for(&self, d: Duration) {
        std::thread::sleep(d);
    }

    /// The participant (for the dynamic endpoints of `subscribe` and `publish`).
    pub(crate) fn participant(&self) -> &DomainParticipant {
        &self.participant
    }

    /// What is known now.
    pub(crate) fn snapshot(&self) -> Snapshot {
        Snapshot::of(&self.participant)
    }
}
