"""Emits tests/tests/golden/types.rs: the Rust mirror of corpus.py (types with #[derive(DdsType)], sample
values, one #[test] per fixture file). Generated so the Rust types cannot drift from the Python ones."""

import enum
import math
import struct
from inspect import isclass

from cyclonedds.idl import IdlStruct, IdlUnion, IdlBitmask
from cyclonedds.idl._type_normalize import get_extended_type_hints, get_idl_annotations, \
    get_idl_field_annotations, WrapOpt
from cyclonedds.idl.types import (sequence, array, bounded_str, typedef, case, default, int8, int16, int32, int64,
                                  uint8, uint16, uint32, uint64, byte, char, wchar, float32, float64)

PRIMS = [(bool, "bool"), (byte, "u8"), (uint8, "u8"), (int8, "i8"), (char, "char"), (wchar, "WChar"),
         (int16, "i16"), (uint16, "u16"), (int32, "i32"), (uint32, "u32"), (int64, "i64"), (uint64, "u64"),
         (float32, "f32"), (float64, "f64"), (str, "String")]


def prim(t):
    for p, r in PRIMS:
        if t is p or t == p:
            return r
    return None


def camel(name):
    return "".join(part[:1].upper() + part[1:].lower() for part in name.split("_"))


def own_fields(cls):
    """(base class or None, fields declared by cls itself) — the binding flattens inherited members."""
    hints = get_extended_type_hints(cls)
    base = next((b for b in cls.__bases__ if isclass(b) and issubclass(b, IdlStruct) and b is not IdlStruct), None)
    if base is None:
        return None, list(hints.items())
    inherited = set(get_extended_type_hints(base))
    return base, [(k, v) for k, v in hints.items() if k not in inherited]


def rust_type(t, nested):
    """Rust spelling of an IDL type; `nested` when no field attribute can carry a bound."""
    p = prim(t)
    if p:
        return p
    if isinstance(t, WrapOpt):
        return f"Option<{rust_type(t.inner, True)}>"
    if isinstance(t, bounded_str):
        return f"BoundedString<{t.max_length}>" if nested else "String"
    if isinstance(t, sequence):
        inner = rust_type(t.subtype, True)
        if t.max_length and nested:
            return f"BoundedSeq<{inner}, {t.max_length}>"
        return f"Vec<{inner}>"
    if isinstance(t, array):
        return f"[{rust_type(t.subtype, True)}; {t.length}]"
    if isinstance(t, typedef):
        return rust_type(t.subtype, nested)
    if isclass(t):
        return t.__name__
    raise TypeError(f"no Rust mapping for {t!r}")


def is_octet(t):
    """Whether the innermost element of `t` (through options, sequences, arrays and typedefs) is IDL octet."""
    while True:
        if isinstance(t, WrapOpt):
            t = t.inner
        elif isinstance(t, (sequence, array, typedef)):
            t = t.subtype
        else:
            return t is byte or t == byte


def has_typedef(t):
    """Whether `t` goes through a typedef (then its member says so with `#[dds(xtypes = ...)]`)."""
    if isinstance(t, WrapOpt):
        return has_typedef(t.inner)
    if isinstance(t, typedef):
        return True
    if isinstance(t, (sequence, array)):
        return has_typedef(t.subtype)
    return False


def typedef_marker(t):
    return t.name.split("::")[-1] + "Typedef"


def xtypes_type(t):
    """The spelling of `t` in `#[dds(xtypes = ...)]`: typedefs by their markers, octets and bounds in the type."""
    if isinstance(t, WrapOpt):
        return xtypes_type(t.inner)
    if isinstance(t, typedef):
        return typedef_marker(t)
    if t is byte or t == byte:
        return "dds_runtime::xtypes::Octet"
    if isinstance(t, sequence):
        inner = xtypes_type(t.subtype)
        return f"BoundedSeq<{inner}, {t.max_length}>" if t.max_length else f"Vec<{inner}>"
    if isinstance(t, array):
        return f"[{xtypes_type(t.subtype)}; {t.length}]"
    return rust_type(t, True)


