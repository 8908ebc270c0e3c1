//! Arbitrary bytes through the shared-memory frame header decoder (`dds_runtime::rtps::shm::decode_header`):
//! no panic, the payload range lies inside the frame, and a decoded header re-encodes to the same header.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| dds_fuzz::shm_one(data));
