//! The XCDR rules one by one, with hand-computed bytes.

use std::collections::BTreeMap;

use dds_runtime::cdr::{
    deserialize, serialize, BoundedSeq, BoundedString, ByteOrder, CdrType, DdsType,
    DecodeErrorKind, EncodeError, Extensibility, LongDouble, WChar, WString, XcdrVersion,
};
use dds_runtime::DdsType;

use ByteOrder::{BigEndian as BE, LittleEndian as LE};
use XcdrVersion::{Xcdr1, Xcdr2};

fn hex(s: &str) -> Vec<u8> {
    s.split_whitespace()
        .map(|b| u8::from_str_radix(b, 16).unwrap())
        .collect()
}

fn enc<T: DdsType>(v: &T, version: XcdrVersion, order: ByteOrder) -> Vec<u8> {
    let mut out = Vec::new();
    serialize(v, version, order, &mut out).unwrap();
    out
}

/// Encodes, compares the full payload (header included) and decodes back.
fn check<T: DdsType + PartialEq + std::fmt::Debug>(
    v: &T,
    version: XcdrVersion,
    order: ByteOrder,
    expected: &str,
) {
    let out = enc(v, version, order);
    assert_eq!(out, hex(expected), "{version:?} {order:?}");
    assert_eq!(&deserialize::<T>(&out).unwrap(), v);
}

fn roundtrip_all<T: DdsType + PartialEq + std::fmt::Debug>(v: &T) {
    for version in [Xcdr1, Xcdr2] {
        for order in [LE, BE] {
            let out = enc(v, version, order);
            assert_eq!(&deserialize::<T>(&out).unwrap(), v, "{version:?} {order:?}");
        }
    }
}

#[derive(DdsType, Debug, PartialEq)]
#[dds(final)]
struct Tiny {
    a: u8,
}

#[test]
fn header_carries_padding_count() {
    check(&Tiny { a: 1 }, Xcdr2, LE, "00 07 00 03 01 00 00 00");
    check(&Tiny { a: 1 }, Xcdr1, BE, "00 00 00 03 01 00 00 00");
    // Unpadded input is accepted too.
    assert_eq!(
        deserialize::<Tiny>(&hex("00 07 00 00 01")).unwrap(),
        Tiny { a: 1 }
    );
    assert_eq!(Tiny::DEFAULT_VERSION, Xcdr1);
}

#[derive(DdsType, Debug, PartialEq)]
#[dds(final)]
struct Wide {
    c: char,
    wc: WChar,
    ws: WString,
}

#[test]
fn wchar_and_wstring_are_utf16_with_a_byte_count() {
    let v = Wide {
        c: 'é',
        wc: WChar(0x20ac),
        ws: WString::from("hé"),
    };
    // char8 Latin-1, wchar 2 bytes, wstring: u32 byte count then UTF-16, no terminator; same in XCDR1 and 2.
    check(
        &v,
        Xcdr1,
        LE,
        "00 01 00 00 e9 00 ac 20 04 00 00 00 68 00 e9 00",
    );
    check(
        &v,
        Xcdr2,
        BE,
        "00 06 00 00 e9 00 20 ac 00 00 00 04 00 68 00 e9",
    );
    let bad = Wide {
        c: '€',
        wc: WChar(0),
        ws: WString::default(),
    };
    let mut out = Vec::new();
    assert!(matches!(
        serialize(&bad, Xcdr2, LE, &mut out),
        Err(EncodeError::InvalidValue { .. })
    ));
    assert!(
        out.is_empty(),
        "a failed encode leaves the buffer as it was"
    );
    // Unpaired surrogate.
    let e = deserialize::<Wide>(&hex("00 07 00 00 41 00 00 00 02 00 00 00 00 d8")).unwrap_err();
    assert_eq!(e.kind, DecodeErrorKind::MalformedString);
    assert_eq!(e.offset, 12);
}

