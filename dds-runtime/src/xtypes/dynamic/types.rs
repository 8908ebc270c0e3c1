//! [`DynamicType`]: a type described at run time (XTypes 1.3 §7.5.2), shared cheaply through an `Arc`.

use std::cell::RefCell;
use std::collections::HashSet;
use std::sync::{Arc, OnceLock};

use crate::cdr::Extensibility;

use super::error::DynamicError;

/// A type known at run time. Cloning shares the description; equality is structural (clones compare in O(1),
/// and each pair of shared sub-types is compared once per comparison, so separately built types that share
/// sub-types, however deeply, compare in time linear in their pairs of nodes).
#[derive(Clone)]
pub struct DynamicType(pub(super) Arc<TypeKind>);

/// Most recursive types (defined forward references) one process makes: each is a cycle of shared nodes that
/// lives as long as the process.
pub const MAX_RECURSIVE_TYPES: usize = 4096;

/// The recursive types defined so far (see [`MAX_RECURSIVE_TYPES`]).
static DEFINED: std::sync::Mutex<Vec<DynamicType>> = std::sync::Mutex::new(Vec::new());

thread_local! {
    /// Within one outermost comparison (depth > 0): the pairs of nodes (by address) found equal so far.
    static EQUAL_PAIRS: RefCell<(u32, HashSet<(usize, usize)>)> = RefCell::new((0, HashSet::new()));
}

impl PartialEq for DynamicType {
    fn eq(&self, other: &Self) -> bool {
        // A defined forward reference is the type it refers to.
        let (this, other) = (self.unforwarded(), other.unforwarded());
        if Arc::ptr_eq(&this.0, &other.0) {
            return true;
        }
        // Both trees are borrowed for the whole outermost comparison, so addresses stay unique until the
        // memo is cleared at its end.
        let pair = (
            Arc::as_ptr(&this.0) as usize,
            Arc::as_ptr(&other.0) as usize,
        );
        // A pair is taken as equal while it is being compared (so a recursive type's cycle ends there): if
        // it is not, the comparison that assumed it fails too, up to the outermost one.
        let known = EQUAL_PAIRS.with(|m| {
            let mut m = m.borrow_mut();
            m.0 += 1;
            !m.1.insert(pair)
        });
        let same = known || this.0 == other.0;
        EQUAL_PAIRS.with(|m| {
            let mut m = m.borrow_mut();
            if !same {
                m.1.remove(&pair);
            }
            m.0 -= 1;
            if m.0 == 0 {
                m.1 = HashSet::new();
            }
        });
        same
    }
}

impl std::fmt::Debug for DynamicType {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match &*self.0 {
            TypeKind::Struct(s) => write!(f, "struct {}", s.name),
            TypeKind::Union(u) => write!(f, "union {}", u.name),
            TypeKind::Enum(e) => write!(f, "enum {}", e.name),
            TypeKind::Bitmask(b) => write!(f, "bitmask {}", b.name),
            TypeKind::Alias { name, .. } => write!(f, "typedef {name}"),
            TypeKind::Forward(r) => r.fmt(f),
            other => other.fmt(f),
        }
    }
}

/// The primitive types (`TK_BOOLEAN` ... `TK_CHAR16`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Primitive {
    /// `boolean`.
    Bool,
    /// `octet`.
    Byte,
    /// `int8`.
    Int8,
    /// `uint8`.
    UInt8,
    /// `short`.
    Int16,
    /// `unsigned short`.
    UInt16,
    /// `long`.
    Int32,
    /// `unsigned long`.
    UInt32,
    /// `long long`.
    Int64,
    /// `unsigned long long`.
    UInt64,
    /// `float`.
    Float32,
    /// `double`.
    Float64,
    /// `long double` (16 bytes, carried as they are).
    Float128,
    /// `char`.
    Char8,
    /// `wchar`.
    Char16,
}

impl Primitive {
    /// Encoded size in bytes.
    pub const fn size(self) -> usize {
        match self {
            Primitive::Bool
            | Primitive::Byte
            | Primitive::Int8
            | Primitive::UInt8
            | Primitive::Char8 => 1,
            Primitive::Int16 | Primitive::UInt16 | Primitive::Char16 => 2,
            Primitive::Int32 | Primitive::UInt32 | Primitive::Float32 => 4,
            Primitive::Int64 | Primitive::UInt64 | Primitive::Float64 => 8,
            Primitive::Float128 => 16,
        }
    }

