//! Walking the submessages of a message, and building messages.

use super::{Header, Submessage, WireError, HEADER_LEN};

/// Iterates over the submessages that follow the header. Unknown and vendor submessages come out as
/// [`Submessage::Unknown`]; the first invalid submessage yields an error and ends the iteration (§8.3.4.1: the
/// rest of the message is ignored).
#[derive(Debug, Clone)]
pub struct MessageIter<'a> {
    rest: &'a [u8],
    done: bool,
}

impl<'a> MessageIter<'a> {
    /// An iterator over the submessages that follow a header (see [`MessageIter::parse`]).
    pub fn new(submessages: &'a [u8]) -> Self {
        MessageIter {
            rest: submessages,
            done: false,
        }
    }

    /// Parses the header and returns it with an iterator over the submessages.
    pub fn parse(datagram: &'a [u8]) -> Result<(Header, MessageIter<'a>), WireError> {
        let (h, rest) = Header::parse(datagram)?;
        Ok((h, MessageIter::new(rest)))
    }
}

impl<'a> Iterator for MessageIter<'a> {
    type Item = Result<Submessage<'a>, WireError>;

    fn next(&mut self) -> Option<Self::Item> {
        if self.done || self.rest.is_empty() {
            return None;
        }
        if self.rest.len() < 4 {
            self.done = true;
            return Some(Err(WireError::Truncated));
        }
        let sid = self.rest[0];
        let flags = self.rest[1];
        let raw = [self.rest[2], self.rest[3]];
        let len = if flags & super::FLAG_E != 0 {
            u16::from_le_bytes(raw)
        } else {
            u16::from_be_bytes(raw)
        } as usize;
        let after = &self.rest[4..];
        // octetsToNextHeader == 0: the submessage runs to the end of the message, except PAD and INFO_TS
        // which are legitimately empty (§9.4.5.1.3).
        let body_len = if len == 0 && sid != super::id::PAD && sid != super::id::INFO_TS {
            after.len()
        } else {
            len
        };
        if body_len > after.len() {
            self.done = true;
            return Some(Err(WireError::Truncated));
        }
        let body = &after[..body_len];
        self.rest = &after[body_len..];
        let r = Submessage::decode(sid, flags, body);
        if r.is_err() {
            self.done = true;
        }
        Some(r)
    }
}

/// Builds one message: header, then submessages, little-endian.
#[derive(Debug, Clone)]
pub struct MessageBuilder {
    buf: Vec<u8>,
    last_header: Option<usize>,
}

impl MessageBuilder {
    /// A builder holding `header` and no submessage yet.
    pub fn new(header: &Header) -> Self {
        Self::with_buffer(header, Vec::new())
    }
    /// Reuses `buf` (cleared) so steady-state sending does not allocate.
    pub fn with_buffer(header: &Header, mut buf: Vec<u8>) -> Self {
        buf.clear();
        header.write(&mut buf);
        MessageBuilder {
            buf,
            last_header: None,
        }
    }
    /// Appends a submessage, aligning the previous one to 4 bytes.
    pub fn push(&mut self, sub: &Submessage<'_>) {
        super::append(&mut self.buf, &mut self.last_header, sub, true);
    }
    /// The message length so far, header included.
    pub fn len(&self) -> usize {
        self.buf.len()
    }
    /// True when only the header has been written.
    pub fn is_empty(&self) -> bool {
        self.buf.len() <= HEADER_LEN
    }
    /// The finished message.
    pub fn finish(self) -> Vec<u8> {
        self.buf
    }
}
