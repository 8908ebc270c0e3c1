//! Large types (ddsperf's Unkeyed64k and the nested Struct16 → Struct32k chain): they must round-trip, and a
//! debug build must encode and decode them within a 2 MiB thread stack. Release builds of these types used to
//! take minutes of LLVM time because every nested `default_value` was inlined into its callers.

use dds_runtime::cdr::{
    deserialize, deserialize_key, key_hash, serialize, serialize_key, ByteOrder, CdrType, DdsType,
    XcdrVersion,
};
use dds_runtime::DdsType;

#[derive(DdsType, Debug, Clone, PartialEq)]
#[dds(final)]
struct Unkeyed64k {
    seq: u32,
    baggage: [u8; 65532],
}

#[derive(DdsType, Debug, Clone, PartialEq, Default)]
#[dds(final)]
struct Struct16 {
    s0: u8,
    s1: u8,
    s2: u8,
    s3: u8,
    s4: u8,
    s5: u8,
    s6: u8,
    s7: u8,
    s8: u8,
    s9: u8,
    sa: u8,
    sb: u8,
    sc: u8,
    sd: u8,
    se: u8,
    sf: u8,
    junk: i64,
    seq: u32,
    #[dds(key)]
    keyval: u32,
}

/// A ddsperf aggregate: 16 (or 8) members of the next smaller size, then junk, seq and the key.
macro_rules! nested {
    ($name:ident, $inner:ty, $($f:ident),*) => {
        #[derive(DdsType, Debug, Clone, PartialEq, Default)]
        #[dds(final)]
        struct $name {
            $($f: $inner,)*
            junk: i64,
            seq: u32,
            #[dds(key)]
            keyval: u32,
        }
    };
}

nested!(Struct256, Struct16, a0, a1, a2, a3, a4, a5, a6, a7, a8, a9, aa, ab, ac, ad, ae, af);
nested!(Struct4k, Struct256, b0, b1, b2, b3, b4, b5, b6, b7, b8, b9, ba, bb, bc, bd, be, bf);
nested!(Struct32k, Struct4k, c0, c1, c2, c3, c4, c5, c6, c7);

const STACK: usize = 2 << 20;

/// Runs `f` on a thread with a 2 MiB stack (what a debug build of a user's reader thread may have).
fn on_small_stack(f: impl FnOnce() + Send + 'static) {
    std::thread::Builder::new()
        .stack_size(STACK)
        .spawn(f)
        .expect("spawn")
        .join()
        .expect("large-type thread panicked");
}

fn s16(k: u32) -> Struct16 {
    Struct16 {
        s0: k as u8,
        sf: 0xee,
        junk: -(i64::from(k)),
        seq: k * 3,
        keyval: k,
        ..Struct16::default()
    }
}

fn s256(k: u32) -> Struct256 {
    Struct256 {
        a0: s16(k),
        a7: s16(k + 1),
        af: s16(k + 2),
        junk: 7,
        seq: k,
        keyval: k + 100,
        ..Struct256::default()
    }
}

fn s4k(k: u32) -> Struct4k {
    Struct4k {
        b0: s256(k),
        bf: s256(k + 10),
        junk: 9,
        seq: k,
        keyval: k + 1000,
        ..Struct4k::default()
    }
}

#[test]
fn unkeyed64k_round_trips_on_a_2mib_stack() {
    on_small_stack(|| {
        let mut v = <Unkeyed64k as CdrType>::default_value();
        assert_eq!(v.baggage, [0u8; 65532]);
        v.seq = 42;
        for (i, b) in v.baggage.iter_mut().enumerate() {
            *b = (i * 7) as u8;
        }
        assert_eq!(Unkeyed64k::DEFAULT_VERSION, XcdrVersion::Xcdr1);
        for version in [XcdrVersion::Xcdr1, XcdrVersion::Xcdr2] {
            for order in [ByteOrder::LittleEndian, ByteOrder::BigEndian] {
                let mut out = Vec::new();
                serialize(&v, version, order, &mut out).unwrap();
                // Header, seq, then the baggage copied as it is; 65540 is a multiple of 4 (no padding).
                assert_eq!(out.len(), 4 + 4 + 65532);
                assert_eq!(&out[8..], &v.baggage[..]);
                assert_eq!(out[3] & 3, 0);
                let back: Unkeyed64k = deserialize(&out).unwrap();
                assert_eq!(back, v);
                // A truncated payload is an error, not a panic or a stack overflow.
                assert!(deserialize::<Unkeyed64k>(&out[..out.len() - 1]).is_err());
                // A type without keys has all its members in a key-only payload.
                let mut k = Vec::new();
                serialize_key(&v, version, order, &mut k).unwrap();
                assert_eq!(k, out);
                let kv: Unkeyed64k = deserialize_key(&k).unwrap();
                assert_eq!(kv, v);
            }
        }
    });
}

