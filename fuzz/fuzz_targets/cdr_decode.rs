//! Arbitrary bytes through `dds_runtime::cdr::deserialize` for several derived types; whatever decodes must
//! re-encode and decode again to an equal value (see `dds_fuzz::round_trip`).
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| dds_fuzz::cdr_one(data));
