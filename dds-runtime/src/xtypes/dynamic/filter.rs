//! Content filters (`dds_runtime::filter`) on dynamic samples: members by name, elements by index, the
//! active union branch by its name. Enumerators compare with strings by name (not with numbers).

use crate::filter::{FieldValue, FilterFields, PathSegment};

use super::types::{DynamicType, TypeKind};
use super::value::{DynamicData, Value};

impl FilterFields for DynamicData {
    fn field_value(&self, path: &[PathSegment]) -> Option<FieldValue<'_>> {
        field(self.dynamic_type(), self.value(), path)
    }
}

fn field<'a>(ty: &'a DynamicType, v: &'a Value, path: &[PathSegment]) -> Option<FieldValue<'a>> {
    let ty = ty.resolved();
    let Some((first, rest)) = path.split_first() else {
        return scalar(ty, v);
    };
    match (ty.kind(), v, first) {
        (TypeKind::Struct(s), Value::Struct(vals), PathSegment::Member(m)) => {
            let i = s.index_of(m)?;
            field(&s.members[i].ty, vals[i].as_ref()?, rest)
        }
        (
            TypeKind::Union(u),
            Value::Union {
                discriminator,
                value,
            },
            PathSegment::Member(m),
        ) => {
            let i = u.case_for(*discriminator)?;
            (u.cases[i].name == **m).then_some(())?;
            field(&u.cases[i].ty, value.as_deref()?, rest)
        }
        (TypeKind::Sequence { element, .. }, Value::Sequence(items), PathSegment::Index(i))
        | (TypeKind::Array { element, .. }, Value::Array(items), PathSegment::Index(i)) => {
            field(element, items.get(*i)?, rest)
        }
        _ => None,
    }
}

fn scalar<'a>(ty: &'a DynamicType, v: &'a Value) -> Option<FieldValue<'a>> {
    Some(match v {
        Value::Bool(b) => FieldValue::Bool(*b),
        Value::Byte(x) | Value::UInt8(x) => FieldValue::UInt(u64::from(*x)),
        Value::Char8(c) => FieldValue::Char(char::from(*c)),
        Value::Char16(c) => FieldValue::Char(char::from_u32(u32::from(*c))?),
        Value::Int8(x) => FieldValue::Int(i64::from(*x)),
        Value::Int16(x) => FieldValue::Int(i64::from(*x)),
        Value::UInt16(x) => FieldValue::UInt(u64::from(*x)),
        Value::Int32(x) => FieldValue::Int(i64::from(*x)),
        Value::UInt32(x) => FieldValue::UInt(u64::from(*x)),
        Value::Int64(x) => FieldValue::Int(*x),
        Value::UInt64(x) | Value::Bitmask(x) => FieldValue::UInt(*x),
        Value::Float32(x) => FieldValue::Float(f64::from(*x)),
        Value::Float64(x) => FieldValue::Float(*x),
        Value::String(s) => FieldValue::Str(s),
        Value::Enum(x) => match ty.kind() {
            TypeKind::Enum(e) => FieldValue::Str(e.name_of(*x)?),
            _ => FieldValue::Int(i64::from(*x)),
        },
        _ => return None,
    })
}
