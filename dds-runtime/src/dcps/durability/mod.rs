//! TRANSIENT and PERSISTENT durability: the durability service (DDS 1.4 §2.2.3.4–5).
//!
//! Every participant runs a service for its own TRANSIENT and PERSISTENT writers (so their data outlives
//! the writer for as long as the participant lives); the standalone program `dds-durability` runs one for
//! the whole domain, and with a persistent store keeps PERSISTENT data across restarts. Choose with
//! [`DurabilityServiceConfig`] on [`DomainParticipantBuilder::durability_service`](super::DomainParticipantBuilder::durability_service)
//! or the environment (`DDS_DURABILITY_SERVICE`, `DDS_DURABILITY_STORE`). docs/durability.md describes the
//! design, the guarantees and the limits.

mod dedup;
mod history;
mod key;
use super::stand_in as marker;
mod service;
#[cfg(feature = "persistence")]
mod store;

use std::path::PathBuf;
use std::sync::Arc;
use std::time::{Duration, Instant};

pub use key::peer_key_hash;
#[cfg(feature = "persistence")]
pub use store::StoreError;

use super::driver::Driver;
use super::error::DdsResult;
use crate::rtps::EntityId;
use service::{Scope, Service};

/// Which writers a participant's durability service keeps.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[non_exhaustive]
pub enum DurabilityServiceMode {
    /// No service: TRANSIENT and PERSISTENT writers behave as TRANSIENT_LOCAL ones.
    Off,
    /// The participant's own TRANSIENT and PERSISTENT writers (the default).
    #[default]
    Local,
    /// Every TRANSIENT and PERSISTENT writer of the domain (what `dds-durability` runs).
    Domain,
}

/// The durability service of a participant.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct DurabilityServiceConfig {
    mode: DurabilityServiceMode,
    store: Option<PathBuf>,
    max_changes_per_writer: usize,
}

impl Default for DurabilityServiceConfig {
    fn default() -> Self {
        DurabilityServiceConfig {
            mode: DurabilityServiceMode::Local,
            store: None,
            max_changes_per_writer: Self::DEFAULT_MAX_CHANGES_PER_WRITER,
        }
    }
}

impl DurabilityServiceConfig {
    /// Default bound of the changes kept per original writer.
    pub const DEFAULT_MAX_CHANGES_PER_WRITER: usize = 100_000;

    /// The default: a service for the participant's own writers, in memory.
    pub fn local() -> Self {
        Self::default()
    }
    /// No durability service.
    pub fn off() -> Self {
        Self::default().mode(DurabilityServiceMode::Off)
    }
    /// A service for the whole domain (the standalone program).
    pub fn domain() -> Self {
        Self::default().mode(DurabilityServiceMode::Domain)
    }
    /// Sets the mode.
    pub fn mode(mut self, mode: DurabilityServiceMode) -> Self {
        self.mode = mode;
        self
    }
    /// Keeps PERSISTENT data in the redb database at `path` (created when missing) and restores it at start.
    /// Without a store, PERSISTENT data is kept in memory as TRANSIENT data is.
    pub fn persistent_store(mut self, path: impl Into<PathBuf>) -> Self {
        self.store = Some(path.into());
        self
    }
    /// Bounds the changes kept per original writer, whatever its DURABILITY_SERVICE QoS allows (at least 1).
    pub fn max_changes_per_writer(mut self, n: usize) -> Self {
        self.max_changes_per_writer = n.max(1);
        self
    }
    /// The mode.
    pub fn get_mode(&self) -> DurabilityServiceMode {
        self.mode
    }
    /// The persistent store's path, if any.
    pub fn store_path(&self) -> Option<&std::path::Path> {
        self.store.as_deref()
    }

    /// The configuration from `DDS_DURABILITY_SERVICE` (`off`, `local` or `domain`; default `local`) and
    /// `DDS_DURABILITY_STORE` (a path). An unknown mode is an error.
    pub fn from_env() -> DdsResult<Self> {
        let mut c = Self::default();
        if let Ok(m) = std::env::var("DDS_DURABILITY_SERVICE") {
            c.mode = match m.to_ascii_lowercase().as_str() {
                "off" | "0" | "false" => DurabilityServiceMode::Off,
                "local" | "" => DurabilityServiceMode::Local,
                "domain" => DurabilityServiceMode::Domain,
                _ => {
                    return Err(super::DdsError::BadParameter(format!(
                        "DDS_DURABILITY_SERVICE={m}: expected off, local or domain"
                    )))
                }
            };
        }
        if let Some(p) = std::env::var_os("DDS_DURABILITY_STORE") {
            c.store = Some(p.into());
        }
        Ok(c)
    }
}

/// Installs the duplicate filter and, unless off, the service on a new participant's driver.
pub(crate) fn install(driver: &Arc<Driver>, config: &DurabilityServiceConfig) -> DdsResult<()> {
    let filter = Arc::new(dedup::ReplayFilter::default());
    driver.add_observer(filter.clone());
    // The driver already runs: writers it discovered before the filter was in place are learnt here (a
    // peer's history can arrive right after, as a late joiner's push).
    driver.query_core(|c| c.publications().for_each(|w| filter.learn(w)));
    let scope = match config.mode {
        DurabilityServiceMode::Off => return Ok(()),
        DurabilityServiceMode::Local => Scope::Local(driver.guid_prefix),
        DurabilityServiceMode::Domain => Scope::Domain,
    };
    #[cfg(feature = "persistence")]
    let store = match &config.store {
        Some(p) => Some(store::PersistentStore::open(p).map_err(std::io::Error::other)?),
        None => None,
    };
    #[cfg(not(feature = "persistence"))]
    if config.store.is_some() {
        return Err(super::DdsError::Unsupported(
            "a persistent store needs the `persistence` feature",
        ));
    }
    let svc = Service::new(
        driver,
        scope,
        config.max_changes_per_writer,
        #[cfg(feature = "persistence")]
        store,
    );
    driver.add_observer(svc.clone());
    #[cfg(feature = "persistence")]
    svc.restore().map_err(std::io::Error::other)?;
    svc.adopt_known();
    Ok(())
}

/// `DataReader::wait_for_historical_data`: waits until the reader `reader` received everything its matched
/// reliable writers (the services' stand-ins included) announced.
pub(crate) fn wait_for_historical_data(
    driver: &Driver,
    reader: EntityId,
    timeout: Duration,
) -> DdsResult<bool> {
    driver.check_alive()?;
    let deadline = Instant::now().checked_add(timeout);
    Ok(driver.wait_progress(deadline, || {
        driver.query_core(|c| c.reader_caught_up(reader))
    }))
}
