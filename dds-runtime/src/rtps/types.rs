//! Basic RTPS value types (DDSI-RTPS 2.5 §8.2, §9.3).

use std::fmt;
use std::time::Duration;

/// The 12-byte prefix shared by a participant and all its entities (§8.2.4.3).
#[derive(Clone, Copy, PartialEq, Eq, Hash, Default)]
pub struct GuidPrefix(pub [u8; 12]);

/// Ordered as the bytes are (lexicographically), compared as one big-endian word: the participant's maps
/// are searched by GUID per sample, and a byte array's comparison goes byte by byte.
impl Ord for GuidPrefix {
    fn cmp(&self, other: &Self) -> std::cmp::Ordering {
        let word = |p: &GuidPrefix| {
            let mut b = [0u8; 16];
            b[..12].copy_from_slice(&p.0);
            u128::from_be_bytes(b)
        };
        word(self).cmp(&word(other))
    }
}

impl PartialOrd for GuidPrefix {
    fn partial_cmp(&self, other: &Self) -> Option<std::cmp::Ordering> {
        Some(self.cmp(other))
    }
}

impl GuidPrefix {
    /// GUIDPREFIX_UNKNOWN.
    pub const UNKNOWN: GuidPrefix = GuidPrefix([0; 12]);
}

impl fmt::Debug for GuidPrefix {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for (i, b) in self.0.iter().enumerate() {
            if i > 0 && i % 4 == 0 {
                f.write_str(":")?;
            }
            write!(f, "{b:02x}")?;
        }
        Ok(())
    }
}

/// The 4-byte id of an entity within its participant (§9.3.1.2): a 3-byte key and a kind octet.
#[derive(Clone, Copy, PartialEq, Eq, Hash, Default)]
pub struct EntityId(pub [u8; 4]);

/// Ordered as the bytes are, compared as one big-endian word (the participant's endpoint maps are
/// searched by entity id per sample; a byte array's comparison goes byte by byte).
impl Ord for EntityId {
    fn cmp(&self, other: &Self) -> std::cmp::Ordering {
        u32::from_be_bytes(self.0).cmp(&u32::from_be_bytes(other.0))
    }
}

impl PartialOrd for EntityId {
    fn partial_cmp(&self, other: &Self) -> Option<std::cmp::Ordering> {
        Some(self.cmp(other))
    }
}

impl fmt::Debug for EntityId {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{:08x}", u32::from_be_bytes(self.0))
    }
}

/// Entity kinds: the last byte of an [`EntityId`].
pub mod entity_kind {
    /// A user writer of a keyed topic.
    pub const USER_WRITER_WITH_KEY: u8 = 0x02;
    /// A user writer of a keyless topic.
    pub const USER_WRITER_NO_KEY: u8 = 0x03;
    /// A user reader of a keyless topic.
    pub const USER_READER_NO_KEY: u8 = 0x04;
    /// A user reader of a keyed topic.
    pub const USER_READER_WITH_KEY: u8 = 0x07;
    /// A user-defined writer group (a publisher).
    pub const USER_WRITER_GROUP: u8 = 0x08;
    /// A builtin participant.
    pub const BUILTIN_PARTICIPANT: u8 = 0xc1;
    /// A builtin writer of a keyed topic.
    pub const BUILTIN_WRITER_WITH_KEY: u8 = 0xc2;
    /// A builtin writer of a keyless topic.
    pub const BUILTIN_WRITER_NO_KEY: u8 = 0xc3;
    /// A builtin reader of a keyless topic.
    pub const BUILTIN_READER_NO_KEY: u8 = 0xc4;
    /// A builtin reader of a keyed topic.
    pub const BUILTIN_READER_WITH_KEY: u8 = 0xc7;
}

