//! Native DDS for Rust.
//!
//! The layers, bottom up:
//! - [`cdr`]: XCDR1/XCDR2 serialization. Knows nothing of RTPS.
//! - [`xtypes`]: type identifiers and type objects.
//! - [`qos`]: the QoS policies, shared by discovery and the DCPS API.
//! - [`rtps`]: the sans-I/O protocol core: messages, discovery, writers and readers.
//! - [`transport`]: sockets and receive threads that drive the core.
//! - [`config`]: configuration from the environment and builders.
//! - [`dcps`]: the typed DCPS API, the only layer that joins `cdr` and `rtps`.

// Lets `#[derive(DdsType)]` name `::dds_runtime` from inside this crate too.
extern crate self as dds_runtime;

pub mod cdr;
pub mod config;
pub mod dcps;
pub mod prelude;
pub mod qos;
pub mod rtps;
pub mod transport;
pub mod xtypes;

pub use dds_macros::DdsType;

#[doc(hidden)]
pub mod __private {
    pub use bitflags;
    pub use md5;
}
