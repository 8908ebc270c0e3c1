//! XTypes type representation. For now only an opaque holder for received/announced TypeInformation.

/// The XCDR2-serialized `TypeInformation` (PID_TYPE_INFORMATION, 0x0075), kept verbatim.
/// Cyclone 11 sends it in SEDP; it is stored and re-announced but not interpreted (matching uses type names).
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct TypeInformation(pub Vec<u8>);

impl TypeInformation {
    /// The serialized bytes, as received or to be announced.
    pub fn as_bytes(&self) -> &[u8] {
        &self.0
    }
}