#[derive(DdsType, Debug, PartialEq)]
#[dds(final)]
struct LongD {
    a: u8,
    l: LongDouble,
}

#[test]
fn long_double_is_16_bytes_aligned_like_a_double() {
    let mut b = [0u8; 16];
    b[0] = 0x40;
    b[15] = 0x01;
    let v = LongD {
        a: 1,
        l: LongDouble(b),
    };
    check(
        &v,
        Xcdr1,
        BE,
        "00 00 00 00 01 00 00 00 00 00 00 00 40 00 00 00 00 00 00 00 00 00 00 00 00 00 00 01",
    );
    check(
        &v,
        Xcdr2,
        LE,
        "00 07 00 00 01 00 00 00 01 00 00 00 00 00 00 00 00 00 00 00 00 00 00 40",
    );
}

#[derive(DdsType, Debug, PartialEq)]
#[dds(final)]
struct Arrays {
    m: [[i16; 3]; 2],
    s: [[String; 2]; 2],
}

#[test]
fn multi_dimensional_arrays_have_one_dheader() {
    let v = Arrays {
        m: [[1, 2, 3], [4, 5, 6]],
        s: [["a".into(), "b".into()], ["c".into(), "d".into()]],
    };
    check(
        &v,
        Xcdr2,
        LE,
        "00 07 00 02 01 00 02 00 03 00 04 00 05 00 06 00 \
         1e 00 00 00 02 00 00 00 61 00 00 00 02 00 00 00 62 00 00 00 02 00 00 00 63 00 00 00 02 00 00 00 64 00 00 00",
    );
    check(
        &v,
        Xcdr1,
        BE,
        "00 00 00 02 00 01 00 02 00 03 00 04 00 05 00 06 \
         00 00 00 02 61 00 00 00 00 00 00 02 62 00 00 00 00 00 00 02 63 00 00 00 00 00 00 02 64 00 00 00",
    );
}

#[derive(DdsType, Debug, PartialEq)]
#[dds(appendable)]
struct Big {
    tag: u8,
    #[dds(default = [7u8; 65532])]
    data: [u8; 65532],
    words: [u32; 40],
}

#[test]
fn arrays_of_any_length_and_their_defaults() {
    let mut v = Big {
        tag: 3,
        data: [0; 65532],
        words: [9; 40],
    };
    v.data[65531] = 0xff;
    roundtrip_all(&v);
    let d = <Big as CdrType>::default_value();
    assert_eq!(d.data[100], 7);
    assert_eq!(d.words, [0; 40]);
    // An appendable sample that stops after `tag` takes the declared default.
    let short = deserialize::<Big>(&hex("00 09 00 00 01 00 00 00 05")).unwrap();
    assert_eq!((short.tag, short.data[0], short.words[0]), (5, 7, 0));
}

#[derive(DdsType, Debug, PartialEq)]
#[dds(final)]
struct Maps {
    p: BTreeMap<u16, u16>,
    s: BTreeMap<u32, String>,
}

#[test]
fn maps_count_entries_and_take_a_dheader_when_not_primitive() {
    let v = Maps {
        p: BTreeMap::from([(1, 2)]),
        s: BTreeMap::from([(3, "x".to_owned())]),
    };
    check(&v, Xcdr2, LE, "00 07 00 02 01 00 00 00 01 00 02 00 0e 00 00 00 01 00 00 00 03 00 00 00 02 00 00 00 78 00 00 00");
    check(
        &v,
        Xcdr1,
        LE,
        "00 01 00 02 01 00 00 00 01 00 02 00 01 00 00 00 03 00 00 00 02 00 00 00 78 00 00 00",
    );
}

#[derive(DdsType, Debug, PartialEq)]
#[dds(final)]
struct Bounded {
    #[dds(bound = 3)]
    s: String,
    #[dds(bound = 2)]
    v: Vec<u8>,
    bs: Vec<BoundedString<2>>,
    bq: BoundedSeq<i32, 1>,
}

