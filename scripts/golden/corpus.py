"""The golden corpus: IDL types declared with Cyclone DDS's Python binding, and sample values.

Every type in `CORPUS` becomes one fixture file. Names are the IDL scoped names ("Golden::X"); the Rust mirror
in tests/tests/golden/types.rs is generated from these declarations by rustgen.py, so the two cannot drift.

Python-binding limits that shape this corpus (see README.md):
- no wstring and no long double type exists in cyclonedds-python 11.0.1;
- `char` is written with struct code 'b', so only ASCII chars are encodable;
- `wchar` is written as a signed 16-bit int, so only code points below U+8000 are encodable;
- mutable unions raise NotImplementedError;
- char-discriminated unions: the binding cannot build their TypeObject (labels are str), so no topic;
- map (dict) members: the binding cannot build a TypeObject for them, so no topic can carry one.
- `@hashid("other name")` crashes the binding (it passes a str to md5); only plain `@hashid` is used.
- a bitmask position above 31 needs the bound set inside the class body (the binding checks before
  `@bit_bound` runs).
"""

from dataclasses import dataclass
from typing import Optional, List, Tuple, Any

from cyclonedds.idl import IdlStruct, IdlUnion, IdlEnum, IdlBitmask
from cyclonedds.idl.annotations import (key, member_id, member_hash_id, external, must_understand, autoid,
                                        final, appendable, mutable, bit_bound, position)
from cyclonedds.idl.types import (int8, int16, int32, int64, uint8, uint16, uint32, uint64, byte, char, wchar,
                                  float32, float64, sequence, array, bounded_str, case, default, typedef)

I32_MIN, I32_MAX = -2**31, 2**31 - 1
I64_MIN, I64_MAX = -2**63, 2**63 - 1


# ---------------------------------------------------------------- enums and bitmasks

class Color(IdlEnum, typename="Golden::Color"):
    RED = 0
    GREEN = 1
    BLUE = 2
    YELLOW = 3


@bit_bound(8)
class Small(IdlEnum, typename="Golden::Small"):
    S0 = 0
    S1 = 1
    S7 = 7


@bit_bound(16)
class Medium(IdlEnum, typename="Golden::Medium"):
    M0 = 0
    M1 = 1
    M300 = 300


@dataclass
@bit_bound(8)
class Perm8(IdlBitmask, typename="Golden::Perm8"):
    read: bool
    write: bool
    exec: bool
    position("exec", 7)


@dataclass
@bit_bound(16)
class Flags16(IdlBitmask, typename="Golden::Flags16"):
    lo: bool
    hi: bool
    position("hi", 15)


@dataclass
class Flags32(IdlBitmask, typename="Golden::Flags32"):
    a: bool
    b: bool
    top: bool
    position("top", 31)


@dataclass
@bit_bound(64)
class Flags64(IdlBitmask, typename="Golden::Flags64"):
    # the binding checks positions against the bound before @bit_bound runs; set it up front
    __idl_annotations__["bit_bound"] = 64  # noqa: F821
    first: bool
    mid: bool
    position("mid", 33)
    last: bool
    position("last", 63)


# ---------------------------------------------------------------- primitives and strings

@dataclass
@final
class Primitives(IdlStruct, typename="Golden::Primitives"):
    b: bool
    o: byte
    i8: int8
    u8: uint8
    c: char
    i16: int16
    u16: uint16
    i32: int32
    u32: uint32
    i64: int64
    u64: uint64
    f32: float32
    f64: float64
    w: wchar  # last: see the note on wchar in README.md


@dataclass
@appendable
class PrimitivesAppendable(IdlStruct, typename="Golden::PrimitivesAppendable"):
    c: char
    i64: int64
    b: bool
    f64: float64
    u16: uint16
    f32: float32


@dataclass
@mutable
class PrimitivesMutable(IdlStruct, typename="Golden::PrimitivesMutable"):
    b: bool
    o: byte
    i8: int8
    c: char
    i16: int16
    u16: uint16
    i32: int32
    u32: uint32
    i64: int64
    u64: uint64
    f32: float32
    f64: float64
    w: wchar  # last: see the note on wchar in README.md


@dataclass
@final
class Strings(IdlStruct, typename="Golden::Strings"):
    s: str
    bs: bounded_str[8]
    after: uint8
    long_s: str


@dataclass
@appendable
class StringsAppendable(IdlStruct, typename="Golden::StringsAppendable"):
    s: str
    bs: bounded_str[16]
    ss: sequence[str]


@dataclass
@final
class Alignment(IdlStruct, typename="Golden::Alignment"):
    """Every alignment step: 8-byte members after odd offsets (XCDR1 aligns 8, XCDR2 caps at 4)."""
    a: uint8
    b: int64
    c: uint8
    d: float64
    e: int16
    f: uint64
    g: char
    h: int32


# ---------------------------------------------------------------- extensibility x keyed x optional