impl EntityId {
    /// ENTITYID_UNKNOWN: any reader (as a DATA destination) or unknown.
    pub const UNKNOWN: EntityId = EntityId([0, 0, 0, 0]);
    /// The participant itself.
    pub const PARTICIPANT: EntityId = EntityId([0, 0, 1, 0xc1]);
    /// SEDP topics writer (not implemented).
    pub const SEDP_TOPICS_WRITER: EntityId = EntityId([0, 0, 2, 0xc2]);
    /// SEDP topics reader (not implemented).
    pub const SEDP_TOPICS_READER: EntityId = EntityId([0, 0, 2, 0xc7]);
    /// SEDP publications writer: announces our writers.
    pub const SEDP_PUBLICATIONS_WRITER: EntityId = EntityId([0, 0, 3, 0xc2]);
    /// SEDP publications reader: learns remote writers.
    pub const SEDP_PUBLICATIONS_READER: EntityId = EntityId([0, 0, 3, 0xc7]);
    /// SEDP subscriptions writer: announces our readers.
    pub const SEDP_SUBSCRIPTIONS_WRITER: EntityId = EntityId([0, 0, 4, 0xc2]);
    /// SEDP subscriptions reader: learns remote readers.
    pub const SEDP_SUBSCRIPTIONS_READER: EntityId = EntityId([0, 0, 4, 0xc7]);
    /// SPDP writer: announces the participant.
    pub const SPDP_WRITER: EntityId = EntityId([0, 1, 0, 0xc2]);
    /// SPDP reader: learns remote participants.
    pub const SPDP_READER: EntityId = EntityId([0, 1, 0, 0xc7]);
    /// Participant message writer (liveliness).
    pub const P2P_MESSAGE_WRITER: EntityId = EntityId([0, 2, 0, 0xc2]);
    /// Participant message reader (liveliness).
    pub const P2P_MESSAGE_READER: EntityId = EntityId([0, 2, 0, 0xc7]);
    /// XTypes type lookup request writer.
    pub const TYPELOOKUP_REQUEST_WRITER: EntityId = EntityId([0, 3, 0, 0xc3]);
    /// XTypes type lookup request reader.
    pub const TYPELOOKUP_REQUEST_READER: EntityId = EntityId([0, 3, 0, 0xc4]);
    /// XTypes type lookup reply writer.
    pub const TYPELOOKUP_REPLY_WRITER: EntityId = EntityId([0, 3, 1, 0xc3]);
    /// XTypes type lookup reply reader.
    pub const TYPELOOKUP_REPLY_READER: EntityId = EntityId([0, 3, 1, 0xc4]);

    /// An id from its 3-byte key and kind octet (see [`entity_kind`]).
    pub fn new(key: [u8; 3], kind: u8) -> Self {
        EntityId([key[0], key[1], key[2], kind])
    }
    /// The kind octet (see [`entity_kind`]).
    pub fn kind(&self) -> u8 {
        self.0[3]
    }
    /// Whether this is a builtin (discovery or liveliness) entity.
    pub fn is_builtin(&self) -> bool {
        self.0[3] & 0xc0 == 0xc0
    }
    /// Whether this entity is a writer.
    pub fn is_writer(&self) -> bool {
        matches!(self.0[3] & 0x3f, 0x02 | 0x03)
    }
    /// Whether this entity is a reader.
    pub fn is_reader(&self) -> bool {
        matches!(self.0[3] & 0x3f, 0x04 | 0x07)
    }
    /// Whether the entity's topic is keyed.
    pub fn is_keyed(&self) -> bool {
        matches!(self.0[3] & 0x3f, 0x02 | 0x07)
    }
}

/// A globally unique entity id (§8.2.4.1): participant prefix plus entity id.
#[derive(Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Default)]
pub struct Guid {
    /// The participant's GUID prefix.
    pub prefix: GuidPrefix,
    /// The entity within the participant.
    pub entity_id: EntityId,
}

/// Hashed as one 128-bit word, not as two length-prefixed byte arrays: the receive path looks a writer's
/// GUID up for every sample. Equal GUIDs have equal bytes, so this agrees with `Eq`.
impl std::hash::Hash for Guid {
    fn hash<H: std::hash::Hasher>(&self, state: &mut H) {
        let mut b = [0u8; 16];
        b[..12].copy_from_slice(&self.prefix.0);
        b[12..].copy_from_slice(&self.entity_id.0);
        state.write_u128(u128::from_ne_bytes(b));
    }
}

impl Guid {
    /// GUID_UNKNOWN.
    pub const UNKNOWN: Guid = Guid {
        prefix: GuidPrefix::UNKNOWN,
        entity_id: EntityId::UNKNOWN,
    };

    /// The GUID of `entity_id` in the participant `prefix`.
    pub fn new(prefix: GuidPrefix, entity_id: EntityId) -> Self {
        Guid { prefix, entity_id }
    }
    /// The 16 bytes on the wire (also the key hash of builtin topics).
    pub fn to_bytes(&self) -> [u8; 16] {
        let mut b = [0u8; 16];
        b[..12].copy_from_slice(&self.prefix.0);
        b[12..].copy_from_slice(&self.entity_id.0);
        b
    }
    /// From the 16 bytes on the wire.
    pub fn from_bytes(b: [u8; 16]) -> Self {
        let mut p = [0u8; 12];
        p.copy_from_slice(&b[..12]);
        Guid {
            prefix: GuidPrefix(p),
            entity_id: EntityId([b[12], b[13], b[14], b[15]]),
        }
    }
}