#[test]
fn bounds_are_enforced_on_write_and_read() {
    let ok = Bounded {
        s: "abc".into(),
        v: vec![1, 2],
        bs: vec![BoundedString::from("xy")],
        bq: BoundedSeq(vec![5]),
    };
    roundtrip_all(&ok);
    let cases = [
        Bounded {
            s: "abcd".into(),
            ..clone_b(&ok)
        },
        Bounded {
            v: vec![1, 2, 3],
            ..clone_b(&ok)
        },
        Bounded {
            bs: vec![BoundedString::from("xyz")],
            ..clone_b(&ok)
        },
        Bounded {
            bq: BoundedSeq(vec![1, 2]),
            ..clone_b(&ok)
        },
    ];
    for c in &cases {
        let mut out = Vec::new();
        assert!(matches!(
            serialize(c, Xcdr2, LE, &mut out),
            Err(EncodeError::BoundExceeded { .. })
        ));
    }
    // A peer that ignores the bound: "abcd" where string<3> is expected.
    #[derive(DdsType, Debug, PartialEq)]
    #[dds(final)]
    struct Loose {
        s: String,
    }
    let bytes = enc(&Loose { s: "abcd".into() }, Xcdr2, LE);
    #[derive(DdsType, Debug, PartialEq)]
    #[dds(final)]
    struct Tight {
        #[dds(bound = 3)]
        s: String,
    }
    let e = deserialize::<Tight>(&bytes).unwrap_err();
    assert_eq!(e.kind, DecodeErrorKind::BoundExceeded { bound: 3, len: 4 });
    assert_eq!(e.offset, 4);
}

fn clone_b(b: &Bounded) -> Bounded {
    Bounded {
        s: b.s.clone(),
        v: b.v.clone(),
        bs: b.bs.clone(),
        bq: b.bq.clone(),
    }
}

#[derive(DdsType, Debug, PartialEq, Clone)]
#[dds(appendable)]
struct Base {
    #[dds(key)]
    id: u32,
    a: u8,
}

#[derive(DdsType, Debug, PartialEq, Clone)]
#[dds(appendable)]
struct Derived {
    #[dds(base)]
    base: Base,
    b: u16,
}

#[derive(DdsType, Debug, PartialEq, Clone)]
#[dds(mutable)]
struct MBase {
    x: u8,
    y: u8,
}

#[derive(DdsType, Debug, PartialEq, Clone)]
#[dds(mutable)]
struct MDerived {
    #[dds(base)]
    base: MBase,
    z: u8,
}

#[test]
fn inheritance_puts_base_members_first_in_one_frame() {
    let v = Derived {
        base: Base { id: 1, a: 2 },
        b: 3,
    };
    check(
        &v,
        Xcdr2,
        LE,
        "00 09 00 00 08 00 00 00 01 00 00 00 02 00 03 00",
    );
    const { assert!(Derived::IS_KEYED) };
    let v = MDerived {
        base: MBase { x: 1, y: 2 },
        z: 3,
    };
    // Member ids continue after the base's: x=0, y=1, z=2.
    check(&v, Xcdr2, LE, "00 0b 00 03 15 00 00 00 00 00 00 00 01 00 00 00 01 00 00 00 02 00 00 00 02 00 00 00 03 00 00 00");
}

#[derive(DdsType, Debug, PartialEq, Clone)]
#[dds(appendable)]
struct Node {
    value: i32,
    children: Vec<Node>,
    #[dds(external)]
    next: Option<Box<Node>>,
}

#[test]
fn recursion_through_sequences_and_external_members() {
    let v = Node {
        value: 1,
        children: vec![Node {
            value: 2,
            children: vec![],
            next: None,
        }],
        next: Some(Box::new(Node {
            value: 3,
            children: vec![],
            next: None,
        })),
    };
    roundtrip_all(&v);
    assert_eq!(Node::DEFAULT_VERSION, Xcdr2);
}