def _ext_family(ext_name, deco):
    """Four structs per extensibility: plain, keyed, with optionals, keyed with optionals."""
    out = []

    @dataclass
    @deco
    class Plain(IdlStruct, typename=f"Golden::{ext_name}Plain"):
        id: int32
        name: str
        value: float64
        flag: bool
    Plain.__name__ = Plain.__qualname__ = f"{ext_name}Plain"
    out.append(Plain)

    @dataclass
    @deco
    class Keyed(IdlStruct, typename=f"Golden::{ext_name}Keyed"):
        id: int32
        key("id")
        name: str
        value: float64
        flag: bool
    Keyed.__name__ = Keyed.__qualname__ = f"{ext_name}Keyed"
    out.append(Keyed)

    @dataclass
    @deco
    class Opt(IdlStruct, typename=f"Golden::{ext_name}Opt"):
        id: int32
        maybe_i: Optional[int32]
        name: str
        maybe_s: Optional[str]
        maybe_d: Optional[float64]
        tail: uint8
    Opt.__name__ = Opt.__qualname__ = f"{ext_name}Opt"
    out.append(Opt)

    @dataclass
    @deco
    class KeyedOpt(IdlStruct, typename=f"Golden::{ext_name}KeyedOpt"):
        id: int32
        key("id")
        maybe_i: Optional[int32]
        name: str
        key("name")
        maybe_p: Optional["Golden_Point"]
        tail: uint16
    KeyedOpt.__name__ = KeyedOpt.__qualname__ = f"{ext_name}KeyedOpt"
    out.append(KeyedOpt)
    return out


@dataclass
@final
class Point(IdlStruct, typename="Golden::Point"):
    x: int32
    y: int32


Golden_Point = Point  # string forward references resolve by module attribute

FinalPlain, FinalKeyed, FinalOpt, FinalKeyedOpt = _ext_family("Final", final)
AppendablePlain, AppendableKeyed, AppendableOpt, AppendableKeyedOpt = _ext_family("Appendable", appendable)
MutablePlain, MutableKeyed, MutableOpt, MutableKeyedOpt = _ext_family("Mutable", mutable)


# ---------------------------------------------------------------- collections

@dataclass
@appendable
class PointA(IdlStruct, typename="Golden::PointA"):
    x: int16
    label: str


@dataclass
@mutable
class PointM(IdlStruct, typename="Golden::PointM"):
    x: int16
    label: str


@dataclass
@final
class Sequences(IdlStruct, typename="Golden::Sequences"):
    longs: sequence[int32]
    octets: sequence[byte]
    bools: sequence[bool]
    doubles: sequence[float64]
    shorts: sequence[int16]
    bounded: sequence[int64, 5]
    strings: sequence[str]
    chars: sequence[char]
    u64s: sequence[uint64]


@dataclass
@final
class NestedSeqs(IdlStruct, typename="Golden::NestedSeqs"):
    points: sequence[Point]
    apoints: sequence[PointA]
    mpoints: sequence[PointM]
    seq_seq: sequence[sequence[int32]]
    seq_seq_str: sequence[sequence[str]]


@dataclass
@appendable
class NestedSeqsAppendable(IdlStruct, typename="Golden::NestedSeqsAppendable"):
    points: sequence[Point]
    seq_seq: sequence[sequence[int16]]
    apoints: sequence[PointA, 3]


@dataclass
@final
class Arrays(IdlStruct, typename="Golden::Arrays"):
    longs: array[int32, 3]
    octets: array[byte, 4]
    strs: array[str, 2]
    matrix: array[array[int16, 3], 2]
    cube: array[array[array[uint8, 2], 2], 2]
    points: array[Point, 2]
    doubles: array[float64, 2]


@dataclass
@mutable
class ArraysMutable(IdlStruct, typename="Golden::ArraysMutable"):
    longs: array[int32, 3]
    strs: array[str, 2]
    matrix: array[array[int16, 2], 2]
    apoints: array[PointA, 2]
    octets: array[byte, 3]


@dataclass
@final
class SeqOfArrays(IdlStruct, typename="Golden::SeqOfArrays"):
    rows: sequence[array[int32, 2]]
    names: array[sequence[str], 2]


# ---------------------------------------------------------------- unions

class UnionEnum(IdlUnion, discriminator=Color, typename="Golden::UnionEnum"):
    red: case[Color.RED, int32]
    other: default[str]
    blue: case[Color.BLUE, float64]


class UnionBool(IdlUnion, discriminator=bool, typename="Golden::UnionBool"):
    yes: case[True, int32]
    no: default[str]


class UnionLong(IdlUnion, discriminator=int32, typename="Golden::UnionLong"):
    text: case[[1, 2], str]
    other: default[uint16]
    point: case[3, Point]
    big: case[I32_MIN, int64]


class UnionEnumLast(IdlUnion, discriminator=Color, typename="Golden::UnionEnumLast"):
    red: case[Color.RED, int32]
    blue: case[Color.BLUE, float64]
    other: default[str]


class UnionLongLast(IdlUnion, discriminator=int32, typename="Golden::UnionLongLast"):
    text: case[[1, 2], str]
    point: case[3, Point]
    other: default[uint16]


@appendable
class UnionAppendable(IdlUnion, discriminator=int16, typename="Golden::UnionAppendable"):
    p: case[1, PointA]
    d: case[2, float64]
    s: case[3, str]


