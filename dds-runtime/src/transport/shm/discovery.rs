//! Which peers can use shared memory: a participant built with the `shm` feature announces its host's
//! identity in SPDP (`PID_PROPERTY_LIST`, property [`SHM_HOST_PROPERTY`]); a peer that announced the same
//! identity runs on this host, with this feature. Every other peer is reached over UDP.

pub use crate::rtps::shm::SHM_HOST_PROPERTY;

/// This host's identity for shared memory: the kernel's boot id (the same in every network namespace of
/// one boot of one machine); `None` where the kernel does not provide it.
pub fn host_id() -> Option<String> {
    let id = std::fs::read_to_string("/proc/sys/kernel/random/boot_id").ok()?;
    let id = id.trim();
    (!id.is_empty()).then(|| id.to_owned())
}

/// Whether a participant that announced `properties` (from its SPDP data) can exchange samples with this
/// process over shared memory.
pub fn peer_can_use_shm(properties: &[(String, String)]) -> bool {
    host_id().is_some_and(|h| {
        properties
            .iter()
            .any(|(k, v)| k == SHM_HOST_PROPERTY && *v == h)
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn same_boot_id_only() {
        let Some(h) = host_id() else { return };
        let p = |v: &str| vec![(SHM_HOST_PROPERTY.to_owned(), v.to_owned())];
        assert!(peer_can_use_shm(&p(&h)));
        assert!(!peer_can_use_shm(&p("another-host")));
        assert!(!peer_can_use_shm(&[]));
    }
}