    /// The IDL spelling.
    pub const fn idl_name(self) -> &'static str {
        match self {
            Primitive::Bool => "boolean",
            Primitive::Byte => "octet",
            Primitive::Int8 => "int8",
            Primitive::UInt8 => "uint8",
            Primitive::Int16 => "short",
            Primitive::UInt16 => "unsigned short",
            Primitive::Int32 => "long",
            Primitive::UInt32 => "unsigned long",
            Primitive::Int64 => "long long",
            Primitive::UInt64 => "unsigned long long",
            Primitive::Float32 => "float",
            Primitive::Float64 => "double",
            Primitive::Float128 => "long double",
            Primitive::Char8 => "char",
            Primitive::Char16 => "wchar",
        }
    }
}

/// What a [`DynamicType`] is.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub enum TypeKind {
    /// A primitive.
    Primitive(Primitive),
    /// `string<bound>` or `wstring<bound>`.
    String {
        /// `wstring`.
        wide: bool,
        /// Maximum length in characters (code units for `wstring`), if bounded.
        bound: Option<u32>,
    },
    /// A typedef: values are those of `target`.
    Alias {
        /// Scoped name.
        name: String,
        /// The aliased type.
        target: DynamicType,
    },
    /// An enum.
    Enum(EnumType),
    /// A bitmask.
    Bitmask(BitmaskType),
    /// A struct.
    Struct(StructType),
    /// A union.
    Union(UnionType),
    /// `sequence<T, bound>`.
    Sequence {
        /// Element type.
        element: DynamicType,
        /// Maximum length, if bounded.
        bound: Option<u32>,
    },
    /// An array; multi-dimensional arrays list every dimension, outermost first.
    Array {
        /// Element type (never itself an array: nested arrays are flattened into `dims`).
        element: DynamicType,
        /// Dimensions, outermost first.
        dims: Vec<u32>,
    },
    /// `map<K, V, bound>`.
    Map {
        /// Key type.
        key: DynamicType,
        /// Value type.
        value: DynamicType,
        /// Maximum entries, if bounded.
        bound: Option<u32>,
    },
    /// A named struct or union used before its definition: the back reference that closes a recursive
    /// type's cycle ([`DynamicType::forward`], [`DynamicType::recursive`]).
    Forward(ForwardType),
}

/// The late-bound reference of [`TypeKind::Forward`]: a name, and the type it stands for once defined.
///
/// Equality compares the types referred to (names when undefined); `Debug` prints the name only.
#[derive(Clone)]
pub struct ForwardType {
    name: String,
    target: OnceLock<DynamicType>,
}

impl ForwardType {
    /// The name of the type referred to.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// The type referred to, once defined.
    pub fn target(&self) -> Option<&DynamicType> {
        self.target.get()
    }
}

impl std::fmt::Debug for ForwardType {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let state = if self.target.get().is_some() {
            ""
        } else {
            " (undefined)"
        };
        write!(f, "forward {}{state}", self.name)
    }
}

impl PartialEq for ForwardType {
    fn eq(&self, other: &Self) -> bool {
        match (self.target(), other.target()) {
            (Some(a), Some(b)) => a == b,
            (None, None) => self.name == other.name,
            _ => false,
        }
    }
}

/// An enumerator.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Enumerator {
    /// Its name.
    pub name: String,
    /// Its value.
    pub value: i32,
}

/// An enum type.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct EnumType {
    /// Scoped name.
    pub name: String,
    /// `@bit_bound` (1..=32): 1, 2 or 4 bytes on the wire.
    pub bit_bound: u16,
    /// Enumerators in declaration order.
    pub literals: Vec<Enumerator>,
    /// Index of the default literal.
    pub default: usize,
    /// Extensibility (in the type object only; `@final` unless annotated).
    pub extensibility: Extensibility,
}

impl EnumType {
    /// Bytes on the wire (both XCDR versions).
    pub fn size(&self) -> usize {
        match self.bit_bound {
            0..=8 => 1,
            9..=16 => 2,
            _ => 4,
        }
    }

    /// The enumerator named `name`.
    pub fn value_of(&self, name: &str) -> Option<i32> {
        self.literals
            .iter()
            .find(|l| l.name == name)
            .map(|l| l.value)
    }

    /// The name of the enumerator with `value`.
    pub fn name_of(&self, value: i32) -> Option<&str> {
        self.literals
            .iter()
            .find(|l| l.value == value)
            .map(|l| l.name.as_str())
    }
}

