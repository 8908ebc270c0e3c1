//! Serialization into a fixed destination (a loaned shared-memory frame): long byte runs (`Vec<u8>` or
//! native-order numeric sequences of 4 KiB or more, `writer::PLACE_MIN`) are copied straight to their
//! place in the destination as they are encoded; everything else is encoded into a small buffer as usual
//! and copied into the gaps between the runs at the end. A sample of megabytes is so copied once, not
//! twice (into a buffer, then into the frame).

use std::mem::MaybeUninit;

use super::error::EncodeError;
use super::header::{ByteOrder, XcdrVersion};
use super::payload::start_payload;
use super::traits::DdsType;
use super::writer::{push_zeros, CdrWriter, PlaceRuns};

/// Most runs placed per sample; later ones go into the buffer.
const MAX_RUNS: usize = 8;

/// The destination and the runs placed in it.
struct Placement<'d> {
    dest: &'d mut [MaybeUninit<u8>],
    /// `(index in the buffer before which the run goes, length)`, in stream order.
    runs: [(usize, usize); MAX_RUNS],
    count: usize,
    placed: usize,
}

/// Copies `src` to the start of `dst` (which must be at least as long).
fn copy_to(dst: &mut [MaybeUninit<u8>], src: &[u8]) {
    let dst = &mut dst[..src.len()];
    // SAFETY: `dst` holds exactly `src.len()` bytes and does not overlap `src` (a `&mut` and a `&`);
    // `MaybeUninit<u8>` has the layout of `u8`.
    unsafe { std::ptr::copy_nonoverlapping(src.as_ptr(), dst.as_mut_ptr().cast(), src.len()) }
}

impl PlaceRuns for Placement<'_> {
    fn place(&mut self, at: usize, bytes: &[u8]) -> bool {
        let from = at + self.placed;
        let Some(dst) = self.dest.get_mut(from..from + bytes.len()) else {
            return false;
        };
        if self.count == MAX_RUNS {
            return false;
        }
        copy_to(dst, bytes);
        self.runs[self.count] = (at, bytes.len());
        self.count += 1;
        self.placed += bytes.len();
        true
    }
}

/// Serializes `sample` (encapsulation header, sample, padding, as [`serialize`](super::serialize)) into
/// the start of `dest`, using `scratch` (cleared first) for what is not placed directly. `Some(len)`: the
/// payload is `dest[..len]`, every byte of it written. `None`: it does not fit in `dest` (whose bytes
/// then mean nothing).
pub(crate) fn serialize_placed<T: DdsType>(
    sample: &T,
    version: XcdrVersion,
    order: ByteOrder,
    scratch: &mut Vec<u8>,
    dest: &mut [MaybeUninit<u8>],
) -> Result<Option<usize>, EncodeError> {
    scratch.clear();
    let mut p = Placement {
        dest,
        runs: [(0, 0); MAX_RUNS],
        count: 0,
        placed: 0,
    };
    start_payload::<T>(version, order, scratch);
    sample.encode(&mut CdrWriter::placing(scratch, version, order, &mut p))?;
    // The padding to a multiple of 4, recorded in the header's options (as `finish_payload`).
    let pad = (scratch.len() + p.placed).wrapping_neg() & 3;
    if pad != 0 {
        push_zeros(scratch, pad);
    }
    scratch[3] = (scratch[3] & !3) | pad as u8;
    let len = scratch.len() + p.placed;
    if len > p.dest.len() {
        return Ok(None);
    }
    // The buffer's pieces go into the gaps between the runs.
    let (mut from, mut to) = (0, 0);
    for &(at, run) in &p.runs[..p.count] {
        copy_to(&mut p.dest[to..], &scratch[from..at]);
        to += at - from + run;
        from = at;
    }
    copy_to(&mut p.dest[to..], &scratch[from..]);
    Ok(Some(len))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cdr::serialize;
    use crate::cdr::writer::PLACE_MIN;

    /// Encodes `sample` placed and plainly; both must give the same bytes.
    fn same_bytes<T: DdsType>(sample: &T, version: XcdrVersion) {
        let mut want = Vec::new();
        serialize(sample, version, ByteOrder::LittleEndian, &mut want).unwrap();
        let mut dest = vec![MaybeUninit::new(0xeeu8); want.len() + 100];
        let mut scratch = Vec::new();
        let got = serialize_placed(
            sample,
            version,
            ByteOrder::LittleEndian,
            &mut scratch,
            &mut dest,
        )
        .unwrap()
        .expect("fits");
        assert_eq!(got, want.len());
        // SAFETY: `serialize_placed` wrote the first `got` bytes (and the rest were initialized above).
        let got: Vec<u8> = dest[..got]
            .iter()
            .map(|b| unsafe { b.assume_init() })
            .collect();
        assert_eq!(got, want);
        if want.len() > 100 * PLACE_MIN {
            assert!(scratch.len() < want.len() / 2, "the long runs were placed");
        }
        // Too small a destination says so.
        let mut small = vec![MaybeUninit::new(0u8); want.len() - 1];
        let r = serialize_placed(
            sample,
            version,
            ByteOrder::LittleEndian,
            &mut scratch,
            &mut small,
        );
        assert_eq!(r.unwrap(), None);
    }

    /// The same members in each extensibility: DHEADERs, EMHEADERs and XCDR1 parameters around runs.
    macro_rules! mixed {
        ($name:ident, $ext:ident) => {
            #[derive(crate::DdsType, Debug, Clone, PartialEq, Default)]
            #[dds($ext)]
            struct $name {
                a: u8,
                big: Vec<u8>,
                b: u64,
                words: Vec<u32>,
                name: String,
                nested: Vec<Vec<u8>>,
            }

            impl $name {
                fn of(n: usize) -> Self {
                    $name {
                        a: 7,
                        big: (0..n).map(|i| i as u8).collect(),
                        b: 0x0102_0304_0506_0708,
                        words: (0..n as u32 / 3).collect(),
                        name: "x".repeat(n % 50),
                        // More long runs than are placed: the last ones go into the buffer.
                        nested: vec![vec![3u8; n]; 10],
                    }
                }
            }
        };
    }
    mixed!(Final, final);
    mixed!(Appendable, appendable);
    mixed!(Mutable, mutable);

    #[test]
    fn placed_encoding_equals_the_plain_one() {
        for version in [XcdrVersion::Xcdr1, XcdrVersion::Xcdr2] {
            for n in [0usize, 5, 4095, 4096, 4097, 70_001] {
                same_bytes(&Final::of(n), version);
                same_bytes(&Appendable::of(n), version);
                same_bytes(&Mutable::of(n), version);
            }
        }
    }
}