#[test]
fn struct32k_round_trips_on_a_2mib_stack() {
    on_small_stack(|| {
        let mut v = Struct32k {
            c0: s4k(1),
            c3: s4k(50),
            c7: s4k(90),
            junk: -1,
            seq: 77,
            keyval: 0xdead_beef,
            ..Struct32k::default()
        };
        v.c5.b9.a3.s4 = 0x55;
        assert_eq!(Struct32k::DEFAULT_VERSION, XcdrVersion::Xcdr1);
        // Struct16 is 32 bytes; each level adds junk, seq and keyval (16 bytes) and stays 8-aligned.
        let s256 = 16 * 32 + 16;
        let s4k = 16 * s256 + 16;
        let s32k = 8 * s4k + 16;
        assert_eq!(s32k, 67_728);
        for version in [XcdrVersion::Xcdr1, XcdrVersion::Xcdr2] {
            for order in [ByteOrder::LittleEndian, ByteOrder::BigEndian] {
                let mut out = Vec::new();
                serialize(&v, version, order, &mut out).unwrap();
                assert_eq!(out.len(), 4 + s32k, "{version:?} {order:?}");
                let back: Struct32k = deserialize(&out).unwrap();
                assert_eq!(back, v);
                assert!(deserialize::<Struct32k>(&out[..out.len() - 4]).is_err());

                // Key-only: only Struct32k's own key travels, everything else decodes to defaults.
                let mut k = Vec::new();
                serialize_key(&v, version, order, &mut k).unwrap();
                assert_eq!(k.len(), 8);
                let kv: Struct32k = deserialize_key(&k).unwrap();
                assert_eq!(
                    kv,
                    Struct32k {
                        keyval: 0xdead_beef,
                        ..Struct32k::default()
                    }
                );
            }
            let h = key_hash(&v, version).unwrap();
            assert_eq!(&h[..4], &0xdead_beef_u32.to_be_bytes());
            assert_eq!(&h[4..], &[0u8; 12]);
        }
    });
}

/// Decoding alone leaves a margin: a debug build decodes each type on a 1 MiB stack, half the 2 MiB above.
#[test]
fn decoding_large_types_fits_in_1mib_of_debug_stack() {
    let mut s32k = Vec::new();
    let v = Box::new(<Struct32k as CdrType>::default_value());
    serialize(&*v, XcdrVersion::Xcdr2, ByteOrder::LittleEndian, &mut s32k).unwrap();
    let mut u64k = Vec::new();
    let u = Box::new(<Unkeyed64k as CdrType>::default_value());
    serialize(&*u, XcdrVersion::Xcdr1, ByteOrder::BigEndian, &mut u64k).unwrap();
    // One thread per type: the test's own temporaries (each a full copy of a sample) stay small.
    let a = std::thread::Builder::new()
        .stack_size(1 << 20)
        .spawn(move || deserialize::<Struct32k>(&s32k).map(|v| v.keyval))
        .unwrap()
        .join()
        .expect("Struct32k decode thread");
    assert_eq!(a, Ok(0));
    let b = std::thread::Builder::new()
        .stack_size(1 << 20)
        .spawn(move || deserialize::<Unkeyed64k>(&u64k).map(|v| v.baggage[65531]))
        .unwrap()
        .join()
        .expect("Unkeyed64k decode thread");
    assert_eq!(b, Ok(0));
}
