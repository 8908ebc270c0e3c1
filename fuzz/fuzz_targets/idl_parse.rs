//! Arbitrary text through the idlc front end (preprocess, parse, resolve, validate) and, when it is accepted,
//! the Rust and JSON back ends; diagnostics are rendered to check their spans.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| dds_fuzz::idl_one(data));
