//! Native DDS for Rust.
//!
//! The layers, bottom up:
//! - [`cdr`]: XCDR1/XCDR2 serialization. Knows nothing of RTPS.
//! - [`xtypes`]: type identifiers and type objects.
//! - [`filter`]: the SQL subset of content filters and queries, and the member access the derive gives.
//! - `qos`: the QoS policies, shared by discovery and the DCPS API (feature `rtps`).
//! - `rtps`: the sans-I/O protocol core: messages, discovery, writers and readers (feature `rtps`).
//! - `transport`: sockets and receive threads that drive the core (feature `net`).
//! - `config`: configuration from the environment and builders (feature `net`).
//! - `dcps`: the typed DCPS API, the only layer that joins `cdr` and `rtps` (feature `net`).
//!
//! # Features
//!
//! | feature | gives | needs |
//! |---|---|---|
//! | (none) | `cdr`, `xtypes` and `#[derive(DdsType)]`: encoding only | no sockets, no threads |
//! | `rtps` | the sans-I/O core (`rtps`) and `qos` | `tracing` |
//! | `net` (default) | `rtps` plus `transport`, `config`, `dcps` and the `prelude` | sockets (`socket2`, `libc` on Unix), threads |
//!
//! For encoding alone: `dds-runtime = { version = "…", default-features = false }`.
//!
//! # Example
//!
//! Derive a topic type and round-trip a sample through XCDR2 (this needs no feature):
//!
//! ```
//! use dds_runtime::cdr::{self, ByteOrder, DdsType as _, XcdrVersion};
//! use dds_runtime::DdsType;
//!
//! #[derive(DdsType, Debug, Clone, PartialEq)]
//! #[dds(name = "Demo::Shape", extensibility = "appendable")]
//! struct Shape {
//!     #[dds(key)]
//!     color: String,
//!     x: i32,
//!     y: i32,
//!     size: i32,
//! }
//!
//! let sample = Shape { color: "BLUE".into(), x: 10, y: 20, size: 30 };
//! let mut bytes = Vec::new();
//! cdr::serialize(&sample, XcdrVersion::Xcdr2, ByteOrder::LittleEndian, &mut bytes)?;
//! // Encapsulation header D_CDR2_LE (appendable, XCDR2, little-endian), then a DHEADER and the members.
//! assert_eq!(bytes[..4], [0x00, 0x09, 0x00, 0x00]);
//! assert_eq!(cdr::deserialize::<Shape>(&bytes)?, sample);
//! assert_eq!(Shape::TYPE_NAME, "Demo::Shape");
//!
//! // The instance is identified by its key members only.
//! let moved = Shape { x: 99, ..sample.clone() };
//! let key = |s: &Shape| cdr::key_hash(s, XcdrVersion::Xcdr2);
//! assert_eq!(key(&moved)?, key(&sample)?);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

// Lets `#[derive(DdsType)]` name `::dds_runtime` from inside this crate too.
extern crate self as dds_runtime;

pub mod cdr;
#[cfg(feature = "net")]
pub mod config;
#[cfg(feature = "net")]
pub mod dcps;
pub mod filter;
#[cfg(feature = "net")]
pub mod prelude;
#[cfg(feature = "rtps")]
pub mod qos;
#[cfg(feature = "rtps")]
pub mod rtps;
#[cfg(feature = "net")]
pub mod transport;
pub mod xtypes;

pub use dds_macros::DdsType;

#[doc(hidden)]
pub mod __private {
    pub use bitflags;
    pub use md5;
}
