//! Writes the committed seed corpora under `fuzz/seeds/`: valid encodings of the `cdr_decode` types in every
//! version and byte order, a few RTPS datagrams built with the message builder, and the repository's IDL files.
//!
//! Run from `fuzz/`: `cargo run --example gen_seeds`.

use std::collections::BTreeMap;
use std::fs;
use std::path::Path;

use dds_fuzz::cdr::*;
use dds_runtime::cdr::{serialize, serialize_key, ByteOrder, DdsType, XcdrVersion};
use dds_runtime::rtps::messages::{Header, MessageBuilder};
use dds_runtime::xtypes::XTypesType;

const ENCODINGS: [(XcdrVersion, ByteOrder, &str); 4] = [
    (XcdrVersion::Xcdr1, ByteOrder::LittleEndian, "x1le"),
    (XcdrVersion::Xcdr1, ByteOrder::BigEndian, "x1be"),
    (XcdrVersion::Xcdr2, ByteOrder::LittleEndian, "x2le"),
    (XcdrVersion::Xcdr2, ByteOrder::BigEndian, "x2be"),
];

fn cdr_seeds<T: DdsType>(dir: &Path, sel: u8, name: &str, v: &T) {
    for (ver, order, tag) in ENCODINGS {
        let mut out = vec![sel];
        serialize(v, ver, order, &mut out).expect("seed encodes");
        fs::write(dir.join(format!("{name}-{tag}")), &out).unwrap();
        let mut key = vec![TYPE_COUNT - 1];
        if serialize_key(v, ver, order, &mut key).is_ok() {
            fs::write(dir.join(format!("{name}-key-{tag}")), &key).unwrap();
        }
    }
}

/// `durability_key` seeds: the type objects of `T` with a sample and a key-only payload in each encoding.
fn key_seeds<T: DdsType + XTypesType>(dir: &Path, name: &str, v: &T) {
    let mapping = &T::type_support().expect("describable").mapping_bytes;
    for (ver, order, tag) in ENCODINGS {
        let mut sample = Vec::new();
        serialize(v, ver, order, &mut sample).expect("seed encodes");
        let input = dds_fuzz::durability_key_input(mapping, true, &sample);
        assert_eq!(dds_fuzz::durability_key_hashes(&input), 2, "{name}-{tag}");
        fs::write(dir.join(format!("{name}-{tag}")), input).unwrap();
        let mut key = Vec::new();
        if serialize_key(v, ver, order, &mut key).is_ok() {
            let input = dds_fuzz::durability_key_input(mapping, false, &key);
            assert_eq!(
                dds_fuzz::durability_key_hashes(&input),
                2,
                "{name}-key-{tag}"
            );
            fs::write(dir.join(format!("{name}-key-{tag}")), input).unwrap();
        }
    }
}

