//! Datagrams given as pieces (scatter-gather): a datagram whose headers are in one buffer and whose
//! payload is a slice of a sample's buffer leaves in one `sendmsg` of several `iovec`s, without being
//! copied together first (the core's [`Transmit::pieces`](crate::rtps::Transmit::pieces)).

use std::io::{self, IoSlice};
use std::net::{SocketAddr, UdpSocket};

use socket2::{SockAddr, SockRef};

use crate::rtps::Transmit;

/// A datagram to send: one contiguous buffer, or its pieces in order.
pub trait Pieces {
    /// The datagram's pieces, in order.
    fn pieces(&self) -> &[&[u8]];

    /// The datagram's length in bytes.
    fn total_len(&self) -> usize {
        self.pieces().iter().map(|p| p.len()).sum()
    }
}

impl Pieces for &[u8] {
    fn pieces(&self) -> &[&[u8]] {
        std::slice::from_ref(self)
    }

    fn total_len(&self) -> usize {
        self.len()
    }
}

impl Pieces for &[&[u8]] {
    fn pieces(&self) -> &[&[u8]] {
        self
    }
}

/// Most pieces one vectored send takes from the stack; a datagram of more is copied together first.
const MAX_PIECES: usize = 16;

/// Sends one datagram of `pieces` on `sock`: to `dest`, or (`None`) to the address it is connected to.
pub(super) fn send_pieces(
    sock: &UdpSocket,
    pieces: &[&[u8]],
    dest: Option<SocketAddr>,
) -> io::Result<usize> {
    let sock = SockRef::from(sock);
    let send = |iov: &[IoSlice<'_>]| match dest {
        Some(d) => sock.send_to_vectored(iov, &SockAddr::from(d)),
        None => sock.send_vectored(iov),
    };
    if pieces.len() > MAX_PIECES {
        let whole = pieces.concat();
        return send(&[IoSlice::new(&whole)]);
    }
    let mut iov = [IoSlice::new(&[]); MAX_PIECES];
    for (s, p) in iov.iter_mut().zip(pieces) {
        *s = IoSlice::new(p);
    }
    send(&iov[..pieces.len()])
}

/// Most datagrams one run (one destination list, consecutive datagrams) hands the transport at once.
pub(crate) const RUN: usize = 16;

/// Pieces gathered on the stack for one run: four per datagram, more than a fragment has (its headers, the
/// slice of the sample, at most a header after it).
const RUN_PIECES: usize = 4 * RUN;

/// Hands `send` the pieces of the first datagrams of `run` (at most [`RUN`], and as many as fit in
/// [`RUN_PIECES`] pieces), one slice of pieces per datagram, and returns how many datagrams that was (at least
/// one when `run` is not empty). The pieces are gathered on the stack: nothing is allocated, except for a
/// datagram alone of more than [`RUN_PIECES`] pieces, which is copied together.
pub(crate) fn with_run_pieces(run: &[Transmit], send: impl FnOnce(&[&[&[u8]]])) -> usize {
    let mut pieces: [&[u8]; RUN_PIECES] = [&[]; RUN_PIECES];
    let mut ends = [0usize; RUN];
    let (mut len, mut taken) = (0, 0);
    for t in run.iter().take(RUN) {
        if len + t.piece_count() > RUN_PIECES {
            break;
        }
        t.pieces(|p| {
            pieces[len] = p;
            len += 1;
        });
        ends[taken] = len;
        taken += 1;
    }
    if taken == 0 {
        if let Some(t) = run.first() {
            let whole = t.datagram();
            send(&[&[&whole[..]]]);
            return 1;
        }
        return 0;
    }
    let mut grams: [&[&[u8]]; RUN] = [&[]; RUN];
    let mut from = 0;
    for (g, &end) in grams.iter_mut().zip(&ends[..taken]) {
        *g = &pieces[from..end];
        from = end;
    }
    send(&grams[..taken]);
    taken
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pieces_arrive_as_one_datagram() {
        let rx = UdpSocket::bind("127.0.0.1:0").unwrap();
        let tx = UdpSocket::bind("127.0.0.1:0").unwrap();
        let dest = rx.local_addr().unwrap();
        let head = [1u8; 20];
        let body = [2u8; 1000];
        let many: Vec<[u8; 3]> = (0..20u8).map(|i| [i; 3]).collect();
        let many: Vec<&[u8]> = many.iter().map(|b| &b[..]).collect();
        let mut buf = [0u8; 2000];
        for pieces in [&[&head[..], &body[..], &head[..4]][..], &many[..]] {
            assert_eq!(
                send_pieces(&tx, pieces, Some(dest)).unwrap(),
                pieces.total_len()
            );
            let n = rx.recv(&mut buf).unwrap();
            assert_eq!(&buf[..n], &pieces.concat()[..]);
        }
        tx.connect(dest).unwrap();
        send_pieces(&tx, &[&head, &body], None).unwrap();
        let n = rx.recv(&mut buf).unwrap();
        assert_eq!(&buf[..n], &[&head[..], &body[..]].concat()[..]);
    }

    /// A datagram of `n_shared` shared parts, each between two bytes of its own.
    fn gram(seq: u8, n_shared: usize) -> Transmit {
        let mut t = Transmit::new(Vec::new(), vec![seq; n_shared + 1]);
        for i in 0..n_shared {
            t.shared.push(crate::rtps::SharedPart {
                at: i + 1,
                bytes: crate::rtps::Payload::from(vec![seq ^ 0xff; 1000 + i]),
            });
        }
        t
    }

    /// Each datagram's pieces are what it holds; a run stops where its pieces would not fit on the stack,
    /// and a datagram of more pieces than that alone is sent whole.
    #[test]
    fn runs_gather_their_pieces_on_the_stack() {
        let check = |run: &[Transmit], expect: usize| {
            let mut seen = Vec::new();
            let n = with_run_pieces(run, |grams| {
                seen = grams.iter().map(|g| g.concat()).collect();
            });
            assert_eq!(n, expect);
            assert_eq!(seen.len(), n);
            for (s, t) in seen.iter().zip(run) {
                assert_eq!(&s[..], &t.datagram()[..]);
            }
        };
        // Fragments: header, slice, trailing header; 16 of them fit (48 pieces), the 17th is the next run.
        let frags: Vec<Transmit> = (0..20).map(|i| gram(i, 1)).collect();
        check(&frags, RUN);
        check(&frags[RUN..], 4);
        // 7 pieces each: 9 fit in 64.
        let wide: Vec<Transmit> = (0..12).map(|i| gram(i, 3)).collect();
        check(&wide, RUN_PIECES / 7);
        // More pieces than the stack holds: alone, copied together.
        check(&[gram(1, RUN_PIECES)], 1);
        check(&[], 0);
    }
}