/// A bitmask flag.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct BitFlag {
    /// Its name.
    pub name: String,
    /// Its bit position.
    pub position: u16,
}

/// A bitmask type.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct BitmaskType {
    /// Scoped name.
    pub name: String,
    /// `@bit_bound` (1..=64): 1, 2, 4 or 8 bytes on the wire.
    pub bit_bound: u16,
    /// The flags.
    pub flags: Vec<BitFlag>,
    /// Extensibility (in the type object only; `@final` unless annotated).
    pub extensibility: Extensibility,
}

impl BitmaskType {
    /// Bytes on the wire.
    pub fn size(&self) -> usize {
        match self.bit_bound {
            0..=8 => 1,
            9..=16 => 2,
            17..=32 => 4,
            _ => 8,
        }
    }
}

/// A struct member.
#[derive(Debug, Clone, PartialEq)]
pub struct Member {
    /// Its name.
    pub name: String,
    /// Its member id.
    pub id: u32,
    /// Its type.
    pub ty: DynamicType,
    /// `@key`.
    pub key: bool,
    /// `@optional`.
    pub optional: bool,
    /// `@external`.
    pub external: bool,
    /// `@must_understand`.
    pub must_understand: bool,
    /// `@hashid` as written (the string, empty for the member name): the type object keeps it.
    pub hash_id: Option<String>,
    /// `@default`: the member's try-construct behaviour is USE_DEFAULT (TRY_CONSTRUCT2) instead of DISCARD.
    pub use_default: bool,
}

/// A struct type. Members of the base come first in [`StructType::members`].
#[derive(Debug, Clone, PartialEq)]
pub struct StructType {
    /// Scoped name.
    pub name: String,
    /// Extensibility.
    pub extensibility: Extensibility,
    /// The base struct, if any.
    pub base: Option<DynamicType>,
    /// Every member, the base's first (a sample's values are in this order).
    pub members: Vec<Member>,
    /// `@autoid(HASH)`.
    pub autoid_hash: bool,
    /// `@nested`: not meant as a topic type.
    pub nested: bool,
    /// How many of `members` the base (and its bases) contributes, per inheritance level, outermost first.
    pub(super) levels: Vec<usize>,
}

impl StructType {
    /// Index of the member named `name`.
    pub fn index_of(&self, name: &str) -> Option<usize> {
        self.members.iter().position(|m| m.name == name)
    }

    /// Index of the member with id `id`.
    pub fn index_of_id(&self, id: u32) -> Option<usize> {
        self.members.iter().position(|m| m.id == id)
    }

    /// The struct's own members (its base's left out).
    pub fn own_members(&self) -> &[Member] {
        let start = self.levels.iter().rev().nth(1).copied().unwrap_or(0);
        &self.members[start..]
    }

    /// Whether the struct (or its base) has key members.
    pub fn has_keys(&self) -> bool {
        self.members.iter().any(|m| m.key)
    }

    /// The members' indices level by level (base first), each level sorted by member id: the key-hash order.
    pub(super) fn by_id(&self) -> Vec<usize> {
        let mut out = Vec::with_capacity(self.members.len());
        let mut start = 0;
        for &end in &self.levels {
            let mut level: Vec<usize> = (start..end).collect();
            level.sort_by_key(|&i| self.members[i].id);
            out.extend(level);
            start = end;
        }
        out
    }
}

/// A union case.
#[derive(Debug, Clone, PartialEq)]
pub struct UnionCase {
    /// Its member name.
    pub name: String,
    /// Its member id.
    pub id: u32,
    /// Its type.
    pub ty: DynamicType,
    /// Its labels (as integers: enumerator values, 0/1 for booleans, character codes).
    pub labels: Vec<i64>,
    /// Carries the `default` label.
    pub is_default: bool,
    /// `@external`.
    pub external: bool,
}

/// A union type.
#[derive(Debug, Clone, PartialEq)]
pub struct UnionType {
    /// Scoped name.
    pub name: String,
    /// Extensibility.
    pub extensibility: Extensibility,
    /// The discriminator type (an integer, `boolean`, `char`, `wchar`, `octet` or an enum, possibly aliased).
    pub discriminator: DynamicType,
    /// `@key` on the discriminator.
    pub disc_key: bool,
    /// The cases.
    pub cases: Vec<UnionCase>,
    /// `@nested`: not meant as a topic type.
    pub nested: bool,
}

