//! Arbitrary datagrams into a live sans-I/O `Participant` that has discovered a peer (`dds_fuzz::participant_one`).
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| dds_fuzz::participant_one(data));
