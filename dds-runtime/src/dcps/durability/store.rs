//! The persistent store of PERSISTENT data: an embedded redb database, one file.
//!
//! Two tables: `writers` maps an original writer's GUID to its SEDP announcement (the parameter-list bytes
//! discovery sends, so that the service can announce its stand-in again after a restart), and `changes`
//! maps (writer GUID, sequence number) to one kept change. Every batch of changes is one write transaction,
//! committed with redb's default durability: the commit returns after the data reached the disk (fsync), so
//! a change the service has stored survives a `kill -9` of the service and a crash of the machine.

use std::path::Path;

use redb::{Database, ReadableTable, TableDefinition};

use super::history::StoredChange;
use crate::rtps::discovery::WriterData;
use crate::rtps::{ChangeKind, Guid, Payload, Time};

const WRITERS: TableDefinition<'_, &[u8], &[u8]> = TableDefinition::new("writers");
const CHANGES: TableDefinition<'_, (&[u8], i64), &[u8]> = TableDefinition::new("changes");

/// Why the persistent store failed.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum StoreError {
    /// The database refused an operation (I/O, locking, corruption it detected).
    #[error("persistent store: {0}")]
    Db(#[source] Box<redb::Error>),
    /// A stored record does not decode.
    #[error("persistent store: corrupt record ({0})")]
    Corrupt(&'static str),
}

fn db_err(e: impl Into<redb::Error>) -> StoreError {
    StoreError::Db(Box::new(e.into()))
}

/// One original writer as stored: its announcement and its kept changes, oldest first.
pub(crate) struct StoredWriter {
    pub(crate) data: WriterData,
    pub(crate) changes: Vec<StoredChange>,
}

/// What one transaction changes.
#[derive(Default)]
pub(crate) struct Batch {
    pub(crate) put: Vec<(Guid, StoredChange)>,
    pub(crate) evicted: Vec<(Guid, i64)>,
}

impl Batch {
    pub(crate) fn is_empty(&self) -> bool {
        self.put.is_empty() && self.evicted.is_empty()
    }
}

/// The database file.
pub(crate) struct PersistentStore {
    db: Database,
}

const HAS_TIMESTAMP: u8 = 1;

fn encode(c: &StoredChange) -> Vec<u8> {
    let mut v = Vec::with_capacity(26 + c.payload.len());
    v.push(c.kind.status_info());
    v.push(if c.timestamp.is_some() {
        HAS_TIMESTAMP
    } else {
        0
    });
    v.extend_from_slice(&c.key_hash);
    let t = c.timestamp.unwrap_or_default();
    v.extend_from_slice(&t.seconds.to_le_bytes());
    v.extend_from_slice(&t.fraction.to_le_bytes());
    v.extend_from_slice(&c.payload);
    v
}

fn decode(seq: i64, v: &[u8]) -> Result<StoredChange, StoreError> {
    const HEAD: usize = 2 + 16 + 8;
    if v.len() < HEAD {
        return Err(StoreError::Corrupt("short change record"));
    }
    let word = |at: usize| [v[at], v[at + 1], v[at + 2], v[at + 3]];
    let mut key_hash = [0u8; 16];
    key_hash.copy_from_slice(&v[2..18]);
    Ok(StoredChange {
        seq,
        kind: ChangeKind::from_status_info(v[0]),
        key_hash,
        timestamp: (v[1] & HAS_TIMESTAMP != 0).then(|| Time {
            seconds: i32::from_le_bytes(word(18)),
            fraction: u32::from_le_bytes(word(22)),
        }),
        payload: Payload::copy_from_slice(&v[HEAD..]),
    })
}

impl PersistentStore {
    /// Opens (or creates) the database at `path`. redb allows one process per file: a second service on the
    /// same file gets an error.
    pub(crate) fn open(path: &Path) -> Result<Self, StoreError> {
        let db = Database::create(path).map_err(db_err)?;
        let tx = db.begin_write().map_err(db_err)?;
        tx.open_table(WRITERS).map_err(db_err)?;
        tx.open_table(CHANGES).map_err(db_err)?;
        tx.commit().map_err(db_err)?;
        Ok(PersistentStore { db })
    }

    /// Every stored writer with its changes.
    pub(crate) fn load(&self) -> Result<Vec<StoredWriter>, StoreError> {
        let tx = self.db.begin_read().map_err(db_err)?;
        let writers = tx.open_table(WRITERS).map_err(db_err)?;
        let changes = tx.open_table(CHANGES).map_err(db_err)?;
        let mut out = Vec::new();
        for row in writers.iter().map_err(db_err)? {
            let (k, v) = row.map_err(db_err)?;
            let data = WriterData::decode(v.value())
                .map_err(|_| StoreError::Corrupt("writer announcement"))?;
            let key = k.value().to_vec();
            let mut list = Vec::new();
            for c in changes
                .range((key.as_slice(), i64::MIN)..=(key.as_slice(), i64::MAX))
                .map_err(db_err)?
            {
                let (ck, cv) = c.map_err(db_err)?;
                list.push(decode(ck.value().1, cv.value())?);
            }
            out.push(StoredWriter {
                data,
                changes: list,
            });
        }
        Ok(out)
    }

    /// Records an original writer's announcement (idempotent).
    pub(crate) fn save_writer(&self, w: &WriterData) -> Result<(), StoreError> {
        let tx = self.db.begin_write().map_err(db_err)?;
        {
            let mut t = tx.open_table(WRITERS).map_err(db_err)?;
            t.insert(w.guid.to_bytes().as_slice(), w.encode().as_slice())
                .map_err(db_err)?;
        }
        tx.commit().map_err(db_err)
    }

    /// Stores and evicts changes in one transaction; returns once it is on disk.
    pub(crate) fn apply(&self, batch: &Batch) -> Result<(), StoreError> {
        let tx = self.db.begin_write().map_err(db_err)?;
        {
            let mut t = tx.open_table(CHANGES).map_err(db_err)?;
            for (g, c) in &batch.put {
                t.insert((g.to_bytes().as_slice(), c.seq), encode(c).as_slice())
                    .map_err(db_err)?;
            }
            for (g, seq) in &batch.evicted {
                t.remove((g.to_bytes().as_slice(), *seq)).map_err(db_err)?;
            }
        }
        tx.commit().map_err(db_err)
    }

    /// Forgets a writer and its changes.
    pub(crate) fn remove_writer(&self, g: &Guid) -> Result<(), StoreError> {
        let key = g.to_bytes();
        let tx = self.db.begin_write().map_err(db_err)?;
        {
            let mut w = tx.open_table(WRITERS).map_err(db_err)?;
            w.remove(key.as_slice()).map_err(db_err)?;
            let mut c = tx.open_table(CHANGES).map_err(db_err)?;
            c.retain_in(
                (key.as_slice(), i64::MIN)..=(key.as_slice(), i64::MAX),
                |_, _| false,
            )
            .map_err(db_err)?;
        }
        tx.commit().map_err(db_err)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn records_round_trip() {
        let c = StoredChange {
            seq: 9,
            kind: ChangeKind::Dispose,
            key_hash: [3; 16],
            timestamp: Some(Time {
                seconds: 5,
                fraction: 7,
            }),
            payload: Payload::from(vec![1, 2, 3]),
        };
        assert_eq!(decode(9, &encode(&c)).unwrap(), c);
        assert!(matches!(decode(1, &[0; 5]), Err(StoreError::Corrupt(_))));
    }
}