fn main() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("seeds");
    let cdr = root.join("cdr_decode");
    fs::create_dir_all(&cdr).unwrap();

    let shape = ShapeType {
        color: "BLUE".into(),
        x: 10,
        y: -20,
        shapesize: 30,
        additional_payload_size: vec![1, 2, 3],
    };
    cdr_seeds(&cdr, 0, "shape", &shape);
    let inner = Inner {
        n: 7,
        tags: vec!["a".into(), "bc".into()],
    };
    let mo = MutOpt {
        id: 42,
        a: Some(-3),
        b: Some("hello".into()),
        c: u64::MAX,
        d: None,
        e: Some(Either::Text("t".into())),
        f: Kind::Gamma,
        g: [1, 2, 3],
        h: Some(inner.clone()),
    };
    cdr_seeds(&cdr, 1, "mutopt", &mo);
    let nest = Nest {
        vv: vec![vec![1, -2], vec![], vec![3]],
        vs: vec![vec!["x".into()], vec![]],
        m: BTreeMap::from([("k".to_string(), vec![1, 2]), ("l".to_string(), vec![])]),
        mi: BTreeMap::from([(-1, inner.clone())]),
        bounded: vec![Inner::default(), inner.clone()],
        u: vec![
            SmallUnion::Neg(5),
            SmallUnion::Nothing,
            SmallUnion::Other(true),
        ],
        arr: [[1, -1], [2, -2]],
        ch: 'é',
        flag: true,
    };
    cdr_seeds(&cdr, 2, "nest", &nest);
    let outer = Outer {
        shape,
        nest,
        m: Some(mo),
        u: Either::Bytes(vec![9; 5]),
        f: 1.5,
    };
    cdr_seeds(&cdr, 3, "outer", &outer);
    cdr_seeds(&cdr, 4, "either-num", &Either::Num(-1));
    cdr_seeds(&cdr, 4, "either-text", &Either::Text("abc".into()));

    let key = root.join("durability_key");
    fs::create_dir_all(&key).unwrap();
    // Without the unit union case: the derive encodes nothing for it, but `xtypes::dynamic`, going by the
    // derive's type objects, reads the default case's member there (FINDINGS.md).
    let mut outer_key = outer.clone();
    outer_key.nest.u.retain(|u| *u != SmallUnion::Nothing);
    key_seeds(&key, "shape", &outer_key.shape);
    key_seeds(&key, "mutopt", outer_key.m.as_ref().expect("set above"));
    key_seeds(&key, "nest", &outer_key.nest);
    key_seeds(&key, "outer", &outer_key);

    let rtps = root.join("rtps_decode");
    fs::create_dir_all(&rtps).unwrap();
    rtps_seeds(&rtps);

    let idl = root.join("idl_parse");
    fs::create_dir_all(&idl).unwrap();
    for f in ["shapes.idl", "ddsperf_types.idl"] {
        let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("../idl").join(f);
        fs::copy(&src, idl.join(f)).unwrap();
    }
    fs::write(idl.join("features.idl"), IDL_FEATURES).unwrap();

    dynamic_seeds(&cdr, &root.join("dynamic_decode"));
    let filter = root.join("filter_parse");
    fs::create_dir_all(&filter).unwrap();
    for (name, text) in FILTERS {
        fs::write(filter.join(name), text).unwrap();
    }
    let shm = root.join("shm_header");
    fs::create_dir_all(&shm).unwrap();
    shm_seeds(&shm);
}

/// Frames as a writer's channel carries them: a sample, a loaned sample (payload range), a change for one
/// reader, the end of a history, a liveliness assertion.
fn shm_seeds(dir: &Path) {
    use std::sync::Arc;

    use dds_runtime::rtps::shm::ShmChange;
    use dds_runtime::rtps::{
        ChangeKind, EntityId, Guid, GuidPrefix, Payload, SequenceNumber, Time, WriteChange,
    };

    let change = |kind, payload: &[u8]| WriteChange {
        kind,
        payload: Payload::copy_from_slice(payload),
        key_hash: Some([7; 16]),
        source_timestamp: Some(Time {
            seconds: 1_700_000_000,
            fraction: 42,
        }),
    };
    let sample = [0, 1, 0, 0, 5, 0, 0, 0, 1, 2, 3, 4];
    let w = EntityId([0, 0, 1, 0x02]);
    let c = |kind, sn| {
        ShmChange::new(
            w,
            SequenceNumber(sn),
            change(kind, &sample),
            Arc::from(Vec::new()),
            true,
        )
    };
    let frame = |c: &ShmChange| {
        let mut f = vec![0; c.frame_len()];
        c.write_frame(&mut f);
        f
    };
    fs::write(dir.join("alive"), frame(&c(ChangeKind::Alive, 1))).unwrap();
    fs::write(
        dir.join("dispose"),
        frame(&c(ChangeKind::DisposeUnregister, 9)),
    )
    .unwrap();
    let mut loaned = vec![0; 96];
    loaned[68..80].copy_from_slice(&sample);
    c(ChangeKind::Alive, 2).write_header_with(&mut loaned, Some(68..80));
    fs::write(dir.join("loaned"), loaned).unwrap();
    let mut targeted = c(ChangeKind::Alive, 3);
    targeted.target = Some(Guid::new(GuidPrefix([3; 12]), EntityId([0, 0, 2, 0x07])));
    fs::write(dir.join("targeted"), frame(&targeted)).unwrap();
    let mut end = targeted.clone();
    end.change.payload = Payload::default();
    end.history_end = true;
    fs::write(dir.join("history_end"), frame(&end)).unwrap();
    let mut alive = c(ChangeKind::Alive, 0);
    alive.change.payload = Payload::default();
    alive.liveliness = true;
    fs::write(dir.join("liveliness"), frame(&alive)).unwrap();
}

