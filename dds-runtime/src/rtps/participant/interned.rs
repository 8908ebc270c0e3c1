//! What the participant shares among the endpoints it knows: the QoS and type information that nearly every
//! endpoint announces alike are kept once per distinct value (see `docs/performance.md`, "Footprint").

use crate::qos::{Interner, ReaderQos, WriterQos};
use crate::rtps::discovery::EndpointData;
use crate::xtypes::TypeInformation;

/// The participant's interners, one per kind of shared value.
#[derive(Debug, Default)]
pub(super) struct Interned {
    writer_qos: Interner<WriterQos>,
    reader_qos: Interner<ReaderQos>,
    types: Interner<TypeInformation>,
}

/// An announced QoS kind that has its own interner.
pub(super) trait SharedQos: PartialEq + Sized {
    /// The interner of this kind.
    fn interner(i: &mut Interned) -> &mut Interner<Self>;
}

impl SharedQos for WriterQos {
    fn interner(i: &mut Interned) -> &mut Interner<Self> {
        &mut i.writer_qos
    }
}

impl SharedQos for ReaderQos {
    fn interner(i: &mut Interned) -> &mut Interner<Self> {
        &mut i.reader_qos
    }
}

impl Interned {
    /// Replaces `d`'s QoS and type information by the shared copies of equal values.
    pub(super) fn share<Q: SharedQos>(&mut self, d: &mut EndpointData<Q>) {
        d.qos = Q::interner(self).intern(d.qos.clone());
        if let Some(t) = d.type_information.take() {
            d.type_information = Some(self.types.intern(t));
        }
    }
}
