//! What the core hands out to send: one RTPS message for a list of destinations, its bytes either all in a
//! buffer of its own or, for large fragments of a sample, partly in the sample's own shared buffer (a
//! scatter-gather send then needs no copy of them; see [`Transmit::pieces`]).

use std::borrow::Cow;

use super::api::Payload;
use super::types::Locator;

/// One datagram to send to every destination.
///
/// Its bytes are `payload` with the [`shared`](Transmit::shared) parts inserted at their offsets. Without
/// [`Participant::gather_sends`](super::Participant::gather_sends), `shared` is always empty and `payload`
/// is the whole message.
#[derive(Debug, Clone, PartialEq, Eq)]
#[non_exhaustive]
pub struct Transmit {
    /// Send the payload to each of these.
    pub destinations: Vec<Locator>,
    /// One RTPS message: its own bytes (all of them when `shared` is empty).
    pub payload: Vec<u8>,
    /// Parts of samples' serialized payloads carried without a copy, in ascending offsets.
    pub shared: Vec<SharedPart>,
}

/// A slice of a sample's payload that goes into a datagram as it is.
#[derive(Debug, Clone, PartialEq, Eq)]
#[non_exhaustive]
pub struct SharedPart {
    /// Where it goes: before the byte at this offset of [`Transmit::payload`].
    pub at: usize,
    /// The bytes (a reference-counted share of the sample's buffer).
    pub bytes: Payload,
}

impl Transmit {
    /// A datagram of `payload` alone.
    pub fn new(destinations: Vec<Locator>, payload: Vec<u8>) -> Self {
        Transmit {
            destinations,
            payload,
            shared: Vec::new(),
        }
    }

    /// The datagram's length in bytes.
    pub fn len(&self) -> usize {
        self.payload.len() + self.shared.iter().map(|s| s.bytes.len()).sum::<usize>()
    }

    /// Whether the datagram is empty.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Calls `f` with each piece of the datagram in order (empty pieces skipped): what a scatter-gather
    /// send hands the kernel as separate buffers.
    pub fn pieces<'a>(&'a self, mut f: impl FnMut(&'a [u8])) {
        let mut from = 0;
        for s in &self.shared {
            let at = s.at.min(self.payload.len());
            if at > from {
                f(&self.payload[from..at]);
            }
            if !s.bytes.is_empty() {
                f(&s.bytes);
            }
            from = at.max(from);
        }
        if from < self.payload.len() {
            f(&self.payload[from..]);
        }
    }

    /// The number of pieces [`pieces`](Transmit::pieces) gives.
    pub fn piece_count(&self) -> usize {
        let mut n = 0;
        self.pieces(|_| n += 1);
        n
    }

    /// The datagram as one contiguous slice: borrowed when nothing is shared, else copied.
    pub fn datagram(&self) -> Cow<'_, [u8]> {
        if self.shared.is_empty() {
            return Cow::Borrowed(&self.payload);
        }
        let mut v = Vec::with_capacity(self.len());
        self.pieces(|p| v.extend_from_slice(p));
        Cow::Owned(v)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pieces_interleave_own_and_shared_bytes() {
        let sample = Payload::new(vec![7u8; 12]);
        let t = Transmit {
            destinations: Vec::new(),
            payload: vec![1, 2, 3, 4, 5],
            shared: vec![
                SharedPart {
                    at: 2,
                    bytes: sample.slice(0..4),
                },
                SharedPart {
                    at: 5,
                    bytes: sample.slice(4..8),
                },
            ],
        };
        let mut pieces = Vec::new();
        t.pieces(|p| pieces.push(p.to_vec()));
        assert_eq!(
            pieces,
            vec![vec![1, 2], vec![7; 4], vec![3, 4, 5], vec![7; 4]]
        );
        assert_eq!(t.len(), 13);
        assert_eq!(t.piece_count(), 4);
        assert_eq!(&t.datagram()[..], &[1, 2, 7, 7, 7, 7, 3, 4, 5, 7, 7, 7, 7]);
        let plain = Transmit::new(Vec::new(), vec![9; 3]);
        assert!(matches!(plain.datagram(), Cow::Borrowed(b) if b == [9; 3]));
        assert_eq!(plain.piece_count(), 1);
    }
}
