//! Content-filter and query expressions as remote readers announce them; see `src/filter.rs`.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| dds_fuzz::filter_one(data));
