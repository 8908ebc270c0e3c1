//! Content filters and queries in the DCPS API: the language lives in [`crate::filter`] (it needs no
//! feature, since `#[derive(DdsType)]` refers to it); this module re-exports it.

pub use crate::filter::*;
