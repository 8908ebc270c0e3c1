//! Conversion between [`DynamicData`] and `serde_json::Value` (feature `json`).
//!
//! Structs are objects (an absent optional member is `null`), sequences and arrays are arrays (a
//! multi-dimensional array nests by dimension), enums are their enumerator's name, bitmasks their bits as a
//! number, chars one-character strings, `long double` 32 hex digits, maps objects (keys as strings), unions
//! `{"discriminator": d, "<case>": value}`. Input also accepts numbers for enums, chars and wchars, an array of
//! flag names for bitmasks, `{"discriminator": d, "value": v}` for unions and `[[k, v], ...]` for maps;
//! members missing from an object take their defaults.

use serde_json::{Map, Number, Value as Json};

use super::error::DynamicError;
use super::types::{DynamicType, Primitive, TypeKind, UnionType};
use super::value::{DynamicData, Value};

impl DynamicData {
    /// The sample as JSON.
    pub fn to_json(&self) -> Json {
        to_json(self.dynamic_type(), self.value())
    }

    /// A sample of type `ty` from JSON.
    pub fn from_json(ty: &DynamicType, json: &Json) -> Result<DynamicData, DynamicError> {
        let v = from_json(ty, json, &mut String::new())?;
        DynamicData::from_value(ty.clone(), v)
    }
}

/// A value of type `ty` as JSON.
pub fn to_json(ty: &DynamicType, v: &Value) -> Json {
    match (ty.resolved().kind(), v) {
        (TypeKind::Enum(e), Value::Enum(x)) => match e.name_of(*x) {
            Some(n) => Json::String(n.to_string()),
            None => Json::from(*x),
        },
        (TypeKind::Struct(s), Value::Struct(vals)) => Json::Object(
            s.members
                .iter()
                .zip(vals)
                .map(|(m, v)| {
                    (
                        m.name.clone(),
                        v.as_ref().map_or(Json::Null, |v| to_json(&m.ty, v)),
                    )
                })
                .collect(),
        ),
        (
            TypeKind::Union(u),
            Value::Union {
                discriminator,
                value,
            },
        ) => {
            let mut o = Map::new();
            o.insert("discriminator".into(), disc_json(u, *discriminator));
            if let (Some(i), Some(v)) = (u.case_for(*discriminator), value) {
                o.insert(u.cases[i].name.clone(), to_json(&u.cases[i].ty, v));
            }
            Json::Object(o)
        }
        (TypeKind::Sequence { element, .. }, Value::Sequence(items)) => {
            Json::Array(items.iter().map(|x| to_json(element, x)).collect())
        }
        (TypeKind::Array { element, dims }, Value::Array(items)) => nest(element, dims, items),
        (TypeKind::Map { key, value, .. }, Value::Map(entries)) => Json::Object(
            entries
                .iter()
                .map(|(k, v)| {
                    let k = match to_json(key, k) {
                        Json::String(s) => s,
                        other => other.to_string(),
                    };
                    (k, to_json(value, v))
                })
                .collect(),
        ),
        (_, v) => scalar_json(v),
    }
}

fn nest(element: &DynamicType, dims: &[u32], items: &[Value]) -> Json {
    if dims.len() <= 1 {
        return Json::Array(items.iter().map(|x| to_json(element, x)).collect());
    }
    let inner: usize = dims[1..].iter().map(|d| *d as usize).product();
    Json::Array(
        items
            .chunks(inner.max(1))
            .map(|c| nest(element, &dims[1..], c))
            .collect(),
    )
}

fn disc_json(u: &UnionType, d: i64) -> Json {
    match u.discriminator.resolved().kind() {
        TypeKind::Enum(e) => e
            .name_of(d as i32)
            .map_or_else(|| Json::from(d), |n| Json::String(n.to_string())),
        TypeKind::Primitive(Primitive::Bool) => Json::Bool(d != 0),
        _ => Json::from(d),
    }
}

fn scalar_json(v: &Value) -> Json {
    match v {
        Value::Bool(b) => Json::Bool(*b),
        Value::Byte(x) | Value::UInt8(x) => Json::from(*x),
        Value::Int8(x) => Json::from(*x),
        Value::Int16(x) => Json::from(*x),
        Value::UInt16(x) => Json::from(*x),
        Value::Int32(x) | Value::Enum(x) => Json::from(*x),
        Value::UInt32(x) => Json::from(*x),
        Value::Int64(x) => Json::from(*x),
        Value::UInt64(x) | Value::Bitmask(x) => Json::from(*x),
        Value::Float32(x) => Number::from_f64(f64::from(*x)).map_or(Json::Null, Json::Number),
        Value::Float64(x) => Number::from_f64(*x).map_or(Json::Null, Json::Number),
        Value::Float128(b) => Json::String(b.iter().map(|x| format!("{x:02x}")).collect()),
        Value::Char8(c) => Json::String(char::from(*c).to_string()),
        Value::Char16(c) => {
            Json::String(char::from_u32(u32::from(*c)).map_or_else(String::new, |c| c.to_string()))
        }
        Value::String(s) => Json::String(s.clone()),
        other => Json::String(format!("<{}>", other.kind_name())),
    }
}

