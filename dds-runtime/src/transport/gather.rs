//! Datagrams given as pieces (scatter-gather): a datagram whose headers are in one buffer and whose
//! payload is a slice of a sample's buffer leaves in one `sendmsg` of several `iovec`s, without being
//! copied together first (the core's [`Transmit::pieces`](crate::rtps::Transmit::pieces)).

use std::io::{self, IoSlice};
use std::net::{SocketAddr, UdpSocket};

use socket2::{SockAddr, SockRef};

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
}