def emit_typedef(t):
    """A typedef's marker, dependencies first (`typedef!`)."""
    return "\n".join([
        "dds_runtime::typedef!(",
        f"    /// IDL typedef `{t.name}`.",
        f'    pub {typedef_marker(t)} = "{t.name}" => {xtypes_type(t.subtype)}',
        ");",
    ])


def collect_typedefs(types):
    """Every typedef the named types' members go through, dependencies first."""
    order = []

    def visit(t):
        if isinstance(t, WrapOpt):
            return visit(t.inner)
        if isinstance(t, (sequence, array, case, default)):
            return visit(t.subtype)
        if isinstance(t, typedef):
            visit(t.subtype)
            if t.name not in [o.name for o in order]:
                order.append(t)
        elif isclass(t) and issubclass(t, (IdlStruct, IdlUnion)):
            for v in get_extended_type_hints(t).values():
                visit(v)

    for t in types:
        visit(t)
    return order


def bound_of(t):
    if isinstance(t, WrapOpt):
        return bound_of(t.inner)
    if isinstance(t, bounded_str):
        return t.max_length
    if isinstance(t, sequence) and t.max_length:
        return t.max_length
    return None


def collect(types):
    """Every named type reachable from the corpus, dependencies first."""
    order, seen = [], set()

    def visit(t):
        if isinstance(t, WrapOpt):
            return visit(t.inner)
        if isinstance(t, (sequence, array, typedef, case, default)):
            return visit(t.subtype)
        if not isclass(t) or t in seen:
            return
        if issubclass(t, (IdlStruct, IdlUnion, IdlBitmask, enum.Enum)):
            seen.add(t)
            if issubclass(t, IdlStruct):
                base, _ = own_fields(t)
                if base:
                    visit(base)
                for v in get_extended_type_hints(t).values():
                    visit(v)
            elif issubclass(t, IdlUnion):
                visit(t.__idl_discriminator__)
                for v in get_extended_type_hints(t).values():
                    visit(v)
            order.append(t)

    for t in types:
        visit(t)
    return order


def ext_attr(cls):
    return get_idl_annotations(cls).get("extensibility", "final")


