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
