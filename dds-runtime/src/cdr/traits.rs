//! The traits generated code implements: [`CdrType`] (any IDL type) and [`DdsType`] (a named constructed type).

use super::error::{DecodeError, EncodeError};
use super::header::{Extensibility, XcdrVersion};
use super::reader::CdrReader;
use super::writer::CdrWriter;

/// The shape of a type as the encoder's layout rules see it (DHEADER on collections, EMHEADER length codes).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Layout {
    /// A primitive of this many bytes (bool, octet, integers, floats, char, wchar).
    Primitive(u8),
    /// An enum or bitmask whose XCDR2 form takes this many bytes; not primitive for DHEADER purposes.
    Enumerated(u8),
    /// A string: its u32 length gives its body size (EMHEADER LC 5).
    String,
    /// A sequence of primitives of this size (LC 5/6/7, or 4 for 2-byte elements).
    PrimitiveSequence(u8),
    /// A sequence or map of non-primitive elements: starts with a DHEADER in XCDR2 (LC 5).
    Delimited,
    /// An array (of any dimension) of primitives: no header (LC 4).
    PrimitiveArray,
    /// An array (of any dimension) of non-primitives: one DHEADER in XCDR2 (LC 5).
    DelimitedArray,
    /// Anything else (structs, unions, arrays of primitives, maps of primitives): LC 4 with NEXTINT.
    Other,
}

impl Layout {
    /// Whether elements of this layout are copied without a DHEADER in XCDR2 collections.
    pub const fn is_primitive(self) -> bool {
        matches!(self, Layout::Primitive(_))
    }

    /// Whether this is an array type (whose elements a enclosing array dimension writes without a header).
    pub const fn is_array(self) -> bool {
        matches!(self, Layout::PrimitiveArray | Layout::DelimitedArray)
    }

    /// The EMHEADER length code for a member of this layout (as Cyclone DDS chooses it).
    pub const fn length_code(self) -> u8 {
        match self {
            Layout::Primitive(n) | Layout::Enumerated(n) => match n {
                1 => 0,
                2 => 1,
                4 => 2,
                8 => 3,
                _ => 4,
            },
            Layout::String | Layout::Delimited | Layout::DelimitedArray => 5,
            Layout::PrimitiveSequence(n) => match n {
                1 => 5,
                4 => 6,
                8 => 7,
                _ => 4,
            },
            Layout::PrimitiveArray | Layout::Other => 4,
        }
    }
}

/// A type that has an XCDR1/XCDR2 encoding. Implemented for the IDL primitive and template types and by
/// `#[derive(DdsType)]`. The methods are plumbing for generated code and the collection impls.
pub trait CdrType: Sized {
    /// How the layout rules see this type.
    const LAYOUT: Layout;
    /// Lower bound of the encoded size (used to reject hostile lengths before allocating). At least 1.
    const MIN_SIZE: usize = 1;
    /// Whether a @mutable aggregate lies on the key path (Cyclone then never zero-pads an XCDR1 key hash).
    const KEY_HAS_MUTABLE: bool = false;
    /// The member id after this struct's last one (a derived struct's ids continue from its base).
    #[doc(hidden)]
    const NEXT_MEMBER_ID: u32 = 0;
    /// Whether XCDR1 can carry this type as Cyclone does by default: final, no optional members, all the way down.
    const XCDR1_PLAIN: bool = true;

