//! How a durability service's stand-in writer says whom it stands for: its USER_DATA is this prefix
//! followed by the 16-byte GUID of the original writer. Other services skip such writers (no service
//! replays another's replay), readers use it to drop repeats (`durability/dedup.rs`) and report the
//! original writer as the changes' publication (`RemoteWriterInfo::original` in `driver.rs`).

use crate::rtps::Guid;

const PREFIX: &[u8] = b"dds-rs durability stand-in for ";

/// The USER_DATA of a stand-in for `original`.
pub(crate) fn user_data(original: &Guid) -> Vec<u8> {
    let mut v = PREFIX.to_vec();
    v.extend_from_slice(&original.to_bytes());
    v
}

/// The original writer, when `user_data` is a stand-in's.
pub(crate) fn stand_in_for(user_data: &[u8]) -> Option<Guid> {
    let g: [u8; 16] = user_data.strip_prefix(PREFIX)?.try_into().ok()?;
    Some(Guid::from_bytes(g))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rtps::{EntityId, GuidPrefix};

    #[test]
    fn round_trip() {
        let g = Guid::new(GuidPrefix([1; 12]), EntityId([0, 0, 1, 2]));
        assert_eq!(stand_in_for(&user_data(&g)), Some(g));
        assert_eq!(stand_in_for(b"other"), None);
        assert_eq!(stand_in_for(&user_data(&g)[..20]), None);
    }
}
