//! Fast paths: encoding into a reused `Vec` allocates nothing; decoding a string or a primitive sequence
//! allocates once; decoding into a reused sample allocates nothing; a hostile length allocates nothing.

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;

use dds_runtime::cdr::{deserialize, deserialize_into, serialize, ByteOrder, XcdrVersion};
use dds_runtime::DdsType;

struct Counting;

thread_local! {
    static COUNT: Cell<usize> = const { Cell::new(0) };
}

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, l: Layout) -> *mut u8 {
        let _ = COUNT.try_with(|c| c.set(c.get() + 1));
        unsafe { System.alloc(l) }
    }
    unsafe fn dealloc(&self, p: *mut u8, l: Layout) {
        unsafe { System.dealloc(p, l) }
    }
    unsafe fn realloc(&self, p: *mut u8, l: Layout, n: usize) -> *mut u8 {
        let _ = COUNT.try_with(|c| c.set(c.get() + 1));
        unsafe { System.realloc(p, l, n) }
    }
}

#[global_allocator]
static A: Counting = Counting;

fn allocations<R>(f: impl FnOnce() -> R) -> (usize, R) {
    let before = COUNT.with(Cell::get);
    let r = f();
    (COUNT.with(Cell::get) - before, r)
}

#[derive(DdsType, Debug, PartialEq)]
#[dds(mutable)]
struct Sample {
    #[dds(key)]
    id: u32,
    name: String,
    data: Vec<u32>,
    opt: Option<[u16; 3]>,
    nested: Vec<Vec<u8>>,
}

#[derive(DdsType, Debug, PartialEq)]
#[dds(final)]
struct Str {
    s: String,
}

#[derive(DdsType, Debug, PartialEq)]
#[dds(final)]
struct Prims {
    v: Vec<f64>,
}

#[test]
fn allocation_counts() {
    let s = Sample {
        id: 1,
        name: "hello".into(),
        data: (0..1000).collect(),
        opt: Some([1, 2, 3]),
        nested: vec![vec![1, 2], vec![3]],
    };
    let mut buf = Vec::with_capacity(8192);
    for version in [XcdrVersion::Xcdr1, XcdrVersion::Xcdr2] {
        for order in [ByteOrder::LittleEndian, ByteOrder::BigEndian] {
            buf.clear();
            let (n, r) = allocations(|| serialize(&s, version, order, &mut buf));
            r.unwrap();
            assert_eq!(
                n, 0,
                "encoding into a reused Vec allocated ({version:?} {order:?})"
            );
        }
    }
    for order in [ByteOrder::LittleEndian, ByteOrder::BigEndian] {
        buf.clear();
        serialize(
            &Str { s: "x".repeat(100) },
            XcdrVersion::Xcdr2,
            order,
            &mut buf,
        )
        .unwrap();
        let (n, r) = allocations(|| deserialize::<Str>(&buf));
        assert_eq!(r.unwrap().s.len(), 100);
        assert_eq!(n, 1, "a string decodes with one allocation");

        buf.clear();
        serialize(
            &Prims { v: vec![1.5; 500] },
            XcdrVersion::Xcdr1,
            order,
            &mut buf,
        )
        .unwrap();
        let (n, r) = allocations(|| deserialize::<Prims>(&buf));
        assert_eq!(r.unwrap().v.len(), 500);
        assert_eq!(n, 1, "a primitive sequence decodes with one allocation");
    }
    let mut hostile = vec![0x00, 0x01, 0x00, 0x00, 0x00, 0x00, 0x00, 0x80];
    hostile.resize(40, 0);
    let (n, r) = allocations(|| deserialize::<Prims>(&hostile));
    assert!(r.is_err());
    assert_eq!(n, 0, "a hostile length allocates nothing");
}

#[derive(DdsType, Debug, PartialEq, Clone)]
#[dds(appendable)]
struct Shape {
    #[dds(key, bound = 128)]
    color: String,
    x: i32,
    y: i32,
    names: Vec<String>,
    payload: Vec<u8>,
}

#[test]
fn decoding_into_a_reused_sample_allocates_nothing() {
    let shape = |i: i32| Shape {
        color: format!("COLOR{i}"),
        x: i,
        y: 2 * i,
        names: vec![format!("n{i}"), "m".into()],
        payload: vec![i as u8; 64],
    };
    let mut reused = shape(1000);
    let mut buf = Vec::with_capacity(1024);
    for version in [XcdrVersion::Xcdr1, XcdrVersion::Xcdr2] {
        for order in [ByteOrder::LittleEndian, ByteOrder::BigEndian] {
            for i in 0..10 {
                buf.clear();
                serialize(&shape(i), version, order, &mut buf).unwrap();
                let (n, r) = allocations(|| deserialize_into(&buf, &mut reused));
                r.unwrap();
                assert_eq!(reused, shape(i));
                assert_eq!(
                    n, 0,
                    "decoding into a reused sample allocated ({version:?} {order:?})"
                );
            }
        }
    }
}