class UnionOctet(IdlUnion, discriminator=uint8, typename="Golden::UnionOctet"):
    small: case[1, uint8]
    seq: case[2, sequence[Point]]
    other: default[int64]


@dataclass
@final
class UnionHolder(IdlStruct, typename="Golden::UnionHolder"):
    id: uint32
    key("id")
    e: UnionEnum
    c: UnionOctet
    b: UnionBool
    l: UnionLong
    el: UnionEnumLast
    ll: UnionLongLast


@dataclass
@appendable
class UnionHolderAppendable(IdlStruct, typename="Golden::UnionHolderAppendable"):
    u: UnionAppendable
    o: UnionOctet
    us: sequence[UnionEnum]


@dataclass
@mutable
class UnionHolderMutable(IdlStruct, typename="Golden::UnionHolderMutable"):
    e: UnionEnum
    a: UnionAppendable
    maybe: Optional[UnionLong]


# ---------------------------------------------------------------- enums, bitmasks

@dataclass
@final
class Enums(IdlStruct, typename="Golden::Enums"):
    c: Color
    s: Small
    m: Medium
    cs: sequence[Color]
    ss: sequence[Small]
    sa: array[Small, 3]


@dataclass
@mutable
class EnumsMutable(IdlStruct, typename="Golden::EnumsMutable"):
    c: Color
    s: Small
    m: Medium
    maybe: Optional[Small]


@dataclass
@final
class Bitmasks(IdlStruct, typename="Golden::Bitmasks"):
    p: Perm8
    f16: Flags16
    f32: Flags32
    f64: Flags64
    ps: sequence[Perm8]


@dataclass
@appendable
class BitmasksAppendable(IdlStruct, typename="Golden::BitmasksAppendable"):
    f64: Flags64
    p: Perm8
    f16: Flags16


# ---------------------------------------------------------------- inheritance

@dataclass
@final
class BaseFinal(IdlStruct, typename="Golden::BaseFinal"):
    id: int32
    key("id")
    tag: str


@dataclass
@final
class DerivedFinal(BaseFinal, typename="Golden::DerivedFinal"):
    extra: float64
    more: sequence[int16]


@dataclass
@appendable
class BaseAppendable(IdlStruct, typename="Golden::BaseAppendable"):
    id: int32
    tag: str


@dataclass
@appendable
class DerivedAppendable(BaseAppendable, typename="Golden::DerivedAppendable"):
    extra: uint8
    maybe: Optional[int64]


@dataclass
@mutable
class BaseMutable(IdlStruct, typename="Golden::BaseMutable"):
    id: int32
    key("id")
    tag: str


@dataclass
@mutable
class DerivedMutable(BaseMutable, typename="Golden::DerivedMutable"):
    extra: uint32
    note: str


# ---------------------------------------------------------------- member ids

@dataclass
@mutable
class ExplicitIds(IdlStruct, typename="Golden::ExplicitIds"):
    a: int32
    member_id("a", 10)
    b: str
    c: int16
    member_id("c", 5)
    d: float64
    e: Optional[uint8]
    member_id("e", 0x3f05)
    f: uint32
    member_id("f", 100000)


@dataclass
@mutable
class HashIds(IdlStruct, typename="Golden::HashIds"):
    alpha: int32
    member_hash_id("alpha")
    beta: str
    member_hash_id("beta")  # @hashid("other name") breaks the binding (str passed to md5)
    gamma: uint8
    maybe: Optional[int16]
    member_hash_id("maybe")


@dataclass
@mutable
@autoid("hash")
class AutoIdHash(IdlStruct, typename="Golden::AutoIdHash"):
    first: int32
    second: str
    third: float32
    fixed: uint8
    member_id("fixed", 7)


@dataclass
@appendable
class ExplicitIdsAppendable(IdlStruct, typename="Golden::ExplicitIdsAppendable"):
    a: int32
    member_id("a", 3)
    b: str
    c: Optional[int16]
    member_id("c", 1)


@dataclass
@mutable
class MustUnderstand(IdlStruct, typename="Golden::MustUnderstand"):
    id: int32
    key("id")
    critical: uint16
    must_understand("critical")
    note: str
    must_understand("note")
    opt: Optional[int32]
    must_understand("opt")
    plain: int8


# ---------------------------------------------------------------- external

@dataclass
@final
class External(IdlStruct, typename="Golden::External"):
    id: int32
    p: Point
    external("p")
    s: str
    external("s")
    maybe: Optional[PointA]
    external("maybe")


@dataclass
@mutable
class ExternalMutable(IdlStruct, typename="Golden::ExternalMutable"):
    p: PointM
    external("p")
    ids: sequence[int32]
    external("ids")


# ---------------------------------------------------------------- deep nesting

@dataclass
@final
class Level6(IdlStruct, typename="Golden::Level6"):
    leaf: int64
    note: str


@dataclass
@mutable
class Level5(IdlStruct, typename="Golden::Level5"):
    l6: Level6
    l6s: sequence[Level6]


@dataclass
@appendable
class Level4(IdlStruct, typename="Golden::Level4"):
    l5: Level5
    tag: uint8


@dataclass
@final
class Level3(IdlStruct, typename="Golden::Level3"):
    k: int16
    key("k")
    l4: Level4