    /// Appends the encoding of `self`.
    fn encode(&self, w: &mut CdrWriter<'_>) -> Result<(), EncodeError>;

    /// Decodes one value.
    fn decode(r: &mut CdrReader<'_>) -> Result<Self, DecodeError>;

    /// The value used for a member that an appendable/mutable sample lacks and for non-key members of a
    /// key-only sample. Unlike `Default`, works for arrays of any length.
    fn default_value() -> Self;

    /// Encodes with an IDL bound (`#[dds(bound = N)]`); only strings, sequences and maps check it.
    #[inline]
    fn encode_bounded(&self, w: &mut CdrWriter<'_>, bound: usize) -> Result<(), EncodeError> {
        let _ = bound;
        self.encode(w)
    }

    /// Decodes with an IDL bound.
    #[inline]
    fn decode_bounded(r: &mut CdrReader<'_>, bound: usize) -> Result<Self, DecodeError> {
        let _ = bound;
        Self::decode(r)
    }

    /// Decodes one value (with an IDL bound) into `self`, reusing what `self` owns: strings and sequences keep
    /// their buffers, derived final/appendable structs decode member by member in place. The default
    /// replaces `self`. On error `self` holds some mix of old and new members (still a valid value).
    #[inline]
    fn decode_in_place(&mut self, r: &mut CdrReader<'_>, bound: usize) -> Result<(), DecodeError> {
        *self = Self::decode_bounded(r, bound)?;
        Ok(())
    }

    /// End offset of the largest key-hash stream of this type (key members only, plain, no DHEADER/EMHEADER)
    /// starting at `start`, or `None` when unbounded; decides between zero-padding and MD5 for the key hash.
    /// `bound` is the member's IDL bound, if any.
    fn key_max_end(start: usize, version: XcdrVersion, bound: Option<usize>) -> Option<usize>;

    /// Decodes an array of `N` values; primitives override this with a bulk copy.
    fn decode_array<const N: usize>(r: &mut CdrReader<'_>) -> Result<[Self; N], DecodeError> {
        let mut err = None;
        let arr = std::array::from_fn(|_| {
            if err.is_none() {
                match Self::decode(r) {
                    Ok(v) => return v,
                    Err(e) => err = Some(e),
                }
            }
            Self::default_value()
        });
        match err {
            None => Ok(arr),
            Some(e) => Err(e),
        }
    }

    /// Encodes an array's elements without its own DHEADER (an inner dimension of a multi-dimensional array).
    #[doc(hidden)]
    #[inline]
    fn encode_flat(&self, w: &mut CdrWriter<'_>) -> Result<(), EncodeError> {
        self.encode(w)
    }

    /// Decodes what [`encode_flat`](Self::encode_flat) wrote.
    #[doc(hidden)]
    #[inline]
    fn decode_flat(r: &mut CdrReader<'_>) -> Result<Self, DecodeError> {
        Self::decode(r)
    }

    /// Encodes a slice of values (arrays and sequences); primitives override this with a bulk copy.
    #[inline]
    fn encode_slice(items: &[Self], w: &mut CdrWriter<'_>) -> Result<(), EncodeError> {
        for item in items {
            item.encode(w)?;
        }
        Ok(())
    }

    /// Decodes `n` values into `out` (already reserved); primitives override this with a bulk copy.
    #[inline]
    fn decode_into(
        out: &mut Vec<Self>,
        n: usize,
        r: &mut CdrReader<'_>,
    ) -> Result<(), DecodeError> {
        for _ in 0..n {
            out.push(Self::decode(r)?);
        }
        Ok(())
    }
}

/// Type metadata for the XTypes TypeObject generator (filled in later; the hook is here so the derive can grow
/// into it without changing the trait).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct TypeDescriptor {
    /// Scoped IDL name.
    pub type_name: &'static str,
    /// Extensibility.
    pub extensibility: Extensibility,
    /// Names of the members in declaration order (enumerators for enums, cases for unions).
    pub members: &'static [MemberDescriptor],
}

/// One member of a [`TypeDescriptor`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct MemberDescriptor {
    /// IDL member name.
    pub name: &'static str,
    /// Member id (enumerator value for enums).
    pub id: u32,
    /// `@key`.
    pub key: bool,
    /// `@optional`.
    pub optional: bool,
    /// `@must_understand`.
    pub must_understand: bool,
}

/// A named IDL type that can be a topic type: what `#[derive(DdsType)]` implements.
pub trait DdsType: CdrType + crate::filter::FilterFields + Send + Sync + 'static {
    /// Scoped IDL name, `"Module::Type"`.
    const TYPE_NAME: &'static str;
    /// XTypes extensibility.
    const EXTENSIBILITY: Extensibility;
    /// Whether the type has key members.
    const IS_KEYED: bool;
    /// Cyclone's default: XCDR1 for @final types without optional members (anywhere), else XCDR2.
    const DEFAULT_VERSION: XcdrVersion = if Self::XCDR1_PLAIN {
        XcdrVersion::Xcdr1
    } else {
        XcdrVersion::Xcdr2
    };

    /// Metadata for TypeObject generation.
    fn type_descriptor() -> TypeDescriptor;

    /// The XCDR2 `TypeInformation` SEDP announces for this type (`PID_TYPE_INFORMATION`), built once; `None`
    /// when the type has none. The derive implements it from `xtypes::XTypesType::type_support`.
    fn type_information() -> Option<&'static [u8]> {
        None
    }

    /// The XCDR2 `TypeMapping` of this type (every type object its `TypeInformation` names), built once;
    /// what the TypeLookup service answers with. The derive implements it next to `type_information`.
    fn type_mapping() -> Option<&'static [u8]> {
        None
    }

    /// A sample that reads a received payload where it is, without decoding it; `shared` is the
    /// payload with the owner of its bytes (`rtps::Payload`). `None` (the default): the payload is
    /// decoded. Implemented by `dcps::InPlace` (plain-data samples read in shared memory).
    #[doc(hidden)]
    fn decode_shared(shared: &dyn std::any::Any) -> Option<Self> {
        let _ = shared;
        None
    }

    /// Whether this value holds a received buffer it reads in place (see [`Self::decode_shared`]), which
    /// must go back to its sender rather than be kept for decoding into (`DataReader::recycle`).
    #[doc(hidden)]
    fn holds_received_buffer(&self) -> bool {
        false
    }
}