impl UnionType {
    /// The id of the first case when none is given, then numbered on (`@id` continues from its value).
    ///
    /// Cyclone DDS 11 (its idlc and Python binding) numbers union members from 0 in the type objects, and its
    /// endpoints match ours only if the ids agree, so final and appendable unions follow it. XTypes 1.3 gives
    /// the discriminator id 0 and the members 1, 2, ... (Cyclone after 11.0.1 does too); a mutable union
    /// puts the discriminator in member 0 on the wire, so its cases must start at 1. Cyclone 11 has no
    /// mutable unions, so for them the spec applies. The derive (dds-macros `model.rs`) applies the same rule.
    pub fn first_member_id(extensibility: Extensibility) -> u32 {
        match extensibility {
            Extensibility::Mutable => 1,
            Extensibility::Final | Extensibility::Appendable => 0,
        }
    }

    /// The case a discriminator value selects: a labelled case, else the default case.
    pub fn case_for(&self, disc: i64) -> Option<usize> {
        self.cases
            .iter()
            .position(|c| c.labels.contains(&disc))
            .or_else(|| self.cases.iter().rposition(|c| c.is_default))
    }

    /// The discriminator written for the default case: the first value no label uses (libddsc's search).
    pub fn default_discriminator(&self) -> Option<i64> {
        let labels: Vec<i64> = self
            .cases
            .iter()
            .flat_map(|c| c.labels.iter().copied())
            .collect();
        match self.discriminator.kind() {
            TypeKind::Enum(e) => e
                .literals
                .iter()
                .map(|l| i64::from(l.value))
                .find(|v| !labels.contains(v)),
            TypeKind::Primitive(Primitive::Bool) => {
                [1, 0].into_iter().find(|v| !labels.contains(v))
            }
            TypeKind::Primitive(p) if is_signed(*p) => (1..=i64::from(u16::MAX))
                .map(|v| -v)
                .find(|v| !labels.contains(v)),
            _ => (0..=i64::from(u16::MAX)).find(|v| !labels.contains(v)),
        }
    }

    /// The name of the case `disc` selects.
    pub fn case_name(&self, disc: i64) -> Option<&str> {
        self.case_for(disc).map(|i| self.cases[i].name.as_str())
    }
}

/// Ends building a type that `forward` stood for while it was built: the placeholder is defined as `t` if
/// anything refers to it (the type is recursive), else dropped. The caller has let go of its own copies
/// (placeholder maps) first.
pub(super) fn close_forward(forward: DynamicType, t: &DynamicType) -> Result<(), DynamicError> {
    if Arc::strong_count(&forward.0) > 1 {
        forward.define(t.clone())
    } else {
        Ok(())
    }
}

/// Whether a value of `ty` holds a value of the forward reference `fwd` (by address) with nothing in between that
/// may be empty (sequence, map, optional member): then the type has no finite value.
fn reaches_by_value(ty: &DynamicType, fwd: &DynamicType) -> bool {
    let mut seen = HashSet::new();
    let mut stack = vec![ty];
    while let Some(t) = stack.pop() {
        if Arc::ptr_eq(&t.0, &fwd.0) {
            return true;
        }
        if !seen.insert(Arc::as_ptr(&t.0) as usize) {
            continue;
        }
        match t.kind() {
            TypeKind::Alias { target, .. } => stack.push(target),
            TypeKind::Forward(r) => stack.extend(r.target()),
            TypeKind::Array { element, .. } => stack.push(element),
            TypeKind::Struct(s) => {
                stack.extend(s.members.iter().filter(|m| !m.optional).map(|m| &m.ty))
            }
            // A union's default value is its first case.
            TypeKind::Union(u) => stack.extend(u.cases.first().map(|c| &c.ty)),
            _ => {}
        }
    }
    false
}

pub(super) fn is_signed(p: Primitive) -> bool {
    matches!(
        p,
        Primitive::Int8 | Primitive::Int16 | Primitive::Int32 | Primitive::Int64
    )
}

impl DynamicType {
    /// A type of this kind.
    pub fn new(kind: TypeKind) -> Self {
        DynamicType(Arc::new(kind))
    }

    /// A primitive type.
    pub fn primitive(p: Primitive) -> Self {
        DynamicType::new(TypeKind::Primitive(p))
    }

    /// `string` (unbounded with `None`).
    pub fn string(bound: Option<u32>) -> Self {
        DynamicType::new(TypeKind::String { wide: false, bound })
    }

    /// `wstring` (unbounded with `None`).
    pub fn wstring(bound: Option<u32>) -> Self {
        DynamicType::new(TypeKind::String { wide: true, bound })
    }

