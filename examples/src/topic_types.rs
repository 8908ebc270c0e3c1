//! The topic types the example programs exchange with other DDS implementations: the idlc-generated
//! types of `idl/shapes.idl` and `idl/ddsperf_types.idl` (type names without a module, as the OMG suite
//! and Cyclone's ddsperf register them), under one path for the programs.

pub use crate::ddsperf_types::{
    Keyed256, Keyed32, KeyedSeq, OneULong, Struct16, Struct256, Struct32k, Struct4k,
};
pub use crate::shapes::ShapeType;
