//! The durability service's key hash of a peer's change, from type objects and a payload
//! (`dds_runtime::dcps::durability::peer_key_hash`); see `src/durability.rs`.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| dds_fuzz::durability_key_one(data));