impl fmt::Debug for Guid {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{:?}:{:?}", self.prefix, self.entity_id)
    }
}

/// Vendor ids (DDSI-RTPS §8.3.3.1 and the OMG vendor list).
#[derive(Clone, Copy, PartialEq, Eq, Hash, Debug, Default)]
pub struct VendorId(pub [u8; 2]);

impl VendorId {
    /// No vendor given.
    pub const UNKNOWN: VendorId = VendorId([0, 0]);
    /// RTI Connext.
    pub const RTI: VendorId = VendorId([1, 1]);
    /// OpenDDS.
    pub const OPENDDS: VendorId = VendorId([1, 3]);
    /// eProsima Fast DDS.
    pub const FASTDDS: VendorId = VendorId([1, 0x0f]);
    /// Eclipse Cyclone DDS.
    pub const CYCLONE: VendorId = VendorId([1, 0x10]);
    /// Ours. The OMG list assigns 0x0101..=0x0121 (as of 2025; RustDDS 0x0112, Dust DDS 0x0121 among them);
    /// 0x01dd ("DDs") is far above the last assigned id and is not known to be used by anyone.
    pub const THIS: VendorId = VendorId([0x01, 0xdd]);
}

/// An RTPS protocol version.
#[derive(Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Debug)]
pub struct ProtocolVersion {
    /// Major version; messages with another major version are dropped.
    pub major: u8,
    /// Minor version.
    pub minor: u8,
}

impl ProtocolVersion {
    /// RTPS 2.5, the version we speak.
    pub const V2_5: ProtocolVersion = ProtocolVersion { major: 2, minor: 5 };
}

/// A locator. `address` holds IPv4 addresses in its last 4 bytes.
#[derive(Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct Locator {
    /// The transport kind (`KIND_*`).
    pub kind: i32,
    /// The port.
    pub port: u32,
    /// The address; IPv4 addresses in the last four bytes.
    pub address: [u8; 16],
}

impl Locator {
    /// LOCATOR_KIND_INVALID.
    pub const KIND_INVALID: i32 = -1;
    /// LOCATOR_KIND_RESERVED.
    pub const KIND_RESERVED: i32 = 0;
    /// LOCATOR_KIND_UDPv4.
    pub const KIND_UDPV4: i32 = 1;
    /// LOCATOR_KIND_UDPv6.
    pub const KIND_UDPV6: i32 = 2;

    /// A UDPv4 locator.
    pub fn udpv4(ip: [u8; 4], port: u16) -> Self {
        let mut address = [0u8; 16];
        address[12..].copy_from_slice(&ip);
        Locator {
            kind: Self::KIND_UDPV4,
            port: port as u32,
            address,
        }
    }
    /// The IPv4 address when this is a UDPv4 locator.
    pub fn ipv4(&self) -> Option<[u8; 4]> {
        (self.kind == Self::KIND_UDPV4).then(|| {
            [
                self.address[12],
                self.address[13],
                self.address[14],
                self.address[15],
            ]
        })
    }
    /// Whether the address is an IPv4 or IPv6 multicast address.
    pub fn is_multicast(&self) -> bool {
        match self.kind {
            Self::KIND_UDPV4 => (224..=239).contains(&self.address[12]),
            Self::KIND_UDPV6 => self.address[0] == 0xff,
            _ => false,
        }
    }
    /// The socket address of a UDP locator; `None` for other kinds.
    pub fn to_socket_addr(&self) -> Option<std::net::SocketAddr> {
        let port = u16::try_from(self.port).ok()?;
        match self.kind {
            Self::KIND_UDPV4 => Some(std::net::SocketAddr::from((self.ipv4()?, port))),
            Self::KIND_UDPV6 => Some(std::net::SocketAddr::from((self.address, port))),
            _ => None,
        }
    }
    /// The UDP locator for a socket address.
    pub fn from_socket_addr(a: std::net::SocketAddr) -> Self {
        match a {
            std::net::SocketAddr::V4(v4) => Locator::udpv4(v4.ip().octets(), v4.port()),
            std::net::SocketAddr::V6(v6) => Locator {
                kind: Self::KIND_UDPV6,
                port: v6.port() as u32,
                address: v6.ip().octets(),
            },
        }
    }
}

impl fmt::Debug for Locator {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.to_socket_addr() {
            Some(a) => write!(f, "udp/{a}"),
            None => write!(f, "locator(kind {}, port {})", self.kind, self.port),
        }
    }
}