fn err(path: &str, ty: &DynamicType, found: &Json) -> DynamicError {
    let mut f = found.to_string();
    f.truncate(40);
    DynamicError::mismatch(path, ty.name(), f)
}

fn int<T: TryFrom<i64> + TryFrom<u64>>(j: &Json) -> Option<T> {
    match j {
        Json::Number(n) => n
            .as_i64()
            .and_then(|x| T::try_from(x).ok())
            .or_else(|| n.as_u64().and_then(|x| T::try_from(x).ok())),
        _ => None,
    }
}

fn one_char(j: &Json) -> Option<u32> {
    match j {
        Json::String(s) => {
            let mut it = s.chars();
            let c = it.next()?;
            it.next().is_none().then_some(u32::from(c))
        }
        _ => int::<u32>(j),
    }
}

fn primitive(p: Primitive, j: &Json) -> Option<Value> {
    Some(match p {
        Primitive::Bool => Value::Bool(match j {
            Json::Bool(b) => *b,
            _ => int::<u8>(j).filter(|x| *x <= 1)? == 1,
        }),
        Primitive::Byte => Value::Byte(int(j)?),
        Primitive::Int8 => Value::Int8(int(j)?),
        Primitive::UInt8 => Value::UInt8(int(j)?),
        Primitive::Int16 => Value::Int16(int(j)?),
        Primitive::UInt16 => Value::UInt16(int(j)?),
        Primitive::Int32 => Value::Int32(int(j)?),
        Primitive::UInt32 => Value::UInt32(int(j)?),
        Primitive::Int64 => Value::Int64(int(j)?),
        Primitive::UInt64 => Value::UInt64(int(j)?),
        Primitive::Float32 => Value::Float32(j.as_f64()? as f32),
        Primitive::Float64 => Value::Float64(j.as_f64()?),
        Primitive::Float128 => {
            let s = j.as_str().filter(|s| s.len() == 32 && s.is_ascii())?;
            let mut b = [0u8; 16];
            for (i, x) in b.iter_mut().enumerate() {
                *x = u8::from_str_radix(&s[2 * i..2 * i + 2], 16).ok()?;
            }
            Value::Float128(b)
        }
        Primitive::Char8 => Value::Char8(u8::try_from(one_char(j)?).ok()?),
        Primitive::Char16 => Value::Char16(u16::try_from(one_char(j)?).ok()?),
    })
}

fn with_path<R>(path: &mut String, seg: &str, f: impl FnOnce(&mut String) -> R) -> R {
    let len = path.len();
    if !path.is_empty() && !seg.starts_with('[') {
        path.push('.');
    }
    path.push_str(seg);
    let r = f(path);
    path.truncate(len);
    r
}

