//! Listener traits. Listeners run on the thread that processed the triggering datagram or timeout (a
//! receive thread or the timer thread), after every internal lock has been released, so they may call
//! back into the entities (read, take, write). Keep them short: they delay the processing of later traffic.
//!
//! The traits are defined next to the entity they serve and re-exported here.

pub use super::publisher::DataWriterListener;
pub use super::subscriber::DataReaderListener;