    /// `sequence<element, bound>`.
    pub fn sequence(element: DynamicType, bound: Option<u32>) -> Self {
        DynamicType::new(TypeKind::Sequence { element, bound })
    }

    /// An array with these dimensions (an array element's own dimensions are appended).
    pub fn array(element: DynamicType, dims: Vec<u32>) -> Result<Self, DynamicError> {
        if dims.is_empty() || dims.contains(&0) {
            return Err(DynamicError::Invalid(
                "an array needs non-zero dimensions".into(),
            ));
        }
        let (element, dims) = match element.kind() {
            TypeKind::Array {
                element: e,
                dims: d,
            } => {
                let mut all = dims;
                all.extend_from_slice(d);
                (e.clone(), all)
            }
            _ => (element, dims),
        };
        Ok(DynamicType::new(TypeKind::Array { element, dims }))
    }

    /// `map<key, value, bound>`.
    pub fn map(key: DynamicType, value: DynamicType, bound: Option<u32>) -> Self {
        DynamicType::new(TypeKind::Map { key, value, bound })
    }

    /// `typedef target name`.
    pub fn alias(name: impl Into<String>, target: DynamicType) -> Self {
        DynamicType::new(TypeKind::Alias {
            name: name.into(),
            target,
        })
    }

    /// A reference to the struct or union `name`, to be defined later with [`DynamicType::define`]: what a
    /// recursive type's members use to refer back to it. [`DynamicType::recursive`] does both steps.
    ///
    /// A defined recursive type is a cycle of shared nodes: it lives as long as the process, and a process
    /// defines at most [`MAX_RECURSIVE_TYPES`] (build each one once, as a topic does; importing the same
    /// component identifiers again reuses the type).
    pub fn forward(name: impl Into<String>) -> Self {
        DynamicType::new(TypeKind::Forward(ForwardType {
            name: name.into(),
            target: OnceLock::new(),
        }))
    }

    /// Defines the forward reference `self` ([`DynamicType::forward`]) as `target`, closing the cycle.
    ///
    /// Errors: `self` is not an undefined forward reference; `target` is not a struct, union or typedef of the
    /// reference's name; or the type would have no finite value (a member, array element or
    /// first union case leads back to it with no sequence, map or optional member in between).
    pub fn define(&self, target: DynamicType) -> Result<(), DynamicError> {
        let TypeKind::Forward(r) = self.kind() else {
            return Err(DynamicError::Invalid(format!(
                "{self:?} is not a forward reference"
            )));
        };
        let named = target.unforwarded();
        if named.name() != r.name
            || !matches!(
                named.kind(),
                TypeKind::Struct(_) | TypeKind::Union(_) | TypeKind::Alias { .. }
            )
        {
            return Err(DynamicError::Invalid(format!(
                "forward {} defined as {target:?}: not a struct, union or typedef of that name",
                r.name
            )));
        }
        if reaches_by_value(&target, self) {
            return Err(DynamicError::Invalid(format!(
                "recursive type {} has no finite value: a sequence, map or optional member must break its cycle",
                r.name
            )));
        }
        // The cycle keeps itself alive: it is kept here too, in a bounded list, so that what lives for the
        // process is visible and limited.
        let mut defined = DEFINED.lock().unwrap_or_else(|e| e.into_inner());
        if defined.len() >= MAX_RECURSIVE_TYPES {
            return Err(DynamicError::Invalid(format!(
                "{} is past the {MAX_RECURSIVE_TYPES} recursive types a process may define",
                r.name
            )));
        }
        r.target
            .set(target.clone())
            .map_err(|_| DynamicError::Invalid(format!("forward {} is already defined", r.name)))?;
        defined.push(target);
        Ok(())
    }

    /// A recursive struct or union: `build` gets a forward reference to the type (named `name`) to use in its
    /// members, and returns the type, which then defines the reference ([`DynamicType::define`]).
    ///
    /// ```
    /// # use dds_runtime::xtypes::dynamic::*;
    /// // struct Node { long v; sequence<Node> kids; };
    /// let node = DynamicType::recursive("Node", |node| {
    ///     StructBuilder::new("Node")
    ///         .member("v", DynamicType::primitive(Primitive::Int32))
    ///         .member("kids", DynamicType::sequence(node, None))
    ///         .build()
    /// })?;
    /// # Ok::<(), DynamicError>(())
    /// ```
    pub fn recursive(
        name: impl Into<String>,
        build: impl FnOnce(DynamicType) -> Result<DynamicType, DynamicError>,
    ) -> Result<DynamicType, DynamicError> {
        let fwd = DynamicType::forward(name);
        let ty = build(fwd.clone())?;
        fwd.define(ty.clone())?;
        Ok(ty)
    }

