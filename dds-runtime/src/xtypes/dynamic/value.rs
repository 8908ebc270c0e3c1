//! [`Value`] (a value of some dynamic type) and [`DynamicData`] (a value with its type: a sample).

use super::error::DynamicError;
use super::types::{DynamicType, Primitive, TypeKind};

/// A value of a dynamic type. Aliases are transparent: a typedef's value is its target's.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub enum Value {
    /// `boolean`.
    Bool(bool),
    /// `octet`.
    Byte(u8),
    /// `int8`.
    Int8(i8),
    /// `uint8`.
    UInt8(u8),
    /// `short`.
    Int16(i16),
    /// `unsigned short`.
    UInt16(u16),
    /// `long`.
    Int32(i32),
    /// `unsigned long`.
    UInt32(u32),
    /// `long long`.
    Int64(i64),
    /// `unsigned long long`.
    UInt64(u64),
    /// `float`.
    Float32(f32),
    /// `double`.
    Float64(f64),
    /// `long double`, its 16 bytes as carried.
    Float128([u8; 16]),
    /// `char` (one octet).
    Char8(u8),
    /// `wchar` (one UTF-16 code unit).
    Char16(u16),
    /// `string` or `wstring`.
    String(String),
    /// An enum: the enumerator's value.
    Enum(i32),
    /// A bitmask: its bits.
    Bitmask(u64),
    /// A struct: one entry per member of [`StructType::members`](super::StructType::members) (base first);
    /// `None` is an absent optional member.
    Struct(Vec<Option<Value>>),
    /// A union: the discriminator, and the selected case's value (`None` when no case is selected).
    Union {
        /// The discriminator as an integer.
        discriminator: i64,
        /// The selected case's value.
        value: Option<Box<Value>>,
    },
    /// A sequence.
    Sequence(Vec<Value>),
    /// An array, every dimension flattened (row-major).
    Array(Vec<Value>),
    /// A map, in its encoded order.
    Map(Vec<(Value, Value)>),
}

impl Value {
    /// The default value of `ty`: zeros, empty strings and sequences, the default enumerator, absent optional
    /// members, the first case of a union.
    pub fn default_of(ty: &DynamicType) -> Value {
        match ty.resolved().kind() {
            TypeKind::Primitive(p) => default_primitive(*p),
            TypeKind::String { .. } => Value::String(String::new()),
            TypeKind::Alias { target, .. } => Value::default_of(target),
            // Only an undefined reference is left after `resolved`.
            TypeKind::Forward(_) => Value::Struct(Vec::new()),
            TypeKind::Enum(e) => Value::Enum(e.literals.get(e.default).map_or(0, |l| l.value)),
            TypeKind::Bitmask(_) => Value::Bitmask(0),
            TypeKind::Struct(s) => Value::Struct(
                s.members
                    .iter()
                    .map(|m| (!m.optional).then(|| Value::default_of(&m.ty)))
                    .collect(),
            ),
            TypeKind::Union(u) => {
                let (discriminator, case) = match u.cases.first() {
                    Some(c) if !c.labels.is_empty() => (c.labels[0], Some(c)),
                    Some(c) => (u.default_discriminator().unwrap_or(0), Some(c)),
                    None => (0, None),
                };
                Value::Union {
                    discriminator,
                    value: case.map(|c| Box::new(Value::default_of(&c.ty))),
                }
            }
            TypeKind::Sequence { .. } => Value::Sequence(Vec::new()),
            TypeKind::Array { element, dims } => {
                let n: usize = dims.iter().map(|d| *d as usize).product();
                Value::Array(vec![Value::default_of(element); n.min(1 << 20)])
            }
            TypeKind::Map { .. } => Value::Map(Vec::new()),
        }
    }

