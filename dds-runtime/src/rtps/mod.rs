//! The sans-I/O RTPS 2.5 protocol core (quinn-proto style).
//!
//! Inputs are datagrams and the current time; outputs are datagrams to send ([`Transmit`]), the next timeout and
//! [`Event`]s. Nothing here opens a socket, starts a thread or reads a clock, so the whole protocol is
//! deterministic and testable in simulation. See `docs/rtps-core.md`.

pub mod discovery;
mod due;
mod liveliness;
pub mod messages;
mod outbox;
mod participant;
pub(crate) mod pool;
mod proxy_map;
pub(crate) mod reader;
pub mod shm;
mod transmit;
pub mod types;
pub(crate) mod writer;

mod api;

pub use api::*;
pub use participant::Participant;
#[cfg(feature = "net")]
pub(crate) use participant::KEPT_QUEUE_ROOM;
pub use transmit::{SharedPart, Transmit};
pub use types::*;
pub use writer::WriterGroup;