/// A value of type `ty` from JSON (see the module documentation for the accepted forms).
pub fn from_json(ty: &DynamicType, j: &Json, path: &mut String) -> Result<Value, DynamicError> {
    let bad = |path: &str| err(path, ty, j);
    match ty.resolved().kind() {
        TypeKind::Primitive(p) => primitive(*p, j).ok_or_else(|| bad(path)),
        TypeKind::String { .. } => j
            .as_str()
            .map(|s| Value::String(s.to_string()))
            .ok_or_else(|| bad(path)),
        TypeKind::Enum(e) => match j {
            Json::String(s) => e.value_of(s).map(Value::Enum).ok_or_else(|| bad(path)),
            _ => int::<i32>(j)
                .filter(|x| e.name_of(*x).is_some())
                .map(Value::Enum)
                .ok_or_else(|| bad(path)),
        },
        TypeKind::Bitmask(b) => match j {
            Json::Array(names) => {
                let mut bits = 0u64;
                for n in names {
                    let f = b
                        .flags
                        .iter()
                        .find(|f| Some(f.name.as_str()) == n.as_str())
                        .ok_or_else(|| bad(path))?;
                    bits |= 1u64 << f.position;
                }
                Ok(Value::Bitmask(bits))
            }
            _ => int::<u64>(j).map(Value::Bitmask).ok_or_else(|| bad(path)),
        },
        TypeKind::Struct(s) => {
            let o = j.as_object().ok_or_else(|| bad(path))?;
            if let Some(k) = o.keys().find(|k| s.index_of(k).is_none()) {
                return Err(DynamicError::NoMember(format!("{path}.{k}")));
            }
            let mut vals = Vec::with_capacity(s.members.len());
            for m in &s.members {
                vals.push(match o.get(&m.name) {
                    None | Some(Json::Null) if m.optional => None,
                    None => Some(Value::default_of(&m.ty)),
                    Some(x) => Some(with_path(path, &m.name, |p| from_json(&m.ty, x, p))?),
                });
            }
            Ok(Value::Struct(vals))
        }
        TypeKind::Union(u) => union_from_json(u, ty, j, path),
        TypeKind::Sequence { element, .. } => {
            let a = j.as_array().ok_or_else(|| bad(path))?;
            let items = a
                .iter()
                .enumerate()
                .map(|(i, x)| with_path(path, &format!("[{i}]"), |p| from_json(element, x, p)))
                .collect::<Result<_, _>>()?;
            Ok(Value::Sequence(items))
        }
        TypeKind::Array { element, dims } => {
            let mut items = Vec::new();
            flatten(element, dims, j, path, &mut items)?;
            Ok(Value::Array(items))
        }
        TypeKind::Map { key, value, .. } => {
            let mut entries = Vec::new();
            match j {
                Json::Object(o) => {
                    for (k, v) in o {
                        let kj = match key.resolved().kind() {
                            TypeKind::String { .. } | TypeKind::Enum(_) => Json::String(k.clone()),
                            _ => serde_json::from_str(k).map_err(|_| bad(path))?,
                        };
                        entries.push((
                            from_json(key, &kj, path)?,
                            with_path(path, k, |p| from_json(value, v, p))?,
                        ));
                    }
                }
                Json::Array(pairs) => {
                    for p in pairs {
                        match p.as_array().map(Vec::as_slice) {
                            Some([k, v]) => {
                                entries.push((from_json(key, k, path)?, from_json(value, v, path)?))
                            }
                            _ => return Err(bad(path)),
                        }
                    }
                }
                _ => return Err(bad(path)),
            }
            Ok(Value::Map(entries))
        }
        TypeKind::Alias { .. } | TypeKind::Forward(_) => Err(bad(path)),
    }
}

fn flatten(
    element: &DynamicType,
    dims: &[u32],
    j: &Json,
    path: &mut String,
    out: &mut Vec<Value>,
) -> Result<(), DynamicError> {
    let a = j
        .as_array()
        .filter(|a| dims.first().is_some_and(|d| a.len() == *d as usize))
        .ok_or_else(|| {
            DynamicError::mismatch(
                path,
                format!("an array of {}", dims.first().copied().unwrap_or(0)),
                j.to_string(),
            )
        })?;
    for (i, x) in a.iter().enumerate() {
        with_path(path, &format!("[{i}]"), |p| {
            if dims.len() > 1 {
                flatten(element, &dims[1..], x, p, out)
            } else {
                out.push(from_json(element, x, p)?);
                Ok(())
            }
        })?;
    }
    Ok(())
}

fn union_from_json(
    u: &UnionType,
    ty: &DynamicType,
    j: &Json,
    path: &mut String,
) -> Result<Value, DynamicError> {
    let o = j.as_object().ok_or_else(|| err(path, ty, j))?;
    let named = u.cases.iter().position(|c| o.contains_key(&c.name));
    let disc = match o.get("discriminator") {
        Some(d) => Some(match (u.discriminator.resolved().kind(), d) {
            (TypeKind::Enum(e), Json::String(s)) => {
                i64::from(e.value_of(s).ok_or_else(|| err(path, ty, d))?)
            }
            (_, Json::Bool(b)) => i64::from(*b),
            (_, Json::String(s)) => {
                i64::from(one_char(&Json::String(s.clone())).ok_or_else(|| err(path, ty, d))?)
            }
            (_, d) => int::<i64>(d).ok_or_else(|| err(path, ty, d))?,
        }),
        None => None,
    };
    let (disc, case) = match (disc, named) {
        (Some(d), _) => (d, u.case_for(d).ok_or_else(|| err(path, ty, j))?),
        (None, Some(i)) => {
            let c = &u.cases[i];
            let d = match c.labels.first() {
                Some(l) => *l,
                None => u.default_discriminator().ok_or_else(|| err(path, ty, j))?,
            };
            (d, i)
        }
        (None, None) => return Err(err(path, ty, j)),
    };
    let c = &u.cases[case];
    let value = match o.get(&c.name).or_else(|| o.get("value")) {
        Some(x) => with_path(path, &c.name, |p| from_json(&c.ty, x, p))?,
        None => Value::default_of(&c.ty),
    };
    Ok(Value::Union {
        discriminator: disc,
        value: Some(Box::new(value)),
    })
}