@dataclass
@appendable
class Level2(IdlStruct, typename="Golden::Level2"):
    l3: Level3
    key("l3")
    maybe: Optional[Level4]


@dataclass
@mutable
class Level1(IdlStruct, typename="Golden::Level1"):
    id: uint32
    key("id")
    l2: Level2
    key("l2")
    l2s: sequence[Level2]


@dataclass
@final
class Deep(IdlStruct, typename="Golden::Deep"):
    l1: Level1
    key("l1")
    trailer: char


# ---------------------------------------------------------------- keys

@dataclass
@final
class KeyNested(IdlStruct, typename="Golden::KeyNested"):
    location: Point
    key("location")
    payload: str


@dataclass
@final
class KeyInner(IdlStruct, typename="Golden::KeyInner"):
    a: uint8
    key("a")
    ignored: str
    b: int64
    key("b")


@dataclass
@final
class KeyPartialNested(IdlStruct, typename="Golden::KeyPartialNested"):
    """Only the key members of the nested struct belong to the key."""
    inner: KeyInner
    key("inner")
    data: sequence[uint8]


@dataclass
@mutable
class KeyOrderMutable(IdlStruct, typename="Golden::KeyOrderMutable"):
    """Keys declared in an order different from their member ids."""
    z: int32
    member_id("z", 9)
    key("z")
    name: str
    member_id("name", 2)
    key("name")
    value: float64
    member_id("value", 4)
    a: uint8
    member_id("a", 1)
    key("a")


@dataclass
@appendable
class KeyOrderAppendable(IdlStruct, typename="Golden::KeyOrderAppendable"):
    z: int32
    member_id("z", 9)
    key("z")
    a: uint8
    member_id("a", 1)
    key("a")
    rest: str


@dataclass
@final
class KeyMultiFinal(IdlStruct, typename="Golden::KeyMultiFinal"):
    b: uint8
    key("b")
    l: int64
    key("l")
    s: bounded_str[20]
    key("s")
    v: float32


@dataclass
@final
class KeySmall(IdlStruct, typename="Golden::KeySmall"):
    k: int32
    key("k")
    v: str


@dataclass
@final
class KeyExactly16(IdlStruct, typename="Golden::KeyExactly16"):
    hi: uint64
    key("hi")
    lo: uint64
    key("lo")
    v: uint8


@dataclass
@final
class KeyBoundedString(IdlStruct, typename="Golden::KeyBoundedString"):
    name: bounded_str[8]
    key("name")
    v: int32


@dataclass
@appendable
class KeyString(IdlStruct, typename="Golden::KeyString"):
    name: str
    key("name")
    v: int32


@dataclass
@final
class KeyArray(IdlStruct, typename="Golden::KeyArray"):
    ids: array[int16, 4]
    key("ids")
    v: str


@dataclass
@mutable
class KeyEnum(IdlStruct, typename="Golden::KeyEnum"):
    c: Color
    key("c")
    s: Small
    key("s")
    v: int32


@dataclass
@appendable
class KeyAppendableInner(IdlStruct, typename="Golden::KeyAppendableInner"):
    x: int32
    key("x")
    y: int32


@dataclass
@appendable
class KeyAppendableNested(IdlStruct, typename="Golden::KeyAppendableNested"):
    inner: KeyAppendableInner
    key("inner")
    other: int64


@dataclass
@mutable
class KeyMutableInner(IdlStruct, typename="Golden::KeyMutableInner"):
    x: int32
    key("x")
    tag: str
    key("tag")
    y: int32


@dataclass
@final
class KeyMutableNested(IdlStruct, typename="Golden::KeyMutableNested"):
    id: uint16
    key("id")
    inner: KeyMutableInner
    key("inner")


@dataclass
@final
class KeyAllPrims(IdlStruct, typename="Golden::KeyAllPrims"):
    b: bool
    key("b")
    o: byte
    key("o")
    c: char
    key("c")
    i16: int16
    key("i16")
    u32: uint32
    key("u32")
    i64: int64
    key("i64")
    f64: float64
    key("f64")


# ---------------------------------------------------------------- more shapes

@dataclass
@final
class NestedBounds(IdlStruct, typename="Golden::NestedBounds"):
    """Bounds the member attribute cannot reach: inside sequences and arrays."""
    names: sequence[bounded_str[4]]
    pairs: sequence[sequence[int16, 2]]
    tags: array[bounded_str[3], 2]
    limited: sequence[sequence[str, 2], 3]


@dataclass
@appendable
class Large(IdlStruct, typename="Golden::Large"):
    blob: sequence[byte]
    text: str
    longs: sequence[int32]
    points: sequence[Point]


@dataclass
@mutable
class MutableNested(IdlStruct, typename="Golden::MutableNested"):
    inner: PointM
    maybe: Optional[PointM]
    list: sequence[PointM]
    grid: array[PointM, 2]
    tail: Optional[sequence[int64]]


MyLong = typedef["Golden::MyLong", int32]
Names = typedef["Golden::Names", sequence[str]]


@dataclass
@appendable
class Typedefs(IdlStruct, typename="Golden::Typedefs"):
    id: MyLong
    key("id")
    names: Names
    more: sequence[MyLong]


