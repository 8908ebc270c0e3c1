//! Short byte runs (strings, small octet sequences) copied with a few word loads and stores: for them a
//! `memcpy` call costs more than the bytes. Shared by the writer and the decoder of fresh strings and sequences.

/// Strings and byte runs up to this long are copied with word stores ([`copy_short`]).
pub(crate) const SHORT: usize = 16;

/// Copies `src` (at most [`SHORT`] bytes) to `dst` with two overlapping word loads and stores (or three byte
/// copies below 4 bytes), and tells whether `src` holds a NUL, tested on the same words.
///
/// # Safety
/// `dst` must be valid for writes of `src.len()` bytes and must not overlap `src`.
#[inline(always)]
pub(crate) unsafe fn copy_short(src: &[u8], dst: *mut u8) -> bool {
    // A byte is zero exactly when the result has its high bit set.
    // SAFETY: as the caller guarantees.
    unsafe { copy_short_testing(src, dst, |v, lo, hi| v.wrapping_sub(lo) & !v & hi != 0) }
}

/// Like [`copy_short`], and tells whether `src` is ASCII without a NUL (which is valid UTF-8 for a string).
///
/// # Safety
/// `dst` must be valid for writes of `src.len()` bytes and must not overlap `src`.
#[inline(always)]
pub(crate) unsafe fn copy_short_ascii(src: &[u8], dst: *mut u8) -> bool {
    // A byte is 0 or >= 0x80 exactly when the result has its high bit set.
    // SAFETY: as the caller guarantees.
    !unsafe { copy_short_testing(src, dst, |v, lo, hi| (v.wrapping_sub(lo) | v) & hi != 0) }
}

/// The copy of [`copy_short`]; `bad(word, 0x0101.., 0x8080..)` tests the words copied (as `u64`, the upper
/// half zero for 4-byte words and single bytes), and the result is whether any test was true.
///
/// # Safety
/// `dst` must be valid for writes of `src.len()` bytes and must not overlap `src`.
#[inline(always)]
unsafe fn copy_short_testing(
    src: &[u8],
    dst: *mut u8,
    bad: impl Fn(u64, u64, u64) -> bool,
) -> bool {
    const LO: u64 = 0x0101_0101_0101_0101;
    const HI: u64 = 0x8080_8080_8080_8080;
    const LO4: u64 = LO & 0xffff_ffff;
    const HI4: u64 = HI & 0xffff_ffff;
    let n = src.len();
    debug_assert!(n <= SHORT);
    let s = src.as_ptr();
    // SAFETY (all branches): every load reads inside `src` (offsets 0..n) and every store writes inside
    // `dst[..n]`, as the caller guarantees.
    unsafe {
        if n >= 8 {
            let a = s.cast::<u64>().read_unaligned();
            let b = s.add(n - 8).cast::<u64>().read_unaligned();
            dst.cast::<u64>().write_unaligned(a);
            dst.add(n - 8).cast::<u64>().write_unaligned(b);
            bad(a, LO, HI) | bad(b, LO, HI)
        } else if n >= 4 {
            let a = s.cast::<u32>().read_unaligned();
            let b = s.add(n - 4).cast::<u32>().read_unaligned();
            dst.cast::<u32>().write_unaligned(a);
            dst.add(n - 4).cast::<u32>().write_unaligned(b);
            bad(u64::from(a), LO4, HI4) | bad(u64::from(b), LO4, HI4)
        } else if n > 0 {
            let (a, b, c) = (*s, *s.add(n / 2), *s.add(n - 1));
            *dst = a;
            *dst.add(n / 2) = b;
            *dst.add(n - 1) = c;
            let byte = |x: u8| bad(u64::from(x), 1, 0x80);
            byte(a) | byte(b) | byte(c)
        } else {
            false
        }
    }
}

/// Copies `src` to `dst`: up to [`SHORT`] bytes with [`copy_short`], longer runs with `memcpy`.
///
/// # Safety
/// `dst` must be valid for writes of `src.len()` bytes and must not overlap `src`.
#[inline(always)]
pub(crate) unsafe fn copy_bytes(src: &[u8], dst: *mut u8) {
    // SAFETY: as the caller guarantees, for either copy.
    unsafe {
        if src.len() <= SHORT {
            copy_short(src, dst);
        } else {
            std::ptr::copy_nonoverlapping(src.as_ptr(), dst, src.len());
        }
    }
}
