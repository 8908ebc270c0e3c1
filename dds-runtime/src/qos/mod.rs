//! QoS policies as plain values, their builders and requested/offered compatibility. Their wire
//! (parameter-list) form lives with discovery, in `rtps::discovery`.

mod changes;
mod compat;
mod entities;
mod intern;
mod policies;

pub use changes::ChangeableQos;
pub use compat::{check_compatible, fnmatch, partitions_match, ReaderQos, WriterQos};
pub use entities::*;
pub(crate) use intern::Interner;
pub use policies::*;
