//! Whether a reader holds everything its matched writers announced: the core of
//! `DataReader::wait_for_historical_data`.

use super::Reader;

impl Reader {
    /// Every reliable writer proxy was heard from and everything up to its last HEARTBEAT was delivered or
    /// skipped. Best-effort proxies announce nothing to wait for and count as caught up.
    pub(crate) fn caught_up(&self) -> bool {
        self.proxies
            .values()
            .filter(|p| p.reliable)
            .all(|p| p.synced && p.next_expected > p.hb_last)
    }
}
