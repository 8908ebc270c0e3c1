//! The durability stand-in's USER_DATA marker, for the DCPS layer: the code is the core's
//! (`rtps/writer/stand_in.rs`), which also uses it to hold, while the original writer lives, the readers of
//! other vendors that the original serves.

pub(crate) use crate::rtps::writer::{stand_in_for, stand_in_user_data as user_data};
