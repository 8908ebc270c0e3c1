//! A set of numbers close to each other: a bitmap of 64-bit words, starting at the word of its lowest
//! member. What a reader asks to be sent again (sequence numbers, fragment numbers) is kept in these: no
//! allocation per member, none per acknowledgement (removing the numbers below one drops whole words from
//! the front), and the words stay allocated while the window is in use.

use std::collections::VecDeque;

/// A set of `u64` spanning at most a given number of words (the bound is the caller's, per insertion).
#[derive(Debug, Clone, Default)]
pub(crate) struct BitWindow {
    /// The number of bit 0 of `words[0]`: a multiple of 64.
    base: u64,
    /// The first and last words are non-zero while the set is not empty.
    words: VecDeque<u64>,
    len: usize,
}

const BITS: u64 = u64::BITS as u64;

impl BitWindow {
    /// How many numbers are in the set.
    pub(crate) fn len(&self) -> usize {
        self.len
    }

    pub(crate) fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// Whether `n` is in the set.
    pub(crate) fn contains(&self, n: u64) -> bool {
        let Some(i) = n.checked_sub(self.base).map(|d| d / BITS) else {
            return false;
        };
        self.words
            .get(i as usize)
            .is_some_and(|w| w & (1 << (n % BITS)) != 0)
    }

    /// Adds `n`, unless the set would then span more than `max_words` words: false then (the set is
    /// unchanged).
    pub(crate) fn insert(&mut self, n: u64, max_words: usize) -> bool {
        let word = n - n % BITS;
        if self.words.is_empty() {
            if max_words == 0 {
                return false;
            }
            self.base = word;
            self.words.push_back(0);
        } else if word < self.base {
            let more = ((self.base - word) / BITS) as usize;
            if self.words.len() + more > max_words {
                return false;
            }
            for _ in 0..more {
                self.words.push_front(0);
            }
            self.base = word;
        } else {
            let i = (word - self.base) / BITS;
            if i >= max_words as u64 {
                return false;
            }
            while self.words.len() <= i as usize {
                self.words.push_back(0);
            }
        }
        let w = &mut self.words[((word - self.base) / BITS) as usize];
        let bit = 1 << (n % BITS);
        if *w & bit == 0 {
            *w |= bit;
            self.len += 1;
        }
        true
    }

    /// Removes `n`; whether it was there.
    pub(crate) fn remove(&mut self, n: u64) -> bool {
        if !self.contains(n) {
            return false;
        }
        let i = ((n - self.base) / BITS) as usize;
        self.words[i] &= !(1 << (n % BITS));
        self.len -= 1;
        self.trim();
        true
    }

    /// The lowest number in the set.
    pub(crate) fn first(&self) -> Option<u64> {
        let w = *self.words.front()?;
        (w != 0).then(|| self.base + u64::from(w.trailing_zeros()))
    }

    /// Takes the lowest number out of the set.
    pub(crate) fn pop_first(&mut self) -> Option<u64> {
        let n = self.first()?;
        self.remove(n);
        Some(n)
    }

    /// Removes every number below `n`.
    pub(crate) fn remove_below(&mut self, n: u64) {
        while let Some(&w) = self.words.front() {
            if self.base + BITS > n {
                break;
            }
            self.len -= w.count_ones() as usize;
            self.words.pop_front();
            self.base += BITS;
        }
        if let Some(w) = self.words.front_mut() {
            if n > self.base {
                let below = (1u64 << (n - self.base)) - 1;
                self.len -= (*w & below).count_ones() as usize;
                *w &= !below;
            }
        }
        self.trim();
    }

    /// The numbers in ascending order.
    pub(crate) fn iter(&self) -> impl Iterator<Item = u64> + '_ {
        self.words.iter().enumerate().flat_map(move |(i, &w)| {
            let base = self.base + i as u64 * BITS;
            Ones(w).map(move |b| base + u64::from(b))
        })
    }

    /// Drops the zero words at both ends (their allocation stays).
    fn trim(&mut self) {
        if self.len == 0 {
            self.words.clear();
            return;
        }
        while self.words.back() == Some(&0) {
            self.words.pop_back();
        }
        while self.words.front() == Some(&0) {
            self.words.pop_front();
            self.base += BITS;
        }
    }
}

/// The set bits of a word, lowest first.
struct Ones(u64);

impl Iterator for Ones {
    type Item = u32;
    fn next(&mut self) -> Option<u32> {
        if self.0 == 0 {
            return None;
        }
        let b = self.0.trailing_zeros();
        self.0 &= self.0 - 1;
        Some(b)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::BTreeSet;

    /// Random operations against a `BTreeSet` (a fixed-seed generator: deterministic).
    #[test]
    fn behaves_like_a_set_within_its_span() {
        let mut seed = 0x9e37_79b9_7f4a_7c15u64;
        let mut rnd = move |m: u64| {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            seed % m
        };
        let (mut w, mut s) = (BitWindow::default(), BTreeSet::new());
        for _ in 0..20_000 {
            let n = 1_000 + rnd(1_000);
            match rnd(5) {
                0 | 1 => {
                    if w.insert(n, 8) {
                        s.insert(n);
                    } else {
                        let lo = s.first().map_or(n, |&f| f.min(n)) / 64;
                        let hi = s.last().map_or(n, |&l| l.max(n)) / 64;
                        assert!(hi - lo >= 8, "refused {n} within the span");
                    }
                }
                2 => assert_eq!(w.remove(n), s.remove(&n)),
                3 => assert_eq!(w.pop_first(), s.pop_first()),
                _ => {
                    w.remove_below(n);
                    s = s.split_off(&n);
                }
            }
            assert_eq!(w.len(), s.len());
            assert_eq!(w.first(), s.first().copied());
            assert_eq!(w.contains(n), s.contains(&n));
        }
        assert!(w.iter().eq(s.iter().copied()));
    }

    #[test]
    fn words_are_kept_once_grown() {
        let mut w = BitWindow::default();
        for n in 0..640 {
            assert!(w.insert(n, 10));
        }
        assert!(!w.insert(640, 10), "an 11th word");
        let cap = w.words.capacity();
        w.remove_below(640);
        assert!(w.is_empty() && w.first().is_none());
        assert!(w.insert(10_000, 10) && w.insert(10_100, 10));
        assert_eq!(w.words.capacity(), cap);
        assert_eq!(w.iter().collect::<Vec<_>>(), [10_000, 10_100]);
        w.remove_below(u64::MAX);
        assert!(w.iter().next().is_none() && w.is_empty());
    }
}
