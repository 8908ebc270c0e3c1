//! What `dds-perf` needs from each ddsperf topic type: a sequence number, a key value and a size.

use dds_runtime::cdr::DdsType;

use crate::perf_args::TopicSel;
use crate::topic_types::{
    Keyed256, Keyed32, KeyedSeq, OneULong, Struct16, Struct256, Struct32k, Struct4k,
};

/// A ddsperf sample type.
pub trait PerfSample: DdsType + Clone + Send + Sync + 'static {
    /// Which `-T` selects it.
    const TOPIC: TopicSel;
    /// A sample with `seq`, key value 0 and `baggage` bytes of payload (KS only).
    fn make(seq: u32, baggage: u32) -> Self;
    /// The sequence number the publisher stamps.
    fn seq(&self) -> u32;
    /// Stamps the sequence number.
    fn set_seq(&mut self, seq: u32);
    /// 0 for unkeyed types.
    fn keyval(&self) -> u32;
    /// Ignored for unkeyed types.
    fn set_keyval(&mut self, k: u32);
    /// The size ddsperf reports for it.
    fn size(&self) -> u32 {
        Self::TOPIC.payload_size(0)
    }
}

impl PerfSample for KeyedSeq {
    const TOPIC: TopicSel = TopicSel::Ks;
    fn make(seq: u32, baggage: u32) -> Self {
        // ddsperf fills the baggage with 0xee.
        KeyedSeq {
            seq,
            keyval: 0,
            baggage: vec![0xee; baggage as usize],
        }
    }
    fn seq(&self) -> u32 {
        self.seq
    }
    fn set_seq(&mut self, seq: u32) {
        self.seq = seq;
    }
    fn keyval(&self) -> u32 {
        self.keyval
    }
    fn set_keyval(&mut self, k: u32) {
        self.keyval = k;
    }
    fn size(&self) -> u32 {
        TopicSel::Ks.payload_size(self.baggage.len() as u32)
    }
}

impl PerfSample for OneULong {
    const TOPIC: TopicSel = TopicSel::Ou;
    fn make(seq: u32, _: u32) -> Self {
        OneULong { seq }
    }
    fn seq(&self) -> u32 {
        self.seq
    }
    fn set_seq(&mut self, seq: u32) {
        self.seq = seq;
    }
    fn keyval(&self) -> u32 {
        0
    }
    fn set_keyval(&mut self, _: u32) {}
}

macro_rules! keyed_fixed {
    ($t:ty, $sel:expr) => {
        impl PerfSample for $t {
            const TOPIC: TopicSel = $sel;
            fn make(seq: u32, _: u32) -> Self {
                let mut s = <$t>::default();
                s.seq = seq;
                s
            }
            fn seq(&self) -> u32 {
                self.seq
            }
            fn set_seq(&mut self, seq: u32) {
                self.seq = seq;
            }
            fn keyval(&self) -> u32 {
                self.keyval
            }
            fn set_keyval(&mut self, k: u32) {
                self.keyval = k;
            }
        }
    };
}

keyed_fixed!(Keyed32, TopicSel::K32);
keyed_fixed!(Keyed256, TopicSel::K256);
keyed_fixed!(Struct16, TopicSel::S16);
keyed_fixed!(Struct256, TopicSel::S256);
keyed_fixed!(Struct4k, TopicSel::S4k);
keyed_fixed!(Struct32k, TopicSel::S32k);

#[cfg(test)]
mod tests {
    use super::*;
    use dds_runtime::cdr::{serialize, ByteOrder, XcdrVersion};

    #[test]
    fn sizes_match_the_encoding() {
        // XCDR1 body size (without the 4-byte header) equals ddsperf's reported size for fixed types.
        fn body<T: PerfSample>() -> usize {
            let mut v = Vec::new();
            serialize(
                &T::make(1, 0),
                XcdrVersion::Xcdr1,
                ByteOrder::LittleEndian,
                &mut v,
            )
            .expect("encodes");
            v.len() - 4
        }
        assert_eq!(body::<Keyed32>(), 32);
        assert_eq!(body::<Keyed256>(), 256);
        assert_eq!(body::<OneULong>(), 4);
        assert_eq!(body::<Struct16>(), 32);
        assert_eq!(body::<Struct256>(), 528);
        assert_eq!(KeyedSeq::make(0, 1012).size(), 1024);
    }
}