    /// A short name of the value's kind, for messages.
    pub fn kind_name(&self) -> &'static str {
        match self {
            Value::Bool(_) => "boolean",
            Value::Byte(_) => "octet",
            Value::Int8(_) => "int8",
            Value::UInt8(_) => "uint8",
            Value::Int16(_) => "short",
            Value::UInt16(_) => "unsigned short",
            Value::Int32(_) => "long",
            Value::UInt32(_) => "unsigned long",
            Value::Int64(_) => "long long",
            Value::UInt64(_) => "unsigned long long",
            Value::Float32(_) => "float",
            Value::Float64(_) => "double",
            Value::Float128(_) => "long double",
            Value::Char8(_) => "char",
            Value::Char16(_) => "wchar",
            Value::String(_) => "string",
            Value::Enum(_) => "enum",
            Value::Bitmask(_) => "bitmask",
            Value::Struct(_) => "struct",
            Value::Union { .. } => "union",
            Value::Sequence(_) => "sequence",
            Value::Array(_) => "array",
            Value::Map(_) => "map",
        }
    }

    /// The value as a signed integer, for integers, enums, booleans and characters (discriminators, labels).
    pub fn as_i64(&self) -> Option<i64> {
        Some(match *self {
            Value::Bool(b) => i64::from(b),
            Value::Byte(v) | Value::UInt8(v) | Value::Char8(v) => i64::from(v),
            Value::Int8(v) => i64::from(v),
            Value::Int16(v) => i64::from(v),
            Value::UInt16(v) | Value::Char16(v) => i64::from(v),
            Value::Int32(v) | Value::Enum(v) => i64::from(v),
            Value::UInt32(v) => i64::from(v),
            Value::Int64(v) => v,
            Value::UInt64(v) => v as i64,
            Value::Bitmask(v) => v as i64,
            _ => return None,
        })
    }

    /// Checks that the value fits `ty` (kinds, bounds, array lengths, union cases), all the way down.
    pub fn check(&self, ty: &DynamicType) -> Result<(), DynamicError> {
        check(self, ty, &mut String::new())
    }
}

fn default_primitive(p: Primitive) -> Value {
    match p {
        Primitive::Bool => Value::Bool(false),
        Primitive::Byte => Value::Byte(0),
        Primitive::Int8 => Value::Int8(0),
        Primitive::UInt8 => Value::UInt8(0),
        Primitive::Int16 => Value::Int16(0),
        Primitive::UInt16 => Value::UInt16(0),
        Primitive::Int32 => Value::Int32(0),
        Primitive::UInt32 => Value::UInt32(0),
        Primitive::Int64 => Value::Int64(0),
        Primitive::UInt64 => Value::UInt64(0),
        Primitive::Float32 => Value::Float32(0.0),
        Primitive::Float64 => Value::Float64(0.0),
        Primitive::Float128 => Value::Float128([0; 16]),
        Primitive::Char8 => Value::Char8(0),
        Primitive::Char16 => Value::Char16(0),
    }
}

fn primitive_matches(p: Primitive, v: &Value) -> bool {
    matches!(
        (p, v),
        (Primitive::Bool, Value::Bool(_))
            | (Primitive::Byte, Value::Byte(_))
            | (Primitive::Int8, Value::Int8(_))
            | (Primitive::UInt8, Value::UInt8(_))
            | (Primitive::Int16, Value::Int16(_))
            | (Primitive::UInt16, Value::UInt16(_))
            | (Primitive::Int32, Value::Int32(_))
            | (Primitive::UInt32, Value::UInt32(_))
            | (Primitive::Int64, Value::Int64(_))
            | (Primitive::UInt64, Value::UInt64(_))
            | (Primitive::Float32, Value::Float32(_))
            | (Primitive::Float64, Value::Float64(_))
            | (Primitive::Float128, Value::Float128(_))
            | (Primitive::Char8, Value::Char8(_))
            | (Primitive::Char16, Value::Char16(_))
    )
}

/// Runs `f` with `name` appended to the dotted member path (`a.b.c`), then takes it off again.
fn within(
    path: &mut String,
    name: &str,
    f: impl FnOnce(&mut String) -> Result<(), DynamicError>,
) -> Result<(), DynamicError> {
    let len = path.len();
    if !path.is_empty() {
        path.push('.');
    }
    path.push_str(name);
    let r = f(path);
    path.truncate(len);
    r
}

