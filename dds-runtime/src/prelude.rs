//! `use dds_runtime::prelude::*;` brings in the DCPS API, the QoS policies and the derive.

pub use crate::cdr::{DdsType, XcdrVersion};
pub use crate::config::{Config, ParticipantIndex};
pub use crate::dcps::*;
pub use crate::qos::*;
pub use crate::DdsType;
