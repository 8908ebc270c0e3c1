//! The durability stand-in's USER_DATA marker, for the DCPS layer: the code is the core's
//! (`rtps/stand_in.rs`), which also uses it to keep a stand-in from repeating to a reader what the original
//! writer serves it.

pub(crate) use crate::rtps::stand_in::{stand_in_for, user_data};