@dataclass
@final
class Chars(IdlStruct, typename="Golden::Chars"):
    cs: array[char, 3]
    flags: array[bool, 3]
    sc: sequence[char]
    ws: sequence[wchar]


@dataclass
@mutable
class BigIds(IdlStruct, typename="Golden::BigIds"):
    """Member ids at the edges of the XCDR1 short parameter id range and of the 28-bit id space."""
    low: uint8
    member_id("low", 0x3eff)
    edge: uint16
    member_id("edge", 0x3f00)
    over: int32
    member_id("over", 0x3f01)
    top: str
    member_id("top", 0x0ffffffe)


@dataclass
@mutable
class AllOptional(IdlStruct, typename="Golden::AllOptional"):
    a: Optional[int32]
    b: Optional[str]
    c: Optional[Point]


# ---------------------------------------------------------------- samples

def _prims(fill):
    if fill == "zero":
        return Primitives(b=False, o=0, i8=0, u8=0, c='\0', w=0, i16=0, u16=0, i32=0, u32=0, i64=0, u64=0,
                          f32=0.0, f64=0.0)
    if fill == "max":
        return Primitives(b=True, o=255, i8=127, u8=255, c='~', w=0x7fff, i16=32767, u16=65535, i32=I32_MAX,
                          u32=2**32 - 1, i64=I64_MAX, u64=2**64 - 1, f32=3.4028234663852886e38,
                          f64=1.7976931348623157e308)
    return Primitives(b=True, o=0x80, i8=-128, u8=1, c='A', w=0x20ac, i16=-32768, u16=1, i32=I32_MIN,
                      u32=0x80000000, i64=I64_MIN, u64=1, f32=-1.5, f64=-2.2250738585072014e-308)


P = Point
CORPUS: List[Tuple[type, List[Tuple[str, Any]]]] = [
    (Primitives, [("zero", _prims("zero")), ("max", _prims("max")), ("min", _prims("min"))]),
    (PrimitivesAppendable, [
        ("basic", PrimitivesAppendable(c='x', i64=-2, b=True, f64=0.5, u16=7, f32=0.25)),
        ("extremes", PrimitivesAppendable(c='\x7f', i64=I64_MAX, b=False, f64=-0.0, u16=65535, f32=1.1754943508222875e-38))]),  # f32: smallest normal, exact
    (PrimitivesMutable, [
        ("basic", PrimitivesMutable(b=True, o=0xab, i8=-5, c='m', w=0x3a9, i16=-300, u16=300, i32=-70000,
                                    u32=70000, i64=-(2**40), u64=2**40, f32=3.5, f64=-1e100)),
        ("zero", PrimitivesMutable(b=False, o=0, i8=0, c='\0', w=0, i16=0, u16=0, i32=0, u32=0, i64=0, u64=0,
                                   f32=0.0, f64=0.0))]),
    (Strings, [
        ("empty", Strings(s="", bs="", after=1, long_s="")),
        ("ascii", Strings(s="hello", bs="12345678", after=0xff, long_s="x" * 70)),
        ("utf8", Strings(s="héllo wörld ✓", bs="ñ", after=2, long_s="日本語のテキスト"))]),
    (StringsAppendable, [
        ("empty", StringsAppendable(s="", bs="", ss=[])),
        ("some", StringsAppendable(s="abc", bs="bounded", ss=["", "a", "bc", "def"]))]),
    (Alignment, [("basic", Alignment(a=1, b=-2, c=3, d=4.5, e=-6, f=7, g='g', h=-8))]),
]

for _ext in ("Final", "Appendable", "Mutable"):
    _g = globals()
    CORPUS += [
        (_g[f"{_ext}Plain"], [
            ("basic", _g[f"{_ext}Plain"](id=1, name="one", value=1.5, flag=True)),
            ("empty", _g[f"{_ext}Plain"](id=0, name="", value=0.0, flag=False))]),
        (_g[f"{_ext}Keyed"], [
            ("basic", _g[f"{_ext}Keyed"](id=42, name="answer", value=-0.125, flag=True)),
            ("min", _g[f"{_ext}Keyed"](id=I32_MIN, name="", value=0.0, flag=False))]),
        (_g[f"{_ext}Opt"], [
            ("all_set", _g[f"{_ext}Opt"](id=7, maybe_i=-1, name="n", maybe_s="opt", maybe_d=2.5, tail=9)),
            ("none_set", _g[f"{_ext}Opt"](id=8, maybe_i=None, name="", maybe_s=None, maybe_d=None, tail=0)),
            ("mixed", _g[f"{_ext}Opt"](id=9, maybe_i=None, name="mix", maybe_s="", maybe_d=None, tail=255))]),
        (_g[f"{_ext}KeyedOpt"], [
            ("all_set", _g[f"{_ext}KeyedOpt"](id=5, maybe_i=6, name="key", maybe_p=P(x=1, y=-1), tail=300)),
            ("none_set", _g[f"{_ext}KeyedOpt"](id=-5, maybe_i=None, name="k", maybe_p=None, tail=0))]),
    ]

