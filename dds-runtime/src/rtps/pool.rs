//! Reusable payload buffers: a pool of `Arc<Vec<u8>>` that hands a buffer out again once every
//! [`Payload`](super::Payload) made from it is gone, so that a steady stream of samples of similar sizes
//! allocates nothing per sample.
//!
//! The pool keeps a clone of each buffer it handed out. A buffer is free again when that clone is the only
//! reference left ([`Arc::get_mut`] succeeds). Buffers are reused oldest first, which is the order in which a
//! writer's history and a reader's deliveries release them; while the oldest is still held, a new buffer
//! is made. The pool keeps the buffers it made, up to its bounds in buffers and in bytes of capacity, so
//! that it grows to the most samples ever in flight at once; at its bounds it forgets its oldest buffers
//! (their holders still free them). A buffer held for long (a sample kept in a reader cache, say) goes to
//! the back when the next one is free, so it cannot stop reuse for good.

use std::collections::VecDeque;
use std::sync::Arc;

use super::api::{prefetch_arc, Payload};

/// A bounded pool of reusable payload buffers.
#[derive(Debug)]
pub(crate) struct BufferPool {
    bufs: VecDeque<Arc<Vec<u8>>>,
    /// Capacity of the buffers held.
    bytes: usize,
    max_buffers: usize,
    max_bytes: usize,
    /// Length of the last buffer shared: the capacity a new buffer starts with.
    last_len: usize,
}

impl BufferPool {
    /// A pool keeping at most `max_buffers` buffers of at most `max_bytes` capacity in all.
    pub(crate) const fn new(max_buffers: usize, max_bytes: usize) -> Self {
        BufferPool {
            bufs: VecDeque::new(),
            bytes: 0,
            max_buffers,
            max_bytes,
            last_len: 0,
        }
    }

    /// Whether it keeps no buffer.
    pub(crate) fn is_empty(&self) -> bool {
        self.bufs.is_empty()
    }

    /// An empty buffer referenced by nobody else: a free one from the pool, else a new one (with the
    /// capacity of the last buffer shared, so that filling it does not regrow it step by step).
    ///
    /// The next buffer in line is prefetched: a writer with thousands of samples in flight reuses a buffer
    /// long after it last touched it, and reading its reference counts cold was a tenth of a 64-byte
    /// publisher's time.
    pub(crate) fn take(&mut self) -> Arc<Vec<u8>> {
        if self.bufs.len() >= 2 && !is_free(&self.bufs[0]) && is_free(&self.bufs[1]) {
            // The oldest is held for long while the next is free: it moves to the back.
            self.bufs.rotate_left(1);
        }
        if let Some(front) = self.bufs.front_mut() {
            if let Some(v) = Arc::get_mut(front) {
                v.clear();
                self.bytes -= v.capacity();
                let b = self.bufs.pop_front().unwrap_or_default();
                // Pipelined: the next buffer's bytes (its counts were fetched one take ago) and the counts
                // of the one after it.
                if let Some(next) = self.bufs.front() {
                    prefetch_bytes(next.as_ptr());
                }
                if let Some(after) = self.bufs.get(1) {
                    prefetch_arc(after);
                }
                return b;
            }
        }
        // A word more than the last length: encoders reserve a word for their last store and padding, and
        // a buffer of exactly the last length would regrow, copying itself, at its very end.
        Arc::new(Vec::with_capacity(self.last_len + 8))
    }

    /// A payload of the bytes `fill` appends to a pooled buffer; the pool keeps the buffer for reuse.
    pub(crate) fn fill<E>(
        &mut self,
        fill: impl FnOnce(&mut Vec<u8>) -> Result<(), E>,
    ) -> Result<Payload, E> {
        let mut b = self.take();
        // `take` returns a buffer nobody else references: `make_mut` does not copy.
        fill(Arc::make_mut(&mut b))?;
        Ok(self.share(b))
    }

    /// `p` itself when it owns its buffer whole, else a copy of its bytes in a pooled buffer: kept for
    /// long, it then no longer pins the larger buffer it is a slice of (a received datagram), and a steady
    /// stream of such copies reuses the same buffers instead of allocating.
    pub(crate) fn compact(&mut self, p: Payload) -> Payload {
        if !p.is_part() {
            return p;
        }
        let mut b = self.take();
        // `take` returns a buffer nobody else references: `make_mut` does not copy.
        Arc::make_mut(&mut b).extend_from_slice(&p);
        self.share(b)
    }

    /// A payload of `b` (filled by the caller); the pool keeps `b` for reuse once the payload is gone.
    pub(crate) fn share(&mut self, b: Arc<Vec<u8>>) -> Payload {
        let p = Payload::from_shared_vec(b.clone());
        let cap = b.capacity();
        self.last_len = b.len();
        if self.max_buffers == 0 || cap > self.max_bytes {
            return p;
        }
        while self.bufs.len() >= self.max_buffers || self.bytes + cap > self.max_bytes {
            let Some(old) = self.bufs.pop_front() else {
                break;
            };
            self.bytes -= old.capacity();
        }
        self.bytes += cap;
        self.bufs.push_back(b);
        p
    }
}