fn check(v: &Value, ty: &DynamicType, path: &mut String) -> Result<(), DynamicError> {
    let bad = |path: &str| DynamicError::mismatch(path, ty.name(), v.kind_name());
    match (ty.resolved().kind(), v) {
        (TypeKind::Primitive(p), v) if primitive_matches(*p, v) => Ok(()),
        (TypeKind::String { wide, bound }, Value::String(s)) => {
            let n = if *wide {
                s.encode_utf16().count()
            } else {
                s.len()
            };
            match bound {
                Some(b) if n > *b as usize => Err(DynamicError::mismatch(
                    path,
                    ty.name(),
                    format!("{n} characters"),
                )),
                _ => Ok(()),
            }
        }
        (TypeKind::Enum(e), Value::Enum(x)) if e.name_of(*x).is_some() => Ok(()),
        (TypeKind::Bitmask(b), Value::Bitmask(x))
            if b.bit_bound >= 64 || *x >> b.bit_bound == 0 =>
        {
            Ok(())
        }
        (TypeKind::Struct(s), Value::Struct(vals)) if vals.len() == s.members.len() => {
            for (m, val) in s.members.iter().zip(vals) {
                within(path, &m.name, |path| match val {
                    Some(val) => check(val, &m.ty, path),
                    None if m.optional => Ok(()),
                    None => Err(DynamicError::mismatch(path, m.ty.name(), "nothing")),
                })?;
            }
            Ok(())
        }
        (
            TypeKind::Union(u),
            Value::Union {
                discriminator,
                value,
            },
        ) => match (u.case_for(*discriminator), value) {
            (Some(i), Some(val)) => within(path, &u.cases[i].name, |path| {
                check(val, &u.cases[i].ty, path)
            }),
            (None, None) => Ok(()),
            _ => Err(DynamicError::mismatch(
                path,
                format!("the case of discriminator {discriminator}"),
                "another",
            )),
        },
        (TypeKind::Sequence { element, bound }, Value::Sequence(items)) => {
            if bound.is_some_and(|b| items.len() > b as usize) {
                return Err(bad(path));
            }
            check_items(items, element, path)
        }
        (TypeKind::Array { element, dims }, Value::Array(items)) => {
            let n: usize = dims.iter().map(|d| *d as usize).product();
            if items.len() != n {
                return Err(DynamicError::mismatch(
                    path,
                    format!("{n} elements"),
                    format!("{}", items.len()),
                ));
            }
            check_items(items, element, path)
        }
        (TypeKind::Map { key, value, bound }, Value::Map(entries)) => {
            if bound.is_some_and(|b| entries.len() > b as usize) {
                return Err(bad(path));
            }
            for (k, val) in entries {
                check(k, key, path)?;
                check(val, value, path)?;
            }
            Ok(())
        }
        _ => Err(bad(path)),
    }
}

fn check_items(
    items: &[Value],
    element: &DynamicType,
    path: &mut String,
) -> Result<(), DynamicError> {
    for (i, item) in items.iter().enumerate() {
        let len = path.len();
        path.push_str(&format!("[{i}]"));
        check(item, element, path)?;
        path.truncate(len);
    }
    Ok(())
}

/// A sample of a dynamic type: the type and a value of it. Members are read and written by name or id.
#[derive(Debug, Clone, PartialEq)]
pub struct DynamicData {
    ty: DynamicType,
    value: Value,
}

impl DynamicData {
    /// A sample with every member at its default.
    pub fn new(ty: DynamicType) -> Self {
        let value = Value::default_of(&ty);
        DynamicData { ty, value }
    }

    /// A sample from a value, checked against the type.
    pub fn from_value(ty: DynamicType, value: Value) -> Result<Self, DynamicError> {
        value.check(&ty)?;
        Ok(DynamicData { ty, value })
    }

    /// A sample from a value the caller knows fits (the decoder's output).
    pub(super) fn from_value_unchecked(ty: DynamicType, value: Value) -> Self {
        DynamicData { ty, value }
    }

    /// The type.
    pub fn dynamic_type(&self) -> &DynamicType {
        &self.ty
    }

    /// The whole value.
    pub fn value(&self) -> &Value {
        &self.value
    }

    /// The value, its type and value parts apart.
    pub fn into_parts(self) -> (DynamicType, Value) {
        (self.ty, self.value)
    }