CORPUS += [
    (Sequences, [
        ("empty", Sequences(longs=[], octets=[], bools=[], doubles=[], shorts=[], bounded=[], strings=[],
                            chars=[], u64s=[])),
        ("full", Sequences(longs=[1, -1, I32_MAX], octets=[0, 255, 7], bools=[True, False, True],
                           doubles=[0.5, -3.25], shorts=[-2, 3, 5], bounded=[I64_MIN, 0, 1, 2, I64_MAX],
                           strings=["", "x", "yz"], chars=['a', 'b'], u64s=[2**64 - 1]))]),
    (NestedSeqs, [
        ("empty", NestedSeqs(points=[], apoints=[], mpoints=[], seq_seq=[], seq_seq_str=[])),
        ("full", NestedSeqs(points=[P(x=1, y=2), P(x=-3, y=4)], apoints=[PointA(x=5, label="five")],
                            mpoints=[PointM(x=6, label="six"), PointM(x=7, label="")],
                            seq_seq=[[], [1], [2, 3]], seq_seq_str=[["a"], [], ["b", "cd"]]))]),
    (NestedSeqsAppendable, [
        ("full", NestedSeqsAppendable(points=[P(x=9, y=8)], seq_seq=[[1, 2, 3], []],
                                      apoints=[PointA(x=1, label="a"), PointA(x=2, label="")]))]),
    (Arrays, [
        ("zero", Arrays(longs=[0, 0, 0], octets=[0, 0, 0, 0], strs=["", ""], matrix=[[0, 0, 0], [0, 0, 0]],
                        cube=[[[0, 0], [0, 0]], [[0, 0], [0, 0]]], points=[P(x=0, y=0), P(x=0, y=0)],
                        doubles=[0.0, 0.0])),
        ("full", Arrays(longs=[1, -2, 3], octets=[1, 2, 3, 255], strs=["ab", "c"], matrix=[[1, 2, 3], [-4, -5, -6]],
                        cube=[[[1, 2], [3, 4]], [[5, 6], [7, 8]]], points=[P(x=1, y=2), P(x=3, y=4)],
                        doubles=[1.25, -1e-3]))]),
    (ArraysMutable, [
        ("full", ArraysMutable(longs=[7, 8, 9], strs=["x", ""], matrix=[[1, 2], [3, 4]],
                               apoints=[PointA(x=-1, label="m"), PointA(x=2, label="nn")], octets=[9, 8, 7]))]),
    (SeqOfArrays, [
        ("full", SeqOfArrays(rows=[[1, 2], [3, 4]], names=[["a", "b"], []])),
        ("empty", SeqOfArrays(rows=[], names=[[], []]))]),
    (UnionHolder, [
        ("cases", UnionHolder(id=1, e=UnionEnum(red=-7), c=UnionOctet(small=12), b=UnionBool(yes=5),
                              l=UnionLong(text="two"), el=UnionEnumLast(blue=-1.0), ll=UnionLongLast(text="t"))),
        ("more_cases", UnionHolder(id=2, e=UnionEnum(blue=0.5), c=UnionOctet(seq=[P(x=5, y=6)]),
                                   b=UnionBool(no="nope"), l=UnionLong(point=P(x=3, y=4)),
                                   el=UnionEnumLast(red=0), ll=UnionLongLast(point=P(x=-1, y=-2)))),
        # Default members selected. A default placed in the middle of the cases (UnionEnum, UnionLong) is
        # misread by libddsc 11.0.1 when selected, so the selected defaults here sit last (see README.md).
        ("defaults", UnionHolder(id=3, e=UnionEnum(red=1), c=UnionOctet(other=I64_MAX), b=UnionBool(no=""),
                                 l=UnionLong(text="x"),
                                 el=UnionEnumLast(discriminator=Color.GREEN, value="green"),
                                 ll=UnionLongLast(other=65535))),
        ("min_label", UnionHolder(id=4, e=UnionEnum(red=0), c=UnionOctet(small=0), b=UnionBool(yes=0),
                                  l=UnionLong(big=I64_MIN), el=UnionEnumLast(red=I32_MIN),
                                  ll=UnionLongLast(text="")))]),
    (UnionHolderAppendable, [
        ("p", UnionHolderAppendable(u=UnionAppendable(p=PointA(x=1, label="p")), o=UnionOctet(small=200),
                                    us=[UnionEnum(red=1), UnionEnum(blue=2.0)])),
        ("d", UnionHolderAppendable(u=UnionAppendable(d=-4.5), o=UnionOctet(seq=[P(x=1, y=1)]), us=[])),
        ("s", UnionHolderAppendable(u=UnionAppendable(s="str"), o=UnionOctet(other=-9),
                                    us=[UnionEnum(red=-1)]))]),
    (UnionHolderMutable, [
        ("set", UnionHolderMutable(e=UnionEnum(blue=1.0), a=UnionAppendable(s=""), maybe=UnionLong(text="t"))),
        ("unset", UnionHolderMutable(e=UnionEnum(red=3), a=UnionAppendable(d=0.0), maybe=None))]),
    (Enums, [
        ("first", Enums(c=Color.RED, s=Small.S0, m=Medium.M0, cs=[], ss=[], sa=[Small.S0, Small.S0, Small.S0])),
        ("last", Enums(c=Color.YELLOW, s=Small.S7, m=Medium.M300, cs=[Color.BLUE, Color.GREEN],
                       ss=[Small.S1, Small.S7], sa=[Small.S7, Small.S1, Small.S0]))]),
    (EnumsMutable, [
        ("set", EnumsMutable(c=Color.BLUE, s=Small.S7, m=Medium.M300, maybe=Small.S1)),
        ("unset", EnumsMutable(c=Color.RED, s=Small.S0, m=Medium.M1, maybe=None))]),
    (Bitmasks, [
        ("empty", Bitmasks(p=Perm8(read=False, write=False, exec=False), f16=Flags16(lo=False, hi=False),
                           f32=Flags32(a=False, b=False, top=False), f64=Flags64(first=False, mid=False, last=False),
                           ps=[])),
        ("all", Bitmasks(p=Perm8(read=True, write=True, exec=True), f16=Flags16(lo=True, hi=True),
                         f32=Flags32(a=True, b=True, top=True), f64=Flags64(first=True, mid=True, last=True),
                         ps=[Perm8(read=True, write=False, exec=True), Perm8(read=False, write=True, exec=False)]))]),
    (BitmasksAppendable, [
        ("some", BitmasksAppendable(f64=Flags64(first=False, mid=True, last=True),
                                    p=Perm8(read=False, write=True, exec=False), f16=Flags16(lo=True, hi=False)))]),
    (DerivedFinal, [
        ("basic", DerivedFinal(id=1, tag="base", extra=2.5, more=[1, 2])),
        ("empty", DerivedFinal(id=0, tag="", extra=0.0, more=[]))]),
    (DerivedAppendable, [
        ("set", DerivedAppendable(id=3, tag="t", extra=4, maybe=-5)),
        ("unset", DerivedAppendable(id=3, tag="t", extra=4, maybe=None))]),
    (DerivedMutable, [("basic", DerivedMutable(id=10, tag="ten", extra=11, note="eleven"))]),
    (BaseMutable, [("basic", BaseMutable(id=10, tag="ten"))]),
    (ExplicitIds, [
        ("set", ExplicitIds(a=1, b="b", c=-3, d=4.0, e=5, f=6)),
        ("unset", ExplicitIds(a=0, b="", c=0, d=0.0, e=None, f=0))]),
    (HashIds, [
        ("set", HashIds(alpha=1, beta="b", gamma=3, maybe=4)),
        ("unset", HashIds(alpha=-1, beta="", gamma=0, maybe=None))]),
    (AutoIdHash, [("basic", AutoIdHash(first=1, second="two", third=3.0, fixed=4))]),
    (ExplicitIdsAppendable, [
        ("set", ExplicitIdsAppendable(a=1, b="two", c=3)),
        ("unset", ExplicitIdsAppendable(a=1, b="two", c=None))]),
    (MustUnderstand, [
        ("set", MustUnderstand(id=1, critical=2, note="three", opt=4, plain=-5)),
        ("unset", MustUnderstand(id=1, critical=2, note="", opt=None, plain=0))]),
    (External, [
        ("set", External(id=1, p=P(x=2, y=3), s="ext", maybe=PointA(x=4, label="four"))),
        ("unset", External(id=0, p=P(x=0, y=0), s="", maybe=None))]),
    (ExternalMutable, [("basic", ExternalMutable(p=PointM(x=1, label="l"), ids=[1, 2, 3]))]),
]