/// `dynamic_decode`: the `cdr_decode` seeds of selectors 0–4 (the same types), and for each type its type
/// objects with a payload, as a peer announces them (selector 5).
fn dynamic_seeds(cdr: &Path, dir: &Path) {
    fs::create_dir_all(dir).unwrap();
    for e in fs::read_dir(cdr).unwrap() {
        let e = e.unwrap();
        let bytes = fs::read(e.path()).unwrap();
        if bytes.first().is_some_and(|&s| s < TYPE_COUNT - 1) {
            fs::write(dir.join(e.file_name()), bytes).unwrap();
        }
    }
    fn announced<T: DdsType + XTypesType>(dir: &Path, name: &str, v: &T) {
        let s = T::type_support().expect("describable");
        let mut out = vec![5u8];
        for part in [&s.information_bytes, &s.mapping_bytes] {
            out.extend_from_slice(&(part.len() as u16).to_le_bytes());
            out.extend_from_slice(part);
        }
        serialize(v, XcdrVersion::Xcdr2, ByteOrder::LittleEndian, &mut out).unwrap();
        fs::write(dir.join(format!("announced-{name}")), out).unwrap();
    }
    announced(dir, "shape", &ShapeType::default());
    announced(
        dir,
        "inner",
        &Inner {
            n: 7,
            tags: vec!["a".into()],
        },
    );
    announced(dir, "either", &Either::Text("abc".into()));
}

/// `filter_parse`: expressions (first line) with parameters (the other lines) over `MutOpt`.
const FILTERS: [(&str, &str); 6] = [
    ("simple", "id > 10"),
    ("params", "b = %0 AND id BETWEEN %1 AND %2\nRED\n1\n100"),
    ("nested", "h.n = 7 OR h.tags[1] LIKE 'b%'"),
    ("enum", "f = 'Gamma' AND NOT (a < -1)"),
    ("union", "e.Text = 't' AND c >= 0"),
    ("order", "id > 0 ORDER BY c, id"),
];

fn rtps_seeds(dir: &Path) {
    use dds_runtime::rtps::messages::{Data, Heartbeat, ParameterList, Submessage};
    use dds_runtime::rtps::{EntityId, GuidPrefix, ProtocolVersion, SequenceNumber, VendorId};

    let header = Header {
        version: ProtocolVersion { major: 2, minor: 5 },
        vendor_id: VendorId([0x01, 0x10]),
        guid_prefix: GuidPrefix([1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12]),
    };
    // Inline QoS: a key hash (PID 0x0070) and the sentinel, little-endian.
    let mut qos = vec![0x70, 0x00, 16, 0];
    qos.extend_from_slice(&[0xab; 16]);
    let qlist = ParameterList {
        data: &qos,
        little_endian: true,
    };
    let payload = [
        0x00, 0x01, 0x00, 0x00, 4, 0, 0, 0, b'B', b'L', b'U', 0, 1, 0, 0, 0,
    ];
    let data = Submessage::Data(Data {
        reader_id: EntityId([0, 0, 0, 0]),
        writer_id: EntityId([0, 0, 1, 2]),
        writer_sn: SequenceNumber(7),
        inline_qos: Some(qlist),
        payload: Some(&payload),
        key_flag: false,
        non_standard_flag: false,
    });
    let hb = Submessage::Heartbeat(Heartbeat {
        reader_id: EntityId([0, 0, 0, 0]),
        writer_id: EntityId([0, 0, 1, 2]),
        first_sn: SequenceNumber(1),
        last_sn: SequenceNumber(7),
        count: 3,
        final_flag: false,
        liveliness_flag: false,
        group_info: None,
    });
    for (name, subs) in [
        ("data", vec![data]),
        ("heartbeat", vec![hb]),
        ("data-heartbeat", vec![data, hb]),
    ] {
        let mut b = MessageBuilder::new(&header);
        for s in &subs {
            b.push(s);
        }
        fs::write(dir.join(name), b.finish()).unwrap();
    }
}

const IDL_FEATURES: &str = r#"
#define N 4
module M {
  const long SIZE = N * 2;
  enum Color { RED, @value(5) GREEN, BLUE };
  @bit_bound(8) bitmask Flags { A, B };
  typedef sequence<long, SIZE> Longs;
  union U switch (Color) { case RED: long a; case GREEN: case BLUE: string<8> s; default: octet o; };
  @mutable struct Base { @key @id(3) long id; @optional string note; };
  @final struct Derived : Base { map<string, Longs> m; long arr[2][3]; U u; @external Base b; };
  bitset BS { bitfield<3> a; bitfield<5> b; };
};
"#;