    fn struct_index(&self, name: &str) -> Result<usize, DynamicError> {
        self.ty
            .as_struct()
            .and_then(|s| s.index_of(name))
            .ok_or_else(|| DynamicError::NoMember(name.to_string()))
    }

    fn struct_index_of_id(&self, id: u32) -> Result<usize, DynamicError> {
        self.ty
            .as_struct()
            .and_then(|s| s.index_of_id(id))
            .ok_or_else(|| DynamicError::NoMember(format!("id {id}")))
    }

    fn at(&self, i: usize) -> Option<&Value> {
        match &self.value {
            Value::Struct(v) => v.get(i).and_then(Option::as_ref),
            _ => None,
        }
    }

    fn set_at(&mut self, i: usize, value: Option<Value>) -> Result<(), DynamicError> {
        let Some(s) = self.ty.as_struct() else {
            return Err(DynamicError::NoMember(i.to_string()));
        };
        let m = &s.members[i];
        match &value {
            Some(v) => check(v, &m.ty, &mut m.name.clone())?,
            None if !m.optional => {
                return Err(DynamicError::mismatch(
                    &m.name,
                    "a value (not optional)",
                    "nothing",
                ))
            }
            None => {}
        }
        if let Value::Struct(vals) = &mut self.value {
            vals[i] = value;
        }
        Ok(())
    }

    /// The value of the struct member `name` (`None` when absent or not a member).
    pub fn get(&self, name: &str) -> Option<&Value> {
        self.struct_index(name).ok().and_then(|i| self.at(i))
    }

    /// The value of the struct member with id `id`.
    pub fn get_by_id(&self, id: u32) -> Option<&Value> {
        self.struct_index_of_id(id).ok().and_then(|i| self.at(i))
    }

    /// A member's value as a sample of its own type (a nested struct or union, say).
    pub fn member(&self, name: &str) -> Option<DynamicData> {
        let i = self.struct_index(name).ok()?;
        let ty = self.ty.as_struct()?.members[i].ty.clone();
        Some(DynamicData::from_value_unchecked(ty, self.at(i)?.clone()))
    }

    /// Sets the struct member `name` (type-checked).
    pub fn set(&mut self, name: &str, value: Value) -> Result<(), DynamicError> {
        let i = self.struct_index(name)?;
        self.set_at(i, Some(value))
    }

    /// Sets the struct member with id `id` (type-checked).
    pub fn set_by_id(&mut self, id: u32, value: Value) -> Result<(), DynamicError> {
        let i = self.struct_index_of_id(id)?;
        self.set_at(i, Some(value))
    }

    /// Makes the optional member `name` absent.
    pub fn clear(&mut self, name: &str) -> Result<(), DynamicError> {
        let i = self.struct_index(name)?;
        self.set_at(i, None)
    }

    /// A union's discriminator.
    pub fn discriminator(&self) -> Option<i64> {
        match &self.value {
            Value::Union { discriminator, .. } => Some(*discriminator),
            _ => None,
        }
    }

    /// A union's selected case: its name and value.
    pub fn case(&self) -> Option<(&str, &Value)> {
        let u = self.ty.as_union()?;
        match &self.value {
            Value::Union {
                discriminator,
                value: Some(v),
            } => Some((u.case_name(*discriminator)?, v)),
            _ => None,
        }
    }

    /// Selects the union case `name` (its first label, or the default discriminator) with `value`.
    pub fn set_case(&mut self, name: &str, value: Value) -> Result<(), DynamicError> {
        let u = self
            .ty
            .as_union()
            .ok_or_else(|| DynamicError::NoMember(name.to_string()))?;
        let c = u
            .cases
            .iter()
            .find(|c| c.name == name)
            .ok_or_else(|| DynamicError::NoMember(name.to_string()))?;
        check(&value, &c.ty, &mut name.to_string())?;
        let discriminator = match c.labels.first() {
            Some(l) => *l,
            None => u.default_discriminator().ok_or_else(|| {
                DynamicError::Invalid("no discriminator value left for the default case".into())
            })?,
        };
        self.value = Value::Union {
            discriminator,
            value: Some(Box::new(value)),
        };
        Ok(())
    }
}