def _deep(n):
    l6 = Level6(leaf=-n, note=f"leaf{n}")
    l5 = Level5(l6=l6, l6s=[Level6(leaf=n, note="")] * (n % 3))
    l4 = Level4(l5=l5, tag=n)
    l3 = Level3(k=n * 3, l4=l4)
    l2 = Level2(l3=l3, maybe=(l4 if n % 2 else None))
    l1 = Level1(id=n, l2=l2, l2s=[l2] * (n % 2))
    return Deep(l1=l1, trailer='t')


CORPUS += [
    (Deep, [("one", _deep(1)), ("two", _deep(2))]),
    (Level1, [("one", _deep(1).l1)]),
    (KeyNested, [("basic", KeyNested(location=P(x=-1, y=1), payload="data"))]),
    (KeyPartialNested, [("basic", KeyPartialNested(inner=KeyInner(a=1, ignored="not key", b=-2), data=[1, 2]))]),
    (KeyOrderMutable, [
        ("basic", KeyOrderMutable(z=-9, name="nm", value=4.0, a=1)),
        ("long_name", KeyOrderMutable(z=1, name="a name long enough to need md5", value=0.0, a=255))]),
    (KeyOrderAppendable, [("basic", KeyOrderAppendable(z=9, a=1, rest="r"))]),
    (KeyMultiFinal, [
        ("short", KeyMultiFinal(b=1, l=2, s="", v=1.0)),
        ("long", KeyMultiFinal(b=255, l=I64_MIN, s="twenty chars exactly", v=-1.0))]),
    (KeySmall, [("basic", KeySmall(k=0x01020304, v="v")), ("neg", KeySmall(k=-1, v=""))]),
    (KeyExactly16, [("basic", KeyExactly16(hi=0x0102030405060708, lo=0x090a0b0c0d0e0f10, v=1))]),
    (KeyBoundedString, [("empty", KeyBoundedString(name="", v=1)), ("full", KeyBoundedString(name="12345678", v=2))]),
    (KeyString, [("short", KeyString(name="k", v=1)), ("empty", KeyString(name="", v=0))]),
    (KeyArray, [("basic", KeyArray(ids=[1, -1, 256, -32768], v="arr"))]),
    (KeyEnum, [("basic", KeyEnum(c=Color.BLUE, s=Small.S7, v=3))]),
    (KeyAppendableNested, [("basic", KeyAppendableNested(inner=KeyAppendableInner(x=1, y=2), other=3))]),
    (KeyMutableNested, [("basic", KeyMutableNested(id=7, inner=KeyMutableInner(x=1, tag="tg", y=2)))]),
    (KeyAllPrims, [("basic", KeyAllPrims(b=True, o=2, c='c', i16=-4, u32=5, i64=-6, f64=7.5))]),
]

