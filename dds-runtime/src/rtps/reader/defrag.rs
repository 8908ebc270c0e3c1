//! Reassembly of DATA_FRAG samples into one buffer of the sample's size (from the participant's pool of
//! reusable buffers), which becomes the delivered payload as it is: each fragment is copied once, out of
//! its datagram, to its place; completion costs no further copy. The buffer (and the bitmap of fragments
//! received) is charged against the reader's limits when it is taken, so a sender claiming large samples
//! cannot make us hold more than those limits.

use std::sync::Arc;

use crate::rtps::api::Payload;
use crate::rtps::pool::BufferPool;
use crate::rtps::types::SequenceNumber;

/// What one sample being reassembled costs beyond its buffer and bitmap (its map node and this struct).
pub(super) const SAMPLE_OVERHEAD: usize = 128;

/// One sample being reassembled.
#[derive(Debug)]
pub(crate) struct Defrag {
    pub sample_size: u32,
    pub fragment_size: u16,
    /// The sample's bytes, in the buffer's spare capacity (its length stays 0 until complete); those of
    /// the fragments marked in `have` are initialised.
    buf: Arc<Vec<u8>>,
    /// One bit per fragment (bit `n - 1` for fragment `n`): received.
    have: Vec<u64>,
    received: u32,
    /// Memory charged for this sample: buffer, bitmap, overhead.
    pub bytes: usize,
    /// Inline QoS of the first fragment seen: (status info, key hash).
    pub status_info: Option<u8>,
    pub key_hash: Option<[u8; 16]>,
    pub key_flag: bool,
    /// `PID_COHERENT_SET` of the sample, if it is in a coherent set.
    pub coherent_set: Option<SequenceNumber>,
    pub group_seq: Option<SequenceNumber>,
    /// Source timestamp in force for the first fragment that carried one.
    pub source_timestamp: Option<crate::rtps::types::Time>,
}

/// Memory a sample of `sample_size` bytes in fragments of `fragment_size` costs to reassemble.
pub(super) fn cost(sample_size: u32, fragment_size: u16) -> usize {
    let total = total(sample_size, fragment_size) as usize;
    sample_size as usize + total.div_ceil(64) * 8 + SAMPLE_OVERHEAD
}

fn total(sample_size: u32, fragment_size: u16) -> u32 {
    sample_size.div_ceil(u32::from(fragment_size.max(1)))
}

impl Defrag {
    /// An empty reassembly buffer in `buf` (empty, referenced by nobody else); the caller has checked
    /// [`cost`] against its limits.
    pub(crate) fn new(sample_size: u32, fragment_size: u16, mut buf: Arc<Vec<u8>>) -> Self {
        let fragment_size = fragment_size.max(1);
        let words = total(sample_size, fragment_size).div_ceil(64) as usize;
        let v = Arc::make_mut(&mut buf);
        v.clear();
        v.reserve_exact(sample_size as usize);
        Defrag {
            sample_size,
            fragment_size,
            buf,
            have: vec![0; words],
            received: 0,
            bytes: cost(sample_size, fragment_size),
            status_info: None,
            key_hash: None,
            key_flag: false,
            coherent_set: None,
            group_seq: None,
            source_timestamp: None,
        }
    }

    pub(crate) fn total(&self) -> u32 {
        total(self.sample_size, self.fragment_size)
    }

    fn has(&self, num: u32) -> bool {
        let i = (num - 1) as usize;
        self.have[i / 64] & (1 << (i % 64)) != 0
    }

    /// Copies fragment `num` (1-based) to its place. Fragments out of range, of the wrong length or
    /// already received are ignored.
    pub(crate) fn add(&mut self, num: u32, data: &[u8]) {
        if num == 0 || num > self.total() || self.has(num) {
            return;
        }
        let start = (num as usize - 1) * self.fragment_size as usize;
        let expect = (self.sample_size as usize - start).min(self.fragment_size as usize);
        if data.len() != expect {
            return;
        }
        // The buffer is ours alone until the sample is complete (`assemble` consumes `self`).
        let Some(buf) = Arc::get_mut(&mut self.buf) else {
            return;
        };
        let dst = &mut buf.spare_capacity_mut()[start..start + expect];
        // SAFETY: `dst` and `data` have the same length, and a buffer of ours cannot overlap the datagram;
        // `MaybeUninit<u8>` has the layout of `u8`.
        unsafe {
            std::ptr::copy_nonoverlapping(data.as_ptr(), dst.as_mut_ptr().cast::<u8>(), expect);
        }
        let i = (num - 1) as usize;
        self.have[i / 64] |= 1 << (i % 64);
        self.received += 1;
    }

    pub(crate) fn is_complete(&self) -> bool {
        self.received == self.total()
    }

    /// The missing fragment numbers up to `last`: at most 256, within 256 of the first missing one.
    pub(crate) fn missing(&self, last: u32) -> Vec<u32> {
        let last = last.min(self.total());
        let mut v = Vec::new();
        let mut n = 1;
        while n <= last && v.len() < 256 {
            if !self.has(n) {
                if let Some(&first) = v.first() {
                    if n - first >= 256 {
                        break;
                    }
                }
                v.push(n);
            }
            n += 1;
        }
        v
    }

    /// The reassembled sample, without a copy (its buffer goes back to `pool` once the payload is gone);
    /// `None` unless complete.
    pub(crate) fn assemble(mut self, pool: &mut BufferPool) -> Option<Payload> {
        if !self.is_complete() {
            return None;
        }
        let v = Arc::get_mut(&mut self.buf)?;
        // SAFETY: the capacity is at least `sample_size` (reserved in `new`), and every fragment was
        // received: the fragments (all but the last of `fragment_size` bytes, the last one the rest) cover
        // the first `sample_size` bytes, so all of them were written.
        unsafe { v.set_len(self.sample_size as usize) };
        Some(pool.share(self.buf))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reassembles_out_of_order_and_ignores_bad_fragments() {
        let sample: Vec<u8> = (0..2500u32).map(|i| i as u8).collect();
        let mut pool = BufferPool::new(4, 1 << 20);
        let mut d = Defrag::new(2500, 1000, pool.take());
        assert_eq!(d.total(), 3);
        d.add(3, &sample[2000..]);
        d.add(3, &sample[2000..]);
        d.add(1, &sample[..999]); // wrong length
        d.add(4, &sample[..500]); // out of range
        d.add(0, &sample[..1000]);
        assert_eq!(d.missing(3), vec![1, 2]);
        assert!(!d.is_complete());
        d.add(1, &sample[..1000]);
        d.add(2, &sample[1000..2000]);
        assert!(d.missing(3).is_empty());
        let p = d.assemble(&mut pool).expect("complete");
        assert_eq!(&p[..], &sample[..]);
        let at = p.as_ptr();
        drop(p);
        let mut d = Defrag::new(3, 2, pool.take());
        d.add(2, &[3]);
        d.add(1, &[1, 2]);
        let p = d.assemble(&mut pool).expect("complete");
        assert_eq!(
            (&p[..], p.as_ptr()),
            (&[1u8, 2, 3][..], at),
            "buffer reused"
        );
    }

    #[test]
    fn incomplete_sample_does_not_assemble_and_cost_counts_buffer() {
        let mut pool = BufferPool::new(4, 1 << 20);
        let d = Defrag::new(10_000, 1344, pool.take());
        assert!(d.bytes >= 10_000);
        assert_eq!(d.bytes, cost(10_000, 1344));
        assert!(d.assemble(&mut pool).is_none());
        // A zero fragment size is never divided by.
        assert_eq!(Defrag::new(10, 0, pool.take()).total(), 10);
    }
}
