//! Shared code of the fuzz targets (`fuzz_targets/`) and the seed generator (`examples/gen_seeds.rs`).

pub mod cdr;
mod durability;
mod dynamic;
mod filter;
mod idl;
mod participant;
mod rtps;
mod shm;
mod typelookup;

pub use cdr::cdr_one;
pub use durability::{durability_key_hashes, durability_key_input, durability_key_one};
pub use dynamic::dynamic_one;
pub use filter::filter_one;
pub use idl::idl_one;
pub use participant::participant_one;
pub use rtps::rtps_one;
pub use shm::shm_one;
pub use typelookup::typelookup_one;
