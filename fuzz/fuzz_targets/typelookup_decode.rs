//! TypeLookup requests and replies through the decoder, the server and the client
//! (`dds_runtime::xtypes::typelookup`); see `src/typelookup.rs`.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| dds_fuzz::typelookup_one(data));