def emit_type(t):
    name = t.__name__
    tn = t.__idl_typename__.replace(".", "::")
    out = []
    if issubclass(t, enum.Enum):
        bb = get_idl_annotations(t).get("bit_bound")
        attrs = [f'name = "{tn}"'] + ([f"bit_bound = {bb}"] if bb else [])
        out.append("#[derive(DdsType, Debug, Clone, Copy, PartialEq, Eq)]")
        out.append(f"#[dds({', '.join(attrs)})]")
        out.append(f"pub enum {name} {{")
        for e in t:
            if camel(e.name) != e.name:
                out.append(f'    #[dds(name = "{e.name}")]')
            out.append(f"    {camel(e.name)} = {e.value},")
        out.append("}")
    elif issubclass(t, IdlBitmask):
        bb = get_idl_annotations(t).get("bit_bound", 32)
        repr_ = "u8" if bb <= 8 else "u16" if bb <= 16 else "u32" if bb <= 32 else "u64"
        out.append("bitflags::bitflags! {")
        out.append("    #[derive(DdsType, Debug, Clone, Copy, PartialEq, Eq)]")
        out.append(f'    #[dds(bitmask, name = "{tn}", bit_bound = {bb})]')
        out.append(f"    pub struct {name}: {repr_} {{")
        for fname, pos in t.__idl_positions__.items():
            out.append(f"        const {fname.upper()} = 1 << {pos};")
        out.append("    }")
        out.append("}")
    elif issubclass(t, IdlUnion):
        disc = t.__idl_discriminator__
        dname = prim(disc) or disc.__name__
        ext = ext_attr(t)
        out.append("#[derive(DdsType, Debug, Clone, PartialEq)]")
        out.append(f'#[dds(name = "{tn}", {ext}, discriminator = {dname})]')
        out.append(f"pub enum {name} {{")
        for mname, ct in get_extended_type_hints(t).items():
            rename = f', name = "{mname}"' if camel(mname) != mname else ""
            if isinstance(ct, default):
                out.append(f"    #[dds(default{rename})]")
            else:
                labels = ", ".join(f"case = {rust_value(disc, lab)}" for lab in ct.labels)
                out.append(f"    #[dds({labels}{rename})]")
            octet = "#[dds(octet)] " if is_octet(ct.subtype) else ""
            if has_typedef(ct.subtype):
                octet += f"#[dds(xtypes = {xtypes_type(ct.subtype)})] "
            out.append(f"    {camel(mname)}({octet}{rust_type(ct.subtype, True)}),")
        out.append("}")
    else:
        ann = get_idl_annotations(t)
        fann = get_idl_field_annotations(t)
        attrs = [f'name = "{tn}"', ext_attr(t)]
        if ann.get("autoid") == "hash":
            attrs.append('autoid = "hash"')
        if not t.__idl__.keyless is False and not any("key" in fann.get(f, {}) for f in get_extended_type_hints(t)):
            pass
        out.append("#[derive(DdsType, Debug, Clone, PartialEq)]")
        out.append(f"#[dds({', '.join(attrs)})]")
        out.append(f"pub struct {name} {{")
        base, fields = own_fields(t)
        if base:
            out.append("    #[dds(base)]")
            out.append(f"    pub base: {base.__name__},")
        for fname, ft in fields:
            fa = fann.get(fname, {})
            a = []
            if fa.get("key"):
                a.append("key")
            if "id" in fa:
                a.append(f"id = {fa['id']}")
            if "hash_id" in fa:
                a.append("hashid")
            if fa.get("must_understand"):
                a.append("must_understand")
            if fa.get("external"):
                a.append("external")
            b = bound_of(ft)
            if b:
                a.append(f"bound = {b}")
            if is_octet(ft):
                a.append("octet")
            if has_typedef(ft):
                a.append(f"xtypes = {xtypes_type(ft)}")
            rt = rust_type(ft, False)
            if fa.get("external"):
                rt = f"Option<Box<{rt[7:-1]}>>" if rt.startswith("Option<") else f"Box<{rt}>"
            if a:
                out.append(f"    #[dds({', '.join(a)})]")
            out.append(f"    pub {fname}: {rt},")
        out.append("}")
    return "\n".join(out)


def rust_str(s):
    out = []
    for ch in s:
        if ch in '"\\':
            out.append("\\" + ch)
        elif 0x20 <= ord(ch) < 0x7f or ord(ch) > 0xa0:
            out.append(ch)
        else:
            out.append(f"\\u{{{ord(ch):x}}}")
    return '"' + "".join(out) + '"'


INT_LIMITS = {"i8": 8, "i16": 16, "i32": 32, "i64": 64}


