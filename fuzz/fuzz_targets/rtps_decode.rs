//! Arbitrary datagrams through the RTPS message decoder (`dds_runtime::rtps::messages`), and arbitrary
//! payloads through the SPDP/SEDP parameter-list decoders. Every submessage that decodes must re-encode (in its
//! own byte order) to something that decodes to the same submessage.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| dds_fuzz::rtps_one(data));
