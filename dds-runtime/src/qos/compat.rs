//! Requested/offered compatibility (DDS 1.4 §2.2.3, the "RxO" column) and partition matching.

use super::entities::{DataReaderQos, DataWriterQos, PublisherQos, SubscriberQos, TopicQos};
use super::policies::*;

/// Everything a writer announces in SEDP: its own QoS plus the publisher's and the topic's parts.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct WriterQos {
    /// The writer's own QoS.
    pub writer: DataWriterQos,
    /// The publisher's PRESENTATION.
    pub presentation: Presentation,
    /// The publisher's PARTITION.
    pub partition: Partition,
    /// The publisher's GROUP_DATA.
    pub group_data: GroupData,
    /// The topic's TOPIC_DATA.
    pub topic_data: TopicData,
}

impl WriterQos {
    /// The announced QoS of a writer of `publisher` on a topic with `topic` QoS.
    pub fn new(writer: DataWriterQos, publisher: &PublisherQos, topic: &TopicQos) -> Self {
        WriterQos {
            writer,
            presentation: publisher.presentation,
            partition: publisher.partition.clone(),
            group_data: publisher.group_data.clone(),
            topic_data: topic.topic_data.clone(),
        }
    }
}

impl From<DataWriterQos> for WriterQos {
    fn from(writer: DataWriterQos) -> Self {
        WriterQos {
            writer,
            ..Default::default()
        }
    }
}

/// Everything a reader announces in SEDP.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct ReaderQos {
    /// The reader's own QoS.
    pub reader: DataReaderQos,
    /// The subscriber's PRESENTATION.
    pub presentation: Presentation,
    /// The subscriber's PARTITION.
    pub partition: Partition,
    /// The subscriber's GROUP_DATA.
    pub group_data: GroupData,
    /// The topic's TOPIC_DATA.
    pub topic_data: TopicData,
}

impl ReaderQos {
    /// The announced QoS of a reader of `subscriber` on a topic with `topic` QoS.
    pub fn new(reader: DataReaderQos, subscriber: &SubscriberQos, topic: &TopicQos) -> Self {
        ReaderQos {
            reader,
            presentation: subscriber.presentation,
            partition: subscriber.partition.clone(),
            group_data: subscriber.group_data.clone(),
            topic_data: topic.topic_data.clone(),
        }
    }
}

impl From<DataReaderQos> for ReaderQos {
    fn from(reader: DataReaderQos) -> Self {
        ReaderQos {
            reader,
            ..Default::default()
        }
    }
}

/// Checks the RxO policies; returns the first incompatible policy.
/// Partitions are not an incompatibility (they simply do not match): see [`partitions_match`].
pub fn check_compatible(offered: &WriterQos, requested: &ReaderQos) -> Result<(), QosPolicyId> {
    let (w, r) = (&offered.writer, &requested.reader);
    if !w.reliability.is_reliable() && r.reliability.is_reliable() {
        return Err(QosPolicyId::Reliability);
    }
    if w.durability < r.durability {
        return Err(QosPolicyId::Durability);
    }
    let (op, rp) = (&offered.presentation, &requested.presentation);
    if op.access_scope < rp.access_scope
        || (rp.coherent_access && !op.coherent_access)
        || (rp.ordered_access && !op.ordered_access)
    {
        return Err(QosPolicyId::Presentation);
    }
    if w.deadline.0 > r.deadline.0 {
        return Err(QosPolicyId::Deadline);
    }
    if w.latency_budget.0 > r.latency_budget.0 {
        return Err(QosPolicyId::LatencyBudget);
    }
    if w.ownership != r.ownership {
        return Err(QosPolicyId::Ownership);
    }
    if w.liveliness.kind < r.liveliness.kind
        || w.liveliness.lease_duration > r.liveliness.lease_duration
    {
        return Err(QosPolicyId::Liveliness);
    }
    if w.destination_order < r.destination_order {
        return Err(QosPolicyId::DestinationOrder);
    }
    if !r
        .data_representation
        .accepts(w.data_representation.offered())
    {
        return Err(QosPolicyId::DataRepresentation);
    }
    Ok(())
}

/// Partition match (DDS 1.4 §2.2.3.13): an empty list is the default partition "". Names match when equal or
/// when exactly one of them is a pattern that matches the other.
pub fn partitions_match(a: &Partition, b: &Partition) -> bool {
    const DEFAULT: &[String] = &[String::new()];
    let a: &[String] = if a.0.is_empty() { DEFAULT } else { &a.0 };
    let b: &[String] = if b.0.is_empty() { DEFAULT } else { &b.0 };
    a.iter()
        .any(|x| b.iter().any(|y| partition_names_match(x, y)))
}

fn is_pattern(s: &str) -> bool {
    s.contains(['*', '?', '['])
}

fn partition_names_match(a: &str, b: &str) -> bool {
    if a == b {
        return true;
    }
    match (is_pattern(a), is_pattern(b)) {
        (true, false) => fnmatch(a.as_bytes(), b.as_bytes()),
        (false, true) => fnmatch(b.as_bytes(), a.as_bytes()),
        _ => false,
    }
}