def rust_value(t, v, external=False, nested=True):
    """Rust expression for value `v` of IDL type `t`; `nested` as in rust_type (False only for struct fields)."""
    if external:
        return f"Box::new({rust_value(t, v, nested=nested)})"
    p = prim(t)
    if p == "bool":
        return "true" if v else "false"
    if p == "String":
        return f"String::from({rust_str(v)})"
    if p == "char":
        return "'" + (v if 0x20 <= ord(v) < 0x7f and v not in "'\\" else f"\\u{{{ord(v):x}}}") + "'"
    if p == "WChar":
        return f"WChar(0x{v:04x})"
    if p in ("f32", "f64"):
        if p == "f32":
            bits = struct.unpack("<I", struct.pack("<f", v))[0]
            if struct.unpack("<f", struct.pack("<f", v))[0] != v:
                return f"f32::from_bits(0x{bits:08x})"
        if math.copysign(1.0, v) < 0 and v == 0:
            return f"-0.0{p}"
        r = repr(float(v))
        return f"{r}{p}" if ("e" in r or "." in r) else f"{r}.0{p}"
    if p:
        if p in INT_LIMITS and v == -(2 ** (INT_LIMITS[p] - 1)):
            return f"{p}::MIN"
        return f"{v}{p}"
    if isinstance(t, WrapOpt):
        return "None" if v is None else f"Some({rust_value(t.inner, v)})"
    if isinstance(t, bounded_str):
        return f"BoundedString(String::from({rust_str(v)}))" if nested else f"String::from({rust_str(v)})"
    if isinstance(t, sequence):
        items = "vec![" + ", ".join(rust_value(t.subtype, x) for x in v) + "]"
        return f"BoundedSeq({items})" if (nested and t.max_length) else items
    if isinstance(t, array):
        return "[" + ", ".join(rust_value(t.subtype, x) for x in v) + "]"
    if isinstance(t, typedef):
        return rust_value(t.subtype, v, nested=nested)
    if isclass(t) and issubclass(t, enum.Enum):
        return f"{t.__name__}::{camel(v.name)}"
    if isclass(t) and issubclass(t, IdlBitmask):
        return f"{t.__name__}::from_bits_retain({v.as_mask()})"
    if isclass(t) and issubclass(t, IdlUnion):
        d, val = v.get()
        for mname, ct in get_extended_type_hints(t).items():
            if isinstance(ct, case) and d in ct.labels:
                return f"{t.__name__}::{camel(mname)}({rust_value(ct.subtype, val)})"
        for mname, ct in get_extended_type_hints(t).items():
            if isinstance(ct, default):
                return f"{t.__name__}::{camel(mname)}({rust_value(ct.subtype, val)})"
        raise ValueError(f"union {t.__name__}: no member for discriminator {d!r}")
    if isclass(t) and issubclass(t, IdlStruct):
        base, fields = own_fields(t)
        fann = get_idl_field_annotations(t)
        parts = []
        if base:
            parts.append(f"base: {rust_value(base, base(**{k: getattr(v, k) for k in base.__dataclass_fields__}))}")
        for fname, ft in fields:
            ext = fann.get(fname, {}).get("external", False)
            val = getattr(v, fname)
            if ext and isinstance(ft, WrapOpt):
                parts.append(f"{fname}: " + ("None" if val is None else f"Some(Box::new({rust_value(ft.inner, val)}))"))
            else:
                parts.append(f"{fname}: {rust_value(ft, val, ext, nested=False)}")
        return f"{t.__name__} {{ " + ", ".join(parts) + " }"
    raise TypeError(f"no Rust value for {t!r}")


def snake(name):
    out = ""
    for i, ch in enumerate(name):
        if ch.isupper() and i and (not name[i - 1].isupper() or (i + 1 < len(name) and name[i + 1].islower())):
            out += "_"
        out += ch.lower()
    return out


def write(path, corpus):
    lines = [
        "// @generated by scripts/gen-golden from scripts/golden/corpus.py. Do not edit by hand.",
        "#![allow(clippy::all, clippy::pedantic, non_camel_case_types, dead_code, unused_imports)]",
        "",
        "use dds_runtime::cdr::{BoundedSeq, BoundedString, WChar};",
        "use dds_runtime::DdsType;",
        "",
    ]
    named = collect([c for c, _ in corpus])
    for t in collect_typedefs(named):
        lines.append(emit_typedef(t))
        lines.append("")
    for t in named:
        lines.append(emit_type(t))
        lines.append("")
    for cls, samples in corpus:
        fn = snake(cls.__name__)
        lines.append("#[test]")
        lines.append(f"fn {fn}() {{")
        lines.append(f'    crate::check::<{cls.__name__}>("{cls.__name__}", vec![')
        for name, s in samples:
            lines.append(f'        ("{name}", {rust_value(cls, s)}),')
        lines.append("    ]);")
        lines.append("}")
        lines.append("")
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text("\n".join(lines))
