//! `cdr::serialize` into a buffer that already has capacity allocates nothing (docs/architecture.md), for every
//! benchmark type, in both versions and byte orders. Counted with a global allocator wrapper.
//!
//! Run: `cargo test -p dds-benches --test encode_alloc` (dds-benches is not a default member).

#[path = "../benches/common/mod.rs"]
mod common;

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;

use common::*;
use dds_runtime::cdr::{self, ByteOrder, DdsType, XcdrVersion};

struct Counting;

thread_local! {
    // Per thread, so the test harness's other threads cannot disturb a measurement.
    static ALLOCS: Cell<u64> = const { Cell::new(0) };
}

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        ALLOCS.with(|c| c.set(c.get() + 1));
        System.alloc(layout)
    }
    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        ALLOCS.with(|c| c.set(c.get() + 1));
        System.alloc_zeroed(layout)
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        ALLOCS.with(|c| c.set(c.get() + 1));
        System.realloc(ptr, layout, new_size)
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        System.dealloc(ptr, layout)
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

fn allocs() -> u64 {
    ALLOCS.with(Cell::get)
}

/// Encodes `v` once to size the buffer, then 100 more times into it; returns the allocations of those 100.
fn steady_state_allocs<T: DdsType>(v: &T, version: XcdrVersion, order: ByteOrder) -> u64 {
    let mut buf = Vec::new();
    cdr::serialize(v, version, order, &mut buf).unwrap();
    let len = buf.len();
    let before = allocs();
    for _ in 0..100 {
        buf.clear();
        cdr::serialize(std::hint::black_box(v), version, order, &mut buf).unwrap();
    }
    let n = allocs() - before;
    assert_eq!(buf.len(), len, "same value, same length");
    n
}

fn check<T: DdsType>(name: &str, v: &T) {
    for version in [XcdrVersion::Xcdr1, XcdrVersion::Xcdr2] {
        for order in [ByteOrder::LittleEndian, ByteOrder::BigEndian] {
            let n = steady_state_allocs(v, version, order);
            assert_eq!(
                n, 0,
                "{name} {version:?} {order:?}: {n} allocations in 100 encodes into a reused buffer"
            );
        }
    }
}

#[test]
fn counter_sees_allocations() {
    // The check below is only meaningful if the counter works.
    let before = allocs();
    let v: Vec<u8> = std::hint::black_box(Vec::with_capacity(10));
    drop(v);
    assert!(allocs() > before);
}

#[test]
fn shape_encode_allocates_nothing() {
    check("ShapeType", &shape());
}

#[test]
fn octets_1k_encode_allocates_nothing() {
    check("KeyedSeq 1 KiB", &keyed_seq_1k());
}

#[test]
fn nested_encode_allocates_nothing() {
    check("Telemetry", &telemetry());
}

#[test]
fn wide_mutable_encode_allocates_nothing() {
    check("Wide (mutable)", &wide());
}

#[test]
fn instance_key_into_reused_buffer_allocates_nothing() {
    // The writer computes this per sample too.
    let v = shape();
    let mut ik = Vec::new();
    cdr::instance_key(&v, &mut ik).unwrap();
    let before = allocs();
    for _ in 0..100 {
        ik.clear();
        cdr::instance_key(std::hint::black_box(&v), &mut ik).unwrap();
    }
    assert_eq!(allocs() - before, 0);
}

#[test]
fn key_hash_allocates_at_most_once_per_call() {
    // key_hash has no buffer argument; for keys that may exceed 16 bytes (MD5 path) it currently builds the key
    // stream in a fresh Vec: one allocation per call (see FINDINGS.md). This pins that it does not get worse.
    let v = shape();
    let before = allocs();
    for _ in 0..100 {
        std::hint::black_box(cdr::key_hash(std::hint::black_box(&v), XcdrVersion::Xcdr2).unwrap());
    }
    let n = allocs() - before;
    assert!(n <= 100, "{n} allocations in 100 key_hash calls");
    eprintln!("key_hash(ShapeType): {n} allocations in 100 calls");
}