#[derive(DdsType, Debug, PartialEq)]
#[dds(appendable, name = "Evolving")]
struct V1 {
    a: u8,
}

#[derive(DdsType, Debug, PartialEq)]
#[dds(appendable, name = "Evolving")]
struct V2 {
    a: u8,
    #[dds(default = 7)]
    b: u32,
}

#[test]
fn appendable_types_evolve_at_the_end() {
    let old = enc(&V1 { a: 1 }, Xcdr2, LE);
    assert_eq!(deserialize::<V2>(&old).unwrap(), V2 { a: 1, b: 7 });
    let new = enc(&V2 { a: 1, b: 9 }, Xcdr2, BE);
    assert_eq!(deserialize::<V1>(&new).unwrap(), V1 { a: 1 });
}

#[derive(DdsType, Debug, PartialEq)]
#[dds(mutable, name = "Mut")]
struct M1 {
    a: u8,
}

#[derive(DdsType, Debug, PartialEq)]
#[dds(mutable, name = "Mut")]
struct M2 {
    a: u8,
    b: u32,
}

#[derive(DdsType, Debug, PartialEq)]
#[dds(mutable, name = "Mut")]
struct M2Mu {
    a: u8,
    #[dds(must_understand)]
    b: u32,
}

#[test]
fn mutable_types_skip_unknown_members_unless_must_understand() {
    for version in [Xcdr1, Xcdr2] {
        let bytes = enc(&M2 { a: 1, b: 2 }, version, LE);
        assert_eq!(deserialize::<M1>(&bytes).unwrap(), M1 { a: 1 });
        let bytes = enc(&M2Mu { a: 1, b: 2 }, version, LE);
        let e = deserialize::<M1>(&bytes).unwrap_err();
        assert_eq!(e.kind, DecodeErrorKind::UnknownMustUnderstand { id: 1 });
        // Members missing from the sample get defaults.
        let bytes = enc(&M1 { a: 4 }, version, BE);
        assert_eq!(deserialize::<M2>(&bytes).unwrap(), M2 { a: 4, b: 0 });
    }
    // The must-understand flag is on the wire.
    assert_eq!(
        enc(&M2Mu { a: 1, b: 2 }, Xcdr2, BE)[16..20],
        [0xa0, 0, 0, 1]
    );
}

#[test]
fn readers_accept_every_length_code_and_short_parameter_headers() {
    // LC 4 (NEXTINT) around a u32 that Cyclone would give LC 2, and LC 3 for a u8 padded to 8 bytes.
    let lc4 = hex("00 0b 00 00 18 00 00 00 00 00 00 30 01 00 00 00 00 00 00 00 01 00 00 40 04 00 00 00 2a 00 00 00");
    assert_eq!(deserialize::<M2>(&lc4).unwrap(), M2 { a: 1, b: 42 });
    // XCDR1 short parameter header (id < 0x3f00), PID_IGNORE, and a list end without the M bit.
    let short =
        hex("00 03 00 00 03 3f 00 00 00 00 04 00 07 00 00 00 01 00 04 00 2a 00 00 00 02 3f 00 00");
    assert_eq!(deserialize::<M2>(&short).unwrap(), M2 { a: 7, b: 42 });
}

#[derive(DdsType, Debug, PartialEq)]
#[dds(appendable)]
struct AppOpt {
    a: Option<u16>,
    #[dds(bound = 4)]
    b: Option<String>,
}

#[test]
fn optional_members_in_appendable_types() {
    let v = AppOpt {
        a: None,
        b: Some("hi".into()),
    };
    check(
        &v,
        Xcdr2,
        LE,
        "00 09 00 01 0b 00 00 00 00 01 00 00 03 00 00 00 68 69 00 00",
    );
    check(
        &v,
        Xcdr1,
        LE,
        "00 01 00 00 01 7f 08 00 00 00 00 00 00 00 00 00 01 7f 08 00 01 00 00 00 08 00 00 00 03 00 00 00 68 69 00 00",
    );
    let v = AppOpt {
        a: Some(3),
        b: None,
    };
    roundtrip_all(&v);
    let mut out = Vec::new();
    assert!(serialize(
        &AppOpt {
            a: None,
            b: Some("hello".into())
        },
        Xcdr1,
        LE,
        &mut out
    )
    .is_err());
}

