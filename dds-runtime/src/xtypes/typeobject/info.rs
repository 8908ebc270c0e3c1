//! `TypeInformation` (the `PID_TYPE_INFORMATION` payload of SEDP) and `TypeMapping` (identifier → object pairs).

use crate::cdr::{members, CdrReader, CdrWriter, DecodeError, EncodeError, Extensibility};

use super::codec::{appendable, seq, XtypesCodec};
use super::decode;
use super::identifier::TypeIdentifier;
use super::object::TypeObject;

/// Member id of `TypeInformation::minimal`.
const ID_MINIMAL: u32 = 0x1001;
/// Member id of `TypeInformation::complete`.
const ID_COMPLETE: u32 = 0x1002;

/// `TypeIdentifierWithSize`: an identifier and the size of its serialized type object.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub struct TypeIdentifierWithSize {
    /// The identifier.
    pub type_id: TypeIdentifier,
    /// Bytes of the XCDR2 type object it hashes.
    pub typeobject_serialized_size: u32,
}

/// `TypeIdentifierWithDependencies`: a type and the types it depends on.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct TypeIdentifierWithDependencies {
    /// The type itself.
    pub typeid_with_size: TypeIdentifierWithSize,
    /// Number of dependent types (-1: unknown); may exceed the list's length.
    pub dependent_typeid_count: i32,
    /// Dependent types.
    pub dependent_typeids: Vec<TypeIdentifierWithSize>,
}

impl Default for TypeIdentifierWithSize {
    fn default() -> Self {
        TypeIdentifierWithSize {
            type_id: TypeIdentifier::None,
            typeobject_serialized_size: 0,
        }
    }
}

/// `TypeInformation` (`@mutable`, member ids 0x1001 and 0x1002).
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct TypeInformation {
    /// The minimal identifier and dependencies.
    pub minimal: TypeIdentifierWithDependencies,
    /// The complete identifier and dependencies.
    pub complete: TypeIdentifierWithDependencies,
}

/// `TypeIdentifierTypeObjectPair`.
#[derive(Debug, Clone, PartialEq)]
pub struct TypeIdentifierTypeObjectPair {
    /// The identifier (a hash or a strongly connected component id).
    pub type_identifier: TypeIdentifier,
    /// Its object.
    pub type_object: TypeObject,
}

/// `TypeIdentifierPair` (complete → minimal).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct TypeIdentifierPair {
    /// The complete identifier.
    pub type_identifier1: TypeIdentifier,
    /// The minimal identifier.
    pub type_identifier2: TypeIdentifier,
}

/// `TypeMapping` (Cyclone's): the objects of a type and its dependencies.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct TypeMapping {
    /// Minimal identifiers and objects.
    pub identifier_object_pair_minimal: Vec<TypeIdentifierTypeObjectPair>,
    /// Complete identifiers and objects.
    pub identifier_object_pair_complete: Vec<TypeIdentifierTypeObjectPair>,
    /// Complete → minimal identifiers.
    pub identifier_complete_minimal: Vec<TypeIdentifierPair>,
}

impl XtypesCodec for TypeIdentifierWithSize {
    fn encode(&self, w: &mut CdrWriter<'_>) -> Result<(), EncodeError> {
        appendable(w, |w| {
            self.type_id.encode(w)?;
            w.write_u32(self.typeobject_serialized_size);
            Ok(())
        })
    }

    fn decode(r: &mut CdrReader<'_>) -> Result<Self, DecodeError> {
        decode::appendable(r, "TypeIdentifierWithSize", |r| {
            Ok(TypeIdentifierWithSize {
                type_id: TypeIdentifier::decode(r)?,
                typeobject_serialized_size: r.read_u32("typeobject_serialized_size")?,
            })
        })
    }
}

impl XtypesCodec for TypeIdentifierWithDependencies {
    fn encode(&self, w: &mut CdrWriter<'_>) -> Result<(), EncodeError> {
        appendable(w, |w| {
            self.typeid_with_size.encode(w)?;
            w.write_u32(self.dependent_typeid_count as u32);
            seq(w, &self.dependent_typeids, |w, t| t.encode(w))
        })
    }