/// A 64-bit sequence number; valid ones start at 1.
#[derive(Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Debug, Default)]
pub struct SequenceNumber(pub i64);

impl SequenceNumber {
    /// SEQUENCENUMBER_UNKNOWN.
    pub const UNKNOWN: SequenceNumber = SequenceNumber((-1i64) << 32);
    /// From the high and low halves on the wire.
    pub fn from_parts(high: i32, low: u32) -> Self {
        SequenceNumber(((high as i64) << 32) | low as i64)
    }
    /// The high half on the wire.
    pub fn high(self) -> i32 {
        (self.0 >> 32) as i32
    }
    /// The low half on the wire.
    pub fn low(self) -> u32 {
        self.0 as u32
    }
    /// The following sequence number (saturating).
    pub fn next(self) -> Self {
        SequenceNumber(self.0.saturating_add(1))
    }
}

impl std::ops::Add<i64> for SequenceNumber {
    type Output = SequenceNumber;
    fn add(self, rhs: i64) -> SequenceNumber {
        SequenceNumber(self.0.saturating_add(rhs))
    }
}

/// Bitmap set over a window of 256 numbers starting at `base` (§9.4.2.6). Used for sequence and fragment numbers.
#[derive(Clone, Copy, PartialEq, Eq, Debug)]
pub struct NumberSet<T> {
    /// The first number of the window.
    pub base: T,
    /// How many bits of the window are meaningful (≤ 256).
    pub num_bits: u32,
    /// The bits, most significant first: bit `i` stands for `base + i`.
    pub bitmap: [u32; 8],
}

/// A set of sequence numbers (SequenceNumberSet).
pub type SequenceNumberSet = NumberSet<SequenceNumber>;
/// A set of fragment numbers (FragmentNumberSet).
pub type FragmentNumberSet = NumberSet<u32>;

impl<T: Copy> NumberSet<T> {
    /// The largest window.
    pub const MAX_BITS: u32 = 256;

    /// An empty set starting at `base`.
    pub fn empty(base: T) -> Self {
        NumberSet {
            base,
            num_bits: 0,
            bitmap: [0; 8],
        }
    }
    /// Sets bit `offset` (0-based from base), growing num_bits; ignores offsets >= 256.
    pub fn insert_offset(&mut self, offset: u32) {
        if offset < Self::MAX_BITS {
            self.bitmap[(offset / 32) as usize] |= 1 << (31 - offset % 32);
            self.num_bits = self.num_bits.max(offset + 1);
        }
    }
    /// Whether bit `offset` (0-based from base) is set.
    pub fn contains_offset(&self, offset: u32) -> bool {
        offset < self.num_bits
            && self.bitmap[(offset / 32) as usize] & (1 << (31 - offset % 32)) != 0
    }
    /// Offsets of the set bits, ascending.
    pub fn offsets(&self) -> impl Iterator<Item = u32> + '_ {
        (0..self.num_bits.min(Self::MAX_BITS)).filter(move |&o| self.contains_offset(o))
    }
    /// The bitmap words the wire carries (`ceil(num_bits / 32)`).
    pub fn words(&self) -> &[u32] {
        &self.bitmap[..self.num_bits.div_ceil(32) as usize]
    }
}

impl SequenceNumberSet {
    /// The sequence numbers in the set, ascending.
    pub fn iter(&self) -> impl Iterator<Item = SequenceNumber> + '_ {
        let base = self.base;
        self.offsets().map(move |o| base + o as i64)
    }
    /// Adds `sn` if it lies in the window; returns whether it did.
    pub fn insert(&mut self, sn: SequenceNumber) -> bool {
        let off = sn.0.wrapping_sub(self.base.0);
        if (0..256).contains(&off) {
            self.insert_offset(off as u32);
            true
        } else {
            false
        }
    }
}

impl FragmentNumberSet {
    /// The fragment numbers in the set, ascending.
    pub fn iter(&self) -> impl Iterator<Item = u32> + '_ {
        let base = self.base;
        self.offsets().map(move |o| base.wrapping_add(o))
    }
    /// Adds fragment `n` if it lies in the window; returns whether it did.
    pub fn insert(&mut self, n: u32) -> bool {
        let off = n.wrapping_sub(self.base);
        if off < 256 {
            self.insert_offset(off);
            true
        } else {
            false
        }
    }
}

/// RTPS wire time: seconds and 2^-32 fractions since the Unix epoch.
#[derive(Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Debug, Default)]
pub struct Time {
    /// Seconds since the Unix epoch.
    pub seconds: i32,
    /// Fractions of a second, in units of 2^-32 s.
    pub fraction: u32,
}