    /// What the type is.
    pub fn kind(&self) -> &TypeKind {
        &self.0
    }

    /// The type with aliases and defined forward references followed.
    pub fn resolved(&self) -> &DynamicType {
        let mut t = self;
        loop {
            t = match &*t.0 {
                TypeKind::Alias { target, .. } => target,
                TypeKind::Forward(r) => match r.target() {
                    Some(target) => target,
                    None => return t,
                },
                _ => return t,
            };
        }
    }

    /// The type with forward references followed (aliases kept).
    pub(super) fn unforwarded(&self) -> &DynamicType {
        let mut t = self;
        while let TypeKind::Forward(r) = &*t.0 {
            match r.target() {
                Some(target) => t = target,
                None => break,
            }
        }
        t
    }

    /// The scoped name of a named type (struct, union, enum, bitmask, alias), else the IDL spelling.
    pub fn name(&self) -> String {
        match self.kind() {
            TypeKind::Struct(s) => s.name.clone(),
            TypeKind::Union(u) => u.name.clone(),
            TypeKind::Enum(e) => e.name.clone(),
            TypeKind::Bitmask(b) => b.name.clone(),
            TypeKind::Alias { name, .. } => name.clone(),
            TypeKind::Forward(r) => r.name.clone(),
            TypeKind::Primitive(p) => p.idl_name().to_string(),
            TypeKind::String { wide, bound } => {
                let s = if *wide { "wstring" } else { "string" };
                match bound {
                    Some(b) => format!("{s}<{b}>"),
                    None => s.to_string(),
                }
            }
            TypeKind::Sequence { element, bound } => match bound {
                Some(b) => format!("sequence<{}, {b}>", element.name()),
                None => format!("sequence<{}>", element.name()),
            },
            TypeKind::Array { element, dims } => {
                let d: String = dims.iter().map(|d| format!("[{d}]")).collect();
                format!("{}{d}", element.name())
            }
            TypeKind::Map { key, value, bound } => match bound {
                Some(b) => format!("map<{}, {}, {b}>", key.name(), value.name()),
                None => format!("map<{}, {}>", key.name(), value.name()),
            },
        }
    }

    /// The struct description, if this (alias-resolved) type is a struct.
    pub fn as_struct(&self) -> Option<&StructType> {
        match self.resolved().kind() {
            TypeKind::Struct(s) => Some(s),
            _ => None,
        }
    }

    /// The union description, if this (alias-resolved) type is a union.
    pub fn as_union(&self) -> Option<&UnionType> {
        match self.resolved().kind() {
            TypeKind::Union(u) => Some(u),
            _ => None,
        }
    }

    /// The extensibility of a struct or union (final for everything else), as a topic type's header says.
    pub fn extensibility(&self) -> Extensibility {
        match self.resolved().kind() {
            TypeKind::Struct(s) => s.extensibility,
            TypeKind::Union(u) => u.extensibility,
            _ => Extensibility::Final,
        }
    }

    /// Whether samples have a key: a struct with key members. A union topic type is unkeyed, as for the derive
    /// (its `disc_key` is kept for the type's description only).
    pub fn is_keyed(&self) -> bool {
        self.as_struct().is_some_and(StructType::has_keys)
    }
}

#[cfg(test)]
mod tests {
    use super::super::builder::StructBuilder;
    use super::*;

    /// `L0 { long a; }`, `Ln { Ln-1 a; Ln-1 b; }`: 2^n paths, n + 1 distinct nodes.
    fn lattice(depth: usize) -> DynamicType {
        let mut t = StructBuilder::new("L0")
            .member("a", DynamicType::primitive(Primitive::Int32))
            .build()
            .unwrap();
        for i in 1..=depth {
            t = StructBuilder::new(format!("L{i}"))
                .member("a", t.clone())
                .member("b", t)
                .build()
                .unwrap();
        }
        t
    }

    #[test]
    fn separately_built_deep_lattices_compare_in_linear_time() {
        // Without the memo this is 2^60 comparisons.
        let (a, b) = (lattice(60), lattice(60));
        let start = std::time::Instant::now();
        assert_eq!(a, b);
        assert_ne!(a, lattice(59));
        assert!(start.elapsed() < std::time::Duration::from_secs(1));
    }
}