/// POSIX fnmatch subset: `*`, `?`, `[...]` (with `!`/`^` negation and ranges) and `\` escapes.
/// Iterative with single-star backtracking, so it runs in O(|p|·|s|) at worst.
pub fn fnmatch(pattern: &[u8], s: &[u8]) -> bool {
    let (mut p, mut i) = (0usize, 0usize);
    let mut star: Option<(usize, usize)> = None;
    while i < s.len() {
        if p < pattern.len() {
            match pattern[p] {
                b'*' => {
                    star = Some((p, i));
                    p += 1;
                    continue;
                }
                b'?' => {
                    p += 1;
                    i += 1;
                    continue;
                }
                b'[' => {
                    if let Some((matched, next)) = match_class(pattern, p, s[i]) {
                        if matched {
                            p = next;
                            i += 1;
                            continue;
                        }
                    } else if s[i] == b'[' {
                        p += 1;
                        i += 1;
                        continue;
                    }
                }
                b'\\' if p + 1 < pattern.len() => {
                    if pattern[p + 1] == s[i] {
                        p += 2;
                        i += 1;
                        continue;
                    }
                }
                c => {
                    if c == s[i] {
                        p += 1;
                        i += 1;
                        continue;
                    }
                }
            }
        }
        match star {
            Some((sp, si)) => {
                p = sp + 1;
                i = si + 1;
                star = Some((sp, si + 1));
            }
            None => return false,
        }
    }
    pattern[p..].iter().all(|&c| c == b'*')
}

/// Returns (matched, index after the class) or None when the class is unterminated.
fn match_class(pattern: &[u8], start: usize, c: u8) -> Option<(bool, usize)> {
    let mut j = start + 1;
    let negate = matches!(pattern.get(j), Some(b'!') | Some(b'^'));
    if negate {
        j += 1;
    }
    let mut matched = false;
    let mut first = true;
    while j < pattern.len() {
        let lo = pattern[j];
        if lo == b']' && !first {
            return Some((matched != negate, j + 1));
        }
        first = false;
        if j + 2 < pattern.len() && pattern[j + 1] == b'-' && pattern[j + 2] != b']' {
            if lo <= c && c <= pattern[j + 2] {
                matched = true;
            }
            j += 3;
        } else {
            if lo == c {
                matched = true;
            }
            j += 1;
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::time::Duration;

    #[test]
    fn fnmatch_basics() {
        assert!(fnmatch(b"B*", b"Bee"));
        assert!(fnmatch(b"*", b""));
        assert!(fnmatch(b"a?c", b"abc"));
        assert!(!fnmatch(b"a?c", b"ac"));
        assert!(fnmatch(b"[a-c]x", b"bx"));
        assert!(!fnmatch(b"[!a-c]x", b"bx"));
        assert!(fnmatch(b"*x*y", b"axxbyy"));
        assert!(!fnmatch(b"abc", b"abd"));
        assert!(fnmatch(b"a\\*", b"a*"));
    }

    #[test]
    fn partitions() {
        assert!(partitions_match(
            &Partition::default(),
            &Partition::default()
        ));
        assert!(partitions_match(
            &Partition::new([""]),
            &Partition::default()
        ));
        assert!(!partitions_match(
            &Partition::new(["A"]),
            &Partition::default()
        ));
        assert!(partitions_match(
            &Partition::new(["A", "B*"]),
            &Partition::new(["Bx"])
        ));
        assert!(!partitions_match(
            &Partition::new(["A*"]),
            &Partition::new(["B*"])
        ));
        assert!(partitions_match(
            &Partition::new(["A*"]),
            &Partition::new(["A*"])
        ));
    }

    #[test]
    fn rxo() {
        let w = WriterQos::from(DataWriterQos::default());
        let r = ReaderQos::from(DataReaderQos::default());
        assert_eq!(check_compatible(&w, &r), Ok(()));
        let w_be = WriterQos::from(
            DataWriterQos::builder()
                .reliability(Reliability::BestEffort)
                .build(),
        );
        let r_rel = ReaderQos::from(
            DataReaderQos::builder()
                .reliability(Reliability::RELIABLE)
                .build(),
        );
        assert_eq!(
            check_compatible(&w_be, &r_rel),
            Err(QosPolicyId::Reliability)
        );
        let r_tl = ReaderQos::from(
            DataReaderQos::builder()
                .durability(Durability::TransientLocal)
                .build(),
        );
        assert_eq!(check_compatible(&w, &r_tl), Err(QosPolicyId::Durability));
        let r_dl = ReaderQos::from(
            DataReaderQos::builder()
                .deadline(Duration::from_secs(1))
                .build(),
        );
        assert_eq!(check_compatible(&w, &r_dl), Err(QosPolicyId::Deadline));
        let w2 = WriterQos::from(
            DataWriterQos::builder()
                .data_representation(DataRepresentation::xcdr2())
                .build(),
        );
        assert_eq!(
            check_compatible(&w2, &r),
            Err(QosPolicyId::DataRepresentation)
        );
        let r2 = ReaderQos::from(
            DataReaderQos::builder()
                .data_representation(vec![XCDR_DATA_REPRESENTATION, XCDR2_DATA_REPRESENTATION])
                .build(),
        );
        assert_eq!(check_compatible(&w2, &r2), Ok(()));
        let r_own = ReaderQos::from(
            DataReaderQos::builder()
                .ownership(Ownership::Exclusive)
                .build(),
        );
        assert_eq!(check_compatible(&w, &r_own), Err(QosPolicyId::Ownership));
    }
}
