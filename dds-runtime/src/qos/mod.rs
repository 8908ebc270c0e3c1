//! QoS policies, their builders, requested/offered compatibility and their wire (parameter-list) form.

mod compat;
mod entities;
mod policies;
pub mod wire;

pub use compat::{check_compatible, fnmatch, partitions_match, ReaderQos, WriterQos};
pub use entities::*;
pub use policies::*;