impl Time {
    /// TIME_ZERO.
    pub const ZERO: Time = Time {
        seconds: 0,
        fraction: 0,
    };
    /// TIME_INVALID.
    pub const INVALID: Time = Time {
        seconds: -1,
        fraction: 0xffff_ffff,
    };
    /// TIME_INFINITE.
    pub const INFINITE: Time = Time {
        seconds: 0x7fff_ffff,
        fraction: 0xffff_ffff,
    };

    /// From a duration since the Unix epoch (what `SystemTime::now().duration_since(UNIX_EPOCH)` gives).
    pub fn from_unix(d: Duration) -> Self {
        let secs = d.as_secs().min(0x7fff_ffff) as i32;
        // Rounded up so that to_unix() gives back the same nanosecond (ddsperf flags pings in the lsb).
        let fraction = ((d.subsec_nanos() as u64) << 32).div_ceil(1_000_000_000);
        Time {
            seconds: secs,
            fraction: fraction as u32,
        }
    }
    /// The duration since the Unix epoch; `None` for negative, invalid or infinite times.
    pub fn to_unix(self) -> Option<Duration> {
        if self.seconds < 0 || self == Time::INFINITE {
            return None;
        }
        let nanos = ((self.fraction as u64) * 1_000_000_000) >> 32;
        Some(Duration::new(self.seconds as u64, nanos as u32))
    }
}

/// Converts a QoS/lease duration to the RTPS Duration_t wire form {seconds, fraction}; `Duration::MAX` and
/// anything beyond i32 seconds is DURATION_INFINITE.
pub fn duration_to_wire(d: Duration) -> (i32, u32) {
    if d.as_secs() >= 0x7fff_ffff {
        return (0x7fff_ffff, 0xffff_ffff);
    }
    // Round up so a non-zero duration never becomes zero.
    let frac = ((d.subsec_nanos() as u64) << 32).div_ceil(1_000_000_000);
    if frac >= 1 << 32 {
        (d.as_secs() as i32 + 1, 0)
    } else {
        (d.as_secs() as i32, frac as u32)
    }
}

/// The inverse of [`duration_to_wire`]; negative values become zero.
pub fn duration_from_wire(seconds: i32, fraction: u32) -> Duration {
    if seconds == 0x7fff_ffff && fraction == 0xffff_ffff {
        return Duration::MAX;
    }
    if seconds < 0 {
        return Duration::ZERO;
    }
    let nanos = ((fraction as u64) * 1_000_000_000) >> 32;
    Duration::new(seconds as u64, nanos as u32)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sn_parts() {
        let sn = SequenceNumber::from_parts(1, 5);
        assert_eq!(sn.0, (1 << 32) + 5);
        assert_eq!((sn.high(), sn.low()), (1, 5));
    }

    #[test]
    fn ids_order_as_their_bytes() {
        let bytes = [
            [0u8, 0, 1, 0xc2],
            [0, 0, 1, 0xc7],
            [0, 1, 0, 0x02],
            [0xff, 0, 0, 0],
            [0, 0, 0, 0],
        ];
        for a in bytes {
            for b in bytes {
                assert_eq!(EntityId(a).cmp(&EntityId(b)), a.cmp(&b));
                let (mut pa, mut pb) = ([7u8; 12], [7u8; 12]);
                pa[3..7].copy_from_slice(&a);
                pb[8..].copy_from_slice(&b);
                assert_eq!(GuidPrefix(pa).cmp(&GuidPrefix(pb)), pa.cmp(&pb));
            }
        }
    }

    #[test]
    fn durations() {
        assert_eq!(duration_to_wire(Duration::MAX), (0x7fff_ffff, 0xffff_ffff));
        assert_eq!(duration_from_wire(0x7fff_ffff, 0xffff_ffff), Duration::MAX);
        let d = Duration::from_millis(100);
        let (s, f) = duration_to_wire(d);
        assert_eq!((s, f), (0, 0x1999_999a));
        let back = duration_from_wire(s, f);
        assert!(back.abs_diff(d) < Duration::from_nanos(2));
    }

    #[test]
    fn sets() {
        let mut s = SequenceNumberSet::empty(SequenceNumber(10));
        assert!(s.insert(SequenceNumber(10)));
        assert!(s.insert(SequenceNumber(45)));
        assert!(!s.insert(SequenceNumber(300)));
        assert_eq!(
            s.iter().collect::<Vec<_>>(),
            vec![SequenceNumber(10), SequenceNumber(45)]
        );
        assert_eq!(s.num_bits, 36);
        assert_eq!(s.words().len(), 2);
    }
}
