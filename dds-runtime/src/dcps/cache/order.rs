//! Which changes an instance accepts from which writer: EXCLUSIVE ownership (the strongest live writer owns
//! the instance, ties go to the lowest GUID, and the owner loses it when it misses the requested deadline)
//! and DESTINATION_ORDER BY_SOURCE_TIMESTAMP (a change older than the newest accepted one is dropped).

use std::time::SystemTime;

use foldhash::HashMap;

use crate::rtps::Guid;

/// Whether `writer` (of `strength`) may change an instance owned by `owner`, whose writers are `writers`.
/// `owner_stale`: the owner missed the requested deadline of the instance, so anyone may take over.
pub(super) fn owner_accepts(
    owner: Option<(Guid, i32)>,
    writers: &HashMap<Guid, i32>,
    writer: Guid,
    strength: i32,
    owner_stale: bool,
) -> bool {
    match owner {
        None => true,
        Some((g, _)) if g == writer => true,
        Some((g, s)) => {
            owner_stale
                || !writers.contains_key(&g)
                || strength > s
                || (strength == s && writer < g)
        }
    }
}

/// Whether a change stamped `ts` keeps the instance's source order, given the newest accepted stamp.
/// Equal stamps are accepted (two writes in the same clock tick are both kept).
pub(super) fn in_source_order(newest: Option<SystemTime>, ts: SystemTime) -> bool {
    newest.is_none_or(|n| ts >= n)
}

#[cfg(test)]
mod tests {
    use super::*;
    use foldhash::HashMapExt;
    use std::time::Duration;

    fn g(b: u8) -> Guid {
        Guid::from_bytes([b; 16])
    }

    #[test]
    fn ownership_rules() {
        let mut w = HashMap::new();
        w.insert(g(5), 10);
        let owner = Some((g(5), 10));
        assert!(!owner_accepts(owner, &w, g(1), 5, false));
        assert!(owner_accepts(owner, &w, g(1), 5, true));
        assert!(owner_accepts(owner, &w, g(1), 10, false));
        assert!(!owner_accepts(owner, &w, g(9), 10, false));
        assert!(owner_accepts(owner, &w, g(9), 11, false));
        w.clear();
        assert!(owner_accepts(owner, &w, g(9), 1, false));
    }

    #[test]
    fn source_order() {
        let t = SystemTime::UNIX_EPOCH + Duration::from_secs(100);
        assert!(in_source_order(None, t));
        assert!(in_source_order(Some(t), t));
        assert!(!in_source_order(Some(t), t - Duration::from_millis(1)));
    }
}
