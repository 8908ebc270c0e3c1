//! Dynamic types and data on peer input, with a differential check against the derived decoder; see
//! `src/dynamic.rs`.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| dds_fuzz::dynamic_one(data));