CORPUS += [
    (NestedBounds, [
        ("full", NestedBounds(names=["", "abcd"], pairs=[[1, 2], [], [-3]], tags=["abc", ""],
                              limited=[["a", "b"], [], ["c"]])),
        ("empty", NestedBounds(names=[], pairs=[], tags=["", ""], limited=[]))]),
    (Large, [("big", Large(blob=list(range(256)) * 4, text="0123456789" * 40, longs=list(range(-150, 150)),
                           points=[Point(x=i, y=-i) for i in range(70)]))]),
    (MutableNested, [
        ("set", MutableNested(inner=PointM(x=1, label="in"), maybe=PointM(x=2, label="opt"),
                              list=[PointM(x=3, label=""), PointM(x=4, label="four")],
                              grid=[PointM(x=5, label="g0"), PointM(x=6, label="g1")], tail=[I64_MIN, I64_MAX])),
        ("unset", MutableNested(inner=PointM(x=0, label=""), maybe=None, list=[],
                                grid=[PointM(x=0, label=""), PointM(x=0, label="")], tail=None))]),
    (Typedefs, [("basic", Typedefs(id=7, names=["x", "y"], more=[1, 2, 3]))]),
]


CORPUS += [
    (Chars, [("basic", Chars(cs=['a', 'b', 'c'], flags=[True, False, True], sc=['x', '\0'], ws=[0x41, 0x20ac, 0x7fff])),
             ("empty", Chars(cs=['\0', '\0', '\0'], flags=[False, False, False], sc=[], ws=[]))]),
    (BigIds, [("basic", BigIds(low=1, edge=2, over=3, top="top"))]),
    (AllOptional, [("none", AllOptional(a=None, b=None, c=None)),
                   ("all", AllOptional(a=1, b="b", c=Point(x=1, y=2)))]),
]


# Unions as topic types.
CORPUS += [
    (UnionLongLast, [("text", UnionLongLast(text="hello")), ("point", UnionLongLast(point=Point(x=1, y=2))),
                     ("default", UnionLongLast(other=9))]),
    (UnionAppendable, [("p", UnionAppendable(p=PointA(x=3, label="pa"))), ("d", UnionAppendable(d=2.5))]),
]


# Probes: byte strings whose acceptance by libddsc is itself the finding (recorded in manifest.json "probes").
PROBES = [
    (UnionHolder, "enum union default, discriminator 4 (the binding's rule: first non-enumerator)",
     UnionHolder(id=3, e=UnionEnum(red=1), c=UnionOctet(small=1), b=UnionBool(yes=1), l=UnionLong(text="x"),
                 el=UnionEnumLast(other="green"), ll=UnionLongLast(text="y"))),
    (UnionHolder, "enum union default, discriminator GREEN (first enumerator no label uses)",
     UnionHolder(id=3, e=UnionEnum(red=1), c=UnionOctet(small=1), b=UnionBool(yes=1), l=UnionLong(text="x"),
                 el=UnionEnumLast(discriminator=Color.GREEN, value="green"), ll=UnionLongLast(text="y"))),
    (UnionHolder, "default placed between the cases, selected (UnionLong, discriminator -1)",
     UnionHolder(id=3, e=UnionEnum(red=1), c=UnionOctet(small=1), b=UnionBool(yes=1), l=UnionLong(other=7),
                 el=UnionEnumLast(red=1), ll=UnionLongLast(text="y"))),
    (UnionHolder, "default placed last, selected (UnionLongLast, discriminator -1)",
     UnionHolder(id=3, e=UnionEnum(red=1), c=UnionOctet(small=1), b=UnionBool(yes=1), l=UnionLong(text="x"),
                 el=UnionEnumLast(red=1), ll=UnionLongLast(other=7))),
    (Enums, "XCDR1 with 4-byte @bit_bound enums (the binding's XCDR1 form)",
     Enums(c=Color.YELLOW, s=Small.S7, m=Medium.M300, cs=[Color.BLUE], ss=[Small.S1], sa=[Small.S7, Small.S1, Small.S0])),
]