    fn decode(r: &mut CdrReader<'_>) -> Result<Self, DecodeError> {
        decode::appendable(r, "TypeIdentifierWithDependencies", |r| {
            Ok(TypeIdentifierWithDependencies {
                typeid_with_size: TypeIdentifierWithSize::decode(r)?,
                dependent_typeid_count: r.read_u32("dependent_typeid_count")? as i32,
                dependent_typeids: decode::seq(
                    r,
                    "dependent_typeids",
                    5,
                    TypeIdentifierWithSize::decode,
                )?,
            })
        })
    }
}

impl XtypesCodec for TypeInformation {
    fn encode(&self, w: &mut CdrWriter<'_>) -> Result<(), EncodeError> {
        appendable(w, |w| {
            for (id, m) in [(ID_MINIMAL, &self.minimal), (ID_COMPLETE, &self.complete)] {
                let slot = w
                    .write_emheader(id, false, 4)?
                    .ok_or(EncodeError::TooLarge {
                        what: "EMHEADER",
                        len: 0,
                    })?;
                m.encode(w)?;
                w.end_length(slot)?;
            }
            Ok(())
        })
    }

    fn decode(r: &mut CdrReader<'_>) -> Result<Self, DecodeError> {
        // A mutable type: DHEADER, then EMHEADER-framed members, read by the same code as generated types.
        let mut st = members::begin_decode(r, Extensibility::Mutable)?;
        let mut ti = TypeInformation::default();
        while let Some(m) = st.next_member(r)? {
            match m.id {
                ID_MINIMAL => ti.minimal = TypeIdentifierWithDependencies::decode(r)?,
                ID_COMPLETE => ti.complete = TypeIdentifierWithDependencies::decode(r)?,
                _ => {
                    members::skip_member(r, m)?;
                    continue;
                }
            }
            members::end_member(r, m);
        }
        st.end(r);
        Ok(ti)
    }
}

impl XtypesCodec for TypeIdentifierTypeObjectPair {
    fn encode(&self, w: &mut CdrWriter<'_>) -> Result<(), EncodeError> {
        self.type_identifier.encode(w)?;
        self.type_object.encode(w)
    }

    fn decode(r: &mut CdrReader<'_>) -> Result<Self, DecodeError> {
        Ok(TypeIdentifierTypeObjectPair {
            type_identifier: TypeIdentifier::decode(r)?,
            type_object: TypeObject::decode(r)?,
        })
    }
}

impl XtypesCodec for TypeIdentifierPair {
    fn encode(&self, w: &mut CdrWriter<'_>) -> Result<(), EncodeError> {
        self.type_identifier1.encode(w)?;
        self.type_identifier2.encode(w)
    }

    fn decode(r: &mut CdrReader<'_>) -> Result<Self, DecodeError> {
        Ok(TypeIdentifierPair {
            type_identifier1: TypeIdentifier::decode(r)?,
            type_identifier2: TypeIdentifier::decode(r)?,
        })
    }
}

impl XtypesCodec for TypeMapping {
    fn encode(&self, w: &mut CdrWriter<'_>) -> Result<(), EncodeError> {
        seq(w, &self.identifier_object_pair_minimal, |w, p| p.encode(w))?;
        seq(w, &self.identifier_object_pair_complete, |w, p| p.encode(w))?;
        seq(w, &self.identifier_complete_minimal, |w, p| p.encode(w))
    }

    fn decode(r: &mut CdrReader<'_>) -> Result<Self, DecodeError> {
        Ok(TypeMapping {
            identifier_object_pair_minimal: decode::seq(
                r,
                "minimal pairs",
                6,
                TypeIdentifierTypeObjectPair::decode,
            )?,
            identifier_object_pair_complete: decode::seq(
                r,
                "complete pairs",
                6,
                TypeIdentifierTypeObjectPair::decode,
            )?,
            identifier_complete_minimal: decode::seq(
                r,
                "identifier pairs",
                2,
                TypeIdentifierPair::decode,
            )?,
        })
    }
}