#[derive(DdsType, Debug, PartialEq, Clone, Copy)]
enum Color {
    Red = 3,
    #[dds(value = 10)]
    Green,
    Blue,
}

#[test]
fn enumerator_values_and_unknown_values() {
    #[derive(DdsType, Debug, PartialEq)]
    #[dds(final)]
    struct C {
        c: Color,
    }
    check(&C { c: Color::Blue }, Xcdr2, BE, "00 06 00 00 00 00 00 0b");
    check(&C { c: Color::Red }, Xcdr1, LE, "00 01 00 00 03 00 00 00");
    let e = deserialize::<C>(&hex("00 07 00 00 04 00 00 00")).unwrap_err();
    assert_eq!(
        (e.offset, e.kind.clone()),
        (4, DecodeErrorKind::InvalidValue { found: 4 })
    );
    assert!(e.to_string().contains("enumerator"), "{e}");
    assert_eq!(<Color as CdrType>::default_value(), Color::Red);
}

#[derive(DdsType, Debug, PartialEq)]
#[dds(final, discriminator = bool)]
enum ByBool {
    #[dds(case = true)]
    Yes(u8),
    #[dds(default)]
    No(u16),
}

#[derive(DdsType, Debug, PartialEq)]
#[dds(final, discriminator = u8)]
enum ByOctet {
    // A unit variant would have no type object beside the default case (the derive refuses it).
    #[dds(case = 0)]
    Zero(u8),
    #[dds(case = 1, case = 2)]
    Small(u16),
    #[dds(default)]
    Other(i32),
}

#[derive(DdsType, Debug, PartialEq)]
#[dds(final, discriminator = char)]
enum ByChar {
    #[dds(case = 'a')]
    A(u8),
    #[dds(default)]
    Other(u8),
}

#[derive(DdsType, Debug, PartialEq)]
#[dds(mutable, discriminator = i32)]
enum MutUnion {
    #[dds(case = 1)]
    One(u8),
    #[dds(case = 2, id = 9)]
    Two(String),
}

#[test]
fn union_discriminators_and_defaults() {
    #[derive(DdsType, Debug, PartialEq)]
    #[dds(final)]
    struct All {
        b: ByBool,
        o: ByOctet,
        o2: ByOctet,
        c: ByChar,
    }
    let v = All {
        b: ByBool::No(5),
        o: ByOctet::Zero(7),
        o2: ByOctet::Other(-1),
        c: ByChar::Other(1),
    };
    // bool default: false (true is used); u8: 0 and 1, 2 used -> 3; char: 0.
    check(
        &v,
        Xcdr2,
        LE,
        "00 07 00 02 00 00 05 00 00 07 03 00 ff ff ff ff 00 01 00 00",
    );
    let v = All {
        b: ByBool::Yes(1),
        o: ByOctet::Small(2),
        o2: ByOctet::Zero(0),
        c: ByChar::A(2),
    };
    roundtrip_all(&v);
    // Mutable unions: discriminator as member 0, the case with its own id.
    #[derive(DdsType, Debug, PartialEq)]
    #[dds(final)]
    struct HasMut {
        u: MutUnion,
    }
    let v = HasMut {
        u: MutUnion::Two("z".into()),
    };
    check(
        &v,
        Xcdr2,
        LE,
        "00 07 00 02 12 00 00 00 00 00 00 a0 02 00 00 00 09 00 00 50 02 00 00 00 7a 00 00 00",
    );
    roundtrip_all(&v);
}

mod rt {
    pub(crate) use dds_runtime::*;
}

