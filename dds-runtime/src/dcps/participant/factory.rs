//! `DomainParticipantFactory` (DDS 1.4 §2.2.2.2.2): the process-wide factory with its own default
//! participant QoS, `lookup_participant` and `delete_participant`.

use std::sync::{Mutex, OnceLock};

use crate::qos::{DomainParticipantFactoryQos, DomainParticipantQos};

use super::super::error::{DdsError, DdsResult};
use super::super::sync::lock;
use super::{DomainParticipant, WeakParticipant};

/// Most participants tracked for `lookup_participant` (the dead ones are pruned first).
const MAX_TRACKED: usize = 4096;

/// The participant factory: one per process ([`DomainParticipantFactory::get_instance`]). It creates
/// participants with its default participant QoS and finds the live ones by domain.
/// [`DomainParticipant::builder`] creates participants through it too.
pub struct DomainParticipantFactory {
    default_qos: Mutex<DomainParticipantQos>,
    qos: Mutex<DomainParticipantFactoryQos>,
    participants: Mutex<Vec<(u32, WeakParticipant)>>,
}

impl std::fmt::Debug for DomainParticipantFactory {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("DomainParticipantFactory")
            .field("default_qos", &*lock(&self.default_qos))
            .field("qos", &*lock(&self.qos))
            .finish()
    }
}

impl DomainParticipantFactory {
    /// The factory (`get_instance`).
    pub fn get_instance() -> &'static DomainParticipantFactory {
        static FACTORY: OnceLock<DomainParticipantFactory> = OnceLock::new();
        FACTORY.get_or_init(|| DomainParticipantFactory {
            default_qos: Mutex::new(DomainParticipantQos::default()),
            qos: Mutex::new(DomainParticipantFactoryQos::default()),
            participants: Mutex::new(Vec::new()),
        })
    }

    /// Creates a participant in `domain_id` with `qos` and the configuration from the environment
    /// (`create_participant`); [`DomainParticipant::builder`] offers the transport settings as well.
    pub fn create_participant(
        &self,
        domain_id: u32,
        qos: &DomainParticipantQos,
    ) -> DdsResult<DomainParticipant> {
        DomainParticipant::builder()
            .domain_id(domain_id)
            .qos(qos.clone())
            .build()
    }

    /// A live participant of `domain_id` created in this process, if any (`lookup_participant`).
    pub fn lookup_participant(&self, domain_id: u32) -> Option<DomainParticipant> {
        lock(&self.participants)
            .iter()
            .filter(|(d, _)| *d == domain_id)
            .find_map(|(_, w)| w.upgrade().filter(|p| p.driver.check_alive().is_ok()))
    }

    /// Deletes `participant` (`delete_participant`): `PreconditionNotMet` while it contains entities
    /// (delete them first, or call [`DomainParticipant::delete_contained_entities`]). It announces its
    /// departure and stops; its handles then return `AlreadyDeleted`.
    pub fn delete_participant(&self, participant: &DomainParticipant) -> DdsResult<()> {
        participant.driver.check_alive()?;
        if participant.has_contained_entities() {
            return Err(DdsError::PreconditionNotMet(
                "the participant still contains entities",
            ));
        }
        participant.driver.shutdown();
        Ok(())
    }

    /// Sets the QoS new participants get by default (`set_default_participant_qos`).
    pub fn set_default_participant_qos(&self, qos: &DomainParticipantQos) -> DdsResult<()> {
        *lock(&self.default_qos) = qos.clone();
        Ok(())
    }

    /// The QoS new participants get by default (`get_default_participant_qos`).
    pub fn default_participant_qos(&self) -> DomainParticipantQos {
        lock(&self.default_qos).clone()
    }

    /// The factory's own QoS (`get_qos`).
    pub fn qos(&self) -> DomainParticipantFactoryQos {
        lock(&self.qos).clone()
    }

    /// Sets the factory's QoS (`set_qos`). `autoenable_created_entities = false` is accepted, and then
    /// participant creation returns `Unsupported` (every entity is enabled when created).
    pub fn set_qos(&self, qos: &DomainParticipantFactoryQos) -> DdsResult<()> {
        *lock(&self.qos) = qos.clone();
        Ok(())
    }

    /// Remembers a new participant for `lookup_participant`.
    pub(super) fn register(&self, p: &DomainParticipant) {
        let mut ps = lock(&self.participants);
        ps.retain(|(_, w)| w.upgrade().is_some_and(|p| p.driver.check_alive().is_ok()));
        if ps.len() < MAX_TRACKED {
            ps.push((p.domain_id(), p.downgrade()));
        }
    }
}
