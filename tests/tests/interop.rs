//! Interoperability tests: our release binaries (`shapes`, `shape_main`, `dds-perf`) against Cyclone DDS (python
//! `cyclonedds` 11), Fast DDS 2.9 (C++ peer in tests/peers/fastdds) and Cyclone's `ddsperf` 0.10.2, plus a
//! tshark dissection check of our traffic.
//!
//! Run (after `cargo build --release --bins`): `scripts/isolated cargo nextest run --profile interop`.
//! Each test uses its own domain ids; every child process is killed when its test ends. A missing peer
//! fails the test when `CI=true` and skips it otherwise.

mod interop {
    pub mod builtin;
    pub mod dds_cli;
    pub mod ddsperf;
    pub mod deadline;
    pub mod durability;
    pub mod evolution;
    pub mod harness;
    pub mod liveliness;
    pub mod main_job;
    pub mod presentation;
    pub mod shapes;
    pub mod tshark;
    pub mod tui;
    pub mod typelookup;
    pub mod xtypes;
    pub mod xtypes_pairs;
}