#[derive(DdsType, Debug, PartialEq)]
#[dds(crate = "crate::rt", final, name = "Mod::Renamed")]
struct ViaAlias {
    #[dds(non_serialized)]
    cache: Vec<u8>,
    #[dds(hashid)]
    x: u32,
    #[dds(hashid = "other", name = "wire_y")]
    y: u32,
}

#[test]
fn metadata_crate_override_hashid_and_non_serialized() {
    assert_eq!(ViaAlias::TYPE_NAME, "Mod::Renamed");
    assert_eq!(ViaAlias::EXTENSIBILITY, Extensibility::Final);
    let d = ViaAlias::type_descriptor();
    // MD5("x") = 9dd4e461..., little-endian and masked to 28 bits.
    assert_eq!(d.members[0].id, 0x01e4_d49d);
    assert_eq!(d.members[1].name, "wire_y");
    let v = ViaAlias {
        cache: vec![1],
        x: 1,
        y: 2,
    };
    let out = enc(&v, Xcdr1, LE);
    assert_eq!(out, hex("00 01 00 00 01 00 00 00 02 00 00 00"));
    assert_eq!(
        deserialize::<ViaAlias>(&out).unwrap(),
        ViaAlias {
            cache: vec![],
            x: 1,
            y: 2
        }
    );
}

#[derive(DdsType, Debug, PartialEq)]
#[dds(final)]
struct FinalWithAppendable {
    inner: V1,
}

#[test]
fn default_version_follows_cyclone() {
    assert_eq!(Tiny::DEFAULT_VERSION, Xcdr1);
    assert_eq!(FinalWithAppendable::DEFAULT_VERSION, Xcdr2);
    assert_eq!(V1::DEFAULT_VERSION, Xcdr2);
    assert_eq!(Color::DEFAULT_VERSION, Xcdr1);
}

#[test]
fn errors_say_where_and_what() {
    let e = deserialize::<M2>(&hex("00 0b 00 00 18 00 00")).unwrap_err();
    assert_eq!(e.offset, 4);
    assert_eq!(e.expected, "DHEADER");
    let e = deserialize::<Tiny>(&hex("00 42 00 00 01")).unwrap_err();
    assert_eq!(
        (e.offset, e.kind),
        (0, DecodeErrorKind::InvalidValue { found: 0x42 })
    );
    let e = deserialize::<Tiny>(&hex("00 01")).unwrap_err();
    assert!(
        e.to_string()
            .starts_with("at offset 0: expected encapsulation header"),
        "{e}"
    );
}

#[derive(DdsType, Debug, PartialEq, Clone, Copy, Default)]
#[dds(bit_bound = 16)]
enum Signed {
    Low = -32000,
    #[default]
    Zero = 0,
    High = 40000,
}

#[derive(DdsType, Debug, PartialEq)]
#[dds(final, discriminator = WChar)]
enum ByWChar {
    #[dds(case = 'a')]
    A(u8),
    #[dds(default)]
    Other(u16),
}

#[test]
fn negative_enumerators_and_wchar_labels() {
    #[derive(DdsType, Debug, PartialEq)]
    #[dds(final)]
    struct H {
        s: Signed,
        t: Signed,
        w: ByWChar,
    }
    // -32000 as a 16-bit two's complement value; 40000 fits the unsigned range of the bound.
    let v = H {
        s: Signed::Low,
        t: Signed::High,
        w: ByWChar::A(7),
    };
    check(&v, Xcdr1, BE, "00 00 00 01 83 00 9c 40 00 61 07 00");
    check(&v, Xcdr2, LE, "00 07 00 01 00 83 40 9c 61 00 07 00");
    assert_eq!(<Signed as CdrType>::default_value(), Signed::Zero);
    let v = H {
        s: Signed::Zero,
        t: Signed::Zero,
        w: ByWChar::Other(1),
    };
    check(&v, Xcdr2, LE, "00 07 00 00 00 00 00 00 00 00 01 00");
}