/// Asks the CPU to bring the first cache line at `p` in (a hint, never a fault; nothing on other targets).
#[inline]
fn prefetch_bytes(p: *const u8) {
    #[cfg(target_arch = "x86_64")]
    // SAFETY: a prefetch is a hint that never faults, whatever the address.
    unsafe {
        use std::arch::x86_64::{_mm_prefetch, _MM_HINT_T0};
        _mm_prefetch::<_MM_HINT_T0>(p.cast::<i8>());
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = p;
}

/// Whether only the pool references `b`.
fn is_free(b: &Arc<Vec<u8>>) -> bool {
    Arc::strong_count(b) == 1 && Arc::weak_count(b) == 0
}

/// The receive path's pools: copies of datagrams whose DATA samples share them, and reassembly buffers.
#[derive(Debug)]
pub(crate) struct ReceivePools {
    pub datagrams: BufferPool,
    pub samples: BufferPool,
}

impl Default for ReceivePools {
    fn default() -> Self {
        ReceivePools {
            datagrams: BufferPool::new(256, 8 << 20),
            samples: BufferPool::new(32, 16 << 20),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_buffer_is_reused_once_its_payloads_are_gone() {
        let mut pool = BufferPool::new(4, 1 << 20);
        let p = pool
            .fill(|v| {
                v.extend_from_slice(&[1, 2, 3]);
                Ok::<_, ()>(())
            })
            .unwrap();
        assert_eq!(&p[..], &[1, 2, 3]);
        let held = p.as_ptr();
        // Still referenced: a new buffer.
        let q = pool.fill(|v| v.try_reserve(3)).unwrap();
        assert!(q.is_empty());
        drop(p);
        let r = pool.fill(|v| {
            v.push(9);
            Ok::<_, ()>(())
        });
        let r = r.unwrap();
        assert_eq!(r.as_ptr(), held, "the first buffer came back");
        assert_eq!(&r[..], &[9]);
    }

    #[test]
    fn bounded_in_buffers_and_bytes() {
        let mut pool = BufferPool::new(2, 100);
        let kept: Vec<Payload> = (0..4)
            .map(|_| pool.share(Arc::new(Vec::with_capacity(40))))
            .collect();
        assert_eq!(
            (pool.bufs.len(), pool.bytes),
            (2, 80),
            "the oldest forgotten"
        );
        let big = pool.share(Arc::new(Vec::with_capacity(1000)));
        assert_eq!(pool.bufs.len(), 2, "larger than the pool: not kept");
        let mid = pool.share(Arc::new(Vec::with_capacity(70)));
        assert_eq!((pool.bufs.len(), pool.bytes), (1, 70), "room made by bytes");
        drop((kept, big, mid));
        assert_eq!(pool.take().capacity(), 70);
    }

    #[test]
    fn keeps_every_buffer_it_made_and_reuses_them_all() {
        let mut pool = BufferPool::new(8, 1 << 20);
        let fill = |pool: &mut BufferPool| pool.fill(|v| v.try_reserve(16)).unwrap();
        let held: Vec<Payload> = (0..6).map(|_| fill(&mut pool)).collect();
        let ptrs: Vec<*const u8> = held.iter().map(|p| p.as_ptr()).collect();
        drop(held);
        // Used one at a time for a while, then six at once again: all six are still there.
        for _ in 0..20 {
            drop(fill(&mut pool));
        }
        let again: Vec<Payload> = (0..6).map(|_| fill(&mut pool)).collect();
        let mut reused: Vec<*const u8> = again.iter().map(|p| p.as_ptr()).collect();
        let mut expect = ptrs.clone();
        reused.sort();
        expect.sort();
        assert_eq!(reused, expect, "no new buffer");
        let more: Vec<Payload> = (0..6).map(|_| fill(&mut pool)).collect();
        assert_eq!(pool.bufs.len(), 8, "bounded");
        drop((again, more));
    }

    #[test]
    fn compact_copies_a_part_into_a_reused_buffer() {
        let mut pool = BufferPool::new(4, 1 << 20);
        let whole = Payload::from(vec![5u8; 100]);
        let alone = Payload::from(vec![7u8; 10]);
        assert_eq!(
            pool.compact(alone.clone()).as_ptr(),
            alone.as_ptr(),
            "already whole: kept"
        );
        let first = pool.compact(whole.slice(10..20));
        assert_eq!(&first[..], &[5u8; 10]);
        assert!(!first.is_part());
        let ptr = first.as_ptr();
        drop(first);
        let again = pool.compact(whole.slice(30..40));
        assert_eq!(again.as_ptr(), ptr, "the pooled buffer came back");
    }

    #[test]
    fn a_buffer_held_for_long_does_not_stop_reuse() {
        let mut pool = BufferPool::new(4, 1 << 20);
        let fill = |pool: &mut BufferPool| pool.fill(|v| v.try_reserve(16)).unwrap();
        let kept = fill(&mut pool);
        let second = fill(&mut pool);
        let ptr = second.as_ptr();
        drop(second);
        let third = fill(&mut pool);
        assert_eq!(
            third.as_ptr(),
            ptr,
            "the free buffer behind the held one is reused"
        );
        assert_ne!(kept.as_ptr(), ptr);
    }
}
