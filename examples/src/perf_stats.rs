//! Statistics and the per-second lines of `dds-perf`, in ddsperf's format:
//!
//! ```text
//! [PID] 1.000  size 1024 total 273011 lost 0 delta 273011 lost 0 rate 272.99 kS/s 2236.33 Mb/s (27.30 kS/s 223.63 Mb/s)
//! [PID] 1.000  host:pid size 12 mean 17.123us min 12.000us 50% 16.500us 90% 20.000us 99% 30.000us max 45.000us cnt 1000
//! [PID] 1.000  255k/s   0n |@_____..._____................|   0%  50m
//! ```

use std::collections::HashMap;

/// `[pid] secs ` — every line starts with it.
pub fn prefix(pid: u32, secs: f64) -> String {
    format!("[{pid}] {secs:.3} ")
}

/// Raw latencies kept per interval for the percentiles (ddsperf's PINGPONG_RAWSIZE).
const RAW_MAX: usize = 20_000;

/// One interval of latency samples, in nanoseconds.
#[derive(Debug, Clone, Default)]
pub struct LatencyStat {
    min: i64,
    max: i64,
    sum: i64,
    cnt: u32,
    /// Round trips over the whole run (for `-Q roundtrips:N`).
    pub total: u64,
    raw: Vec<i64>,
}

impl LatencyStat {
    /// An empty interval.
    pub fn new() -> Self {
        LatencyStat {
            min: i64::MAX,
            max: i64::MIN,
            ..Default::default()
        }
    }

    /// Adds a latency of `ns` nanoseconds.
    pub fn record(&mut self, ns: i64) {
        self.min = self.min.min(ns);
        self.max = self.max.max(ns);
        self.sum += ns;
        if self.raw.len() < RAW_MAX {
            self.raw.push(ns);
        }
        self.cnt += 1;
        self.total += 1;
    }

    /// Latencies in this interval.
    pub fn count(&self) -> u32 {
        self.cnt
    }

    /// The percentile summary of this interval, then a reset; `None` when empty.
    pub fn take_summary(&mut self) -> Option<LatencySummary> {
        if self.cnt == 0 {
            return None;
        }
        self.raw.sort_unstable();
        let n = self.raw.len();
        // ddsperf's indices: raw[n - (n+1)/2], raw[n - (n+9)/10], raw[n - (n+99)/100].
        let pick = |d: usize| self.raw[n - (n + d) / (d + 1)] as f64 / 1e3;
        let s = LatencySummary {
            mean_us: self.sum as f64 / f64::from(self.cnt) / 1e3,
            min_us: self.min as f64 / 1e3,
            p50_us: pick(1),
            p90_us: pick(9),
            p99_us: pick(99),
            max_us: self.max as f64 / 1e3,
            count: self.cnt,
        };
        let total = self.total;
        self.raw.clear();
        *self = LatencyStat {
            total,
            raw: std::mem::take(&mut self.raw),
            ..LatencyStat::new()
        };
        Some(s)
    }
}

/// Percentiles of one interval, in microseconds.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LatencySummary {
    /// Mean.
    pub mean_us: f64,
    /// Minimum.
    pub min_us: f64,
    /// Median.
    pub p50_us: f64,
    /// 90th percentile.
    pub p90_us: f64,
    /// 99th percentile.
    pub p99_us: f64,
    /// Maximum.
    pub max_us: f64,
    /// Latencies summarised.
    pub count: u32,
}

/// `{prefix}{sub} {peer} size {size} mean ..us min ..us 50% ..us 90% ..us 99% ..us max ..us cnt N`.
pub fn latency_line(
    prefix: &str,
    subprefix: &str,
    peer: &str,
    size: u32,
    s: &LatencySummary,
) -> String {
    format!(
        "{prefix}{subprefix} {peer} size {size} mean {:.3}us min {:.3}us 50% {:.3}us 90% {:.3}us 99% {:.3}us max {:.3}us cnt {}",
        s.mean_us, s.min_us, s.p50_us, s.p90_us, s.p99_us, s.max_us, s.count
    )
}

#[derive(Debug, Clone, Copy, Default)]
struct Counts {
    nrecv: u64,
    nlost: u64,
    bytes: u64,
}

/// Per-publication receive accounting, ddsperf's `eseq_admin`: the next expected sequence number per
/// key value, losses, and a ring of per-second snapshots for the 10 s average.
#[derive(Debug)]
struct PubStat {
    expected: Vec<u32>,
    now: Counts,
    last_size: u32,
    refs: [Counts; 10],
    refidx: usize,
}

/// Receive statistics of `sub` mode across all publications.
#[derive(Debug)]
pub struct SubStats {
    nkeys: u32,
    pubs: HashMap<[u8; 16], PubStat>,
}

/// What [`SubStats::record`] found.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SeqCheck {
    /// The expected sequence number (or the first from this writer).
    InOrder,
    /// A gap (or reordering): `lost` more samples counted as lost.
    Gap {
        /// Sequence numbers skipped.
        lost: u32,
    },
    /// Behind the expected number (reordered or duplicated): neither a gap nor a loss.
    Late,
    /// `keyval` outside 0..nkeys: ddsperf exits with 3.
    BadKey,
}

impl SubStats {
    /// Statistics for data cycling through `nkeys` key values.
    pub fn new(nkeys: u32) -> Self {
        SubStats {
            nkeys: nkeys.max(1),
            pubs: HashMap::new(),
        }
    }

    /// Accounts one sample from writer `writer`.
    pub fn record(&mut self, writer: [u8; 16], seq: u32, keyval: u32, size: u32) -> SeqCheck {
        if keyval >= self.nkeys {
            return SeqCheck::BadKey;
        }
        let nkeys = self.nkeys;
        if let Some(p) = self.pubs.get_mut(&writer) {
            p.now.nrecv += 1;
            p.now.bytes += u64::from(size);
            p.last_size = size;
            let e = &mut p.expected[keyval as usize];
            // Distance from the expected number, modulo 2^32: the upper half is behind it.
            let ahead = seq.wrapping_sub(*e);
            if ahead > u32::MAX / 2 {
                // Late (reordered) or duplicate: already counted when the gap was seen; the
                // expectation stays where it is.
                return SeqCheck::Late;
            }
            *e = seq.wrapping_add(nkeys);
            p.now.nlost += u64::from(ahead);
            return if ahead == 0 {
                SeqCheck::InOrder
            } else {
                SeqCheck::Gap { lost: ahead }
            };
        }
        // First sample from this writer: the writer cycles through the keys, so the next expected
        // sequence number for key i is seq + (i - keyval), one round later for keys at or before keyval.
        let expected = (0..nkeys)
            .map(|i| {
                seq.wrapping_add(i.wrapping_sub(keyval))
                    .wrapping_add(if i <= keyval { nkeys } else { 0 })
            })
            .collect();
        let now = Counts {
            nrecv: 1,
            nlost: 0,
            bytes: u64::from(size),
        };
        self.pubs.insert(
            writer,
            PubStat {
                expected,
                now,
                last_size: size,
                refs: [Counts::default(); 10],
                refidx: 0,
            },
        );
        SeqCheck::InOrder
    }

    /// Samples lost over the whole run.
    pub fn total_lost(&self) -> u64 {
        self.pubs.values().map(|p| p.now.nlost).sum()
    }

    /// Samples received over the whole run.
    pub fn total_received(&self) -> u64 {
        self.pubs.values().map(|p| p.now.nrecv).sum()
    }

    /// The minimum number received from any one writer (for `-Q samples:N`).
    pub fn min_received_per_writer(&self) -> u64 {
        self.pubs.values().map(|p| p.now.nrecv).min().unwrap_or(0)
    }

    /// The per-second line (`None` when nothing arrived and `every_second` is off), advancing the
    /// snapshot ring. `dt_ns` is the time since the previous call.
    pub fn second_line(&mut self, prefix: &str, dt_ns: f64, every_second: bool) -> Option<String> {
        let (mut tot_recv, mut tot_lost, mut nrecv, mut nlost, mut bytes, mut nrecv10, mut bytes10) =
            (0, 0, 0, 0, 0, 0, 0);
        let mut last_size = 0;
        for p in self.pubs.values_mut() {
            let r1 = p.refs[(p.refidx + 9) % 10];
            let r10 = p.refs[p.refidx];
            tot_recv += p.now.nrecv;
            tot_lost += p.now.nlost;
            nrecv += p.now.nrecv - r1.nrecv;
            nlost += p.now.nlost - r1.nlost;
            bytes += p.now.bytes - r1.bytes;
            nrecv10 += p.now.nrecv - r10.nrecv;
            bytes10 += p.now.bytes - r10.bytes;
            last_size = p.last_size;
            p.refs[p.refidx] = p.now;
            p.refidx = (p.refidx + 1) % 10;
        }
        if nrecv == 0 && !every_second {
            return None;
        }
        let dt = dt_ns.max(1.0);
        Some(format!(
            "{prefix} size {last_size} total {tot_recv} lost {tot_lost} delta {nrecv} lost {nlost} rate {:.2} kS/s {:.2} Mb/s ({:.2} kS/s {:.2} Mb/s)",
            nrecv as f64 * 1e6 / dt,
            bytes as f64 * 8.0 * 1e3 / dt,
            nrecv10 as f64 * 1e6 / (10.0 * dt),
            bytes10 as f64 * 8.0 * 1e3 / (10.0 * dt),
        ))
    }
}

/// Histogram of write() durations for the `pub` line (30 bins of 1 µs, like ddsperf).
#[derive(Debug, Clone)]
pub struct WriteHist {
    bins: [u64; 30],
    over: u64,
    min: u64,
    max: u64,
}

impl Default for WriteHist {
    fn default() -> Self {
        WriteHist {
            bins: [0; 30],
            over: 0,
            min: u64::MAX,
            max: 0,
        }
    }
}

fn fmt_ns(x: u64) -> String {
    if x < 1000 {
        format!("{x:3}n")
    } else if x + 500 < 1_000_000 {
        format!("{:3}u", (x + 500) / 1000)
    } else if x + 500_000 < 1_000_000_000 {
        format!("{:3}m", (x + 500_000) / 1_000_000)
    } else {
        format!("{:3}s", (x + 500_000_000) / 1_000_000_000)
    }
}

/// C's `%.3g` for the values the pub line shows (0 <= v < 1e6): three significant digits, no
/// trailing zeros.
fn fmt_g3(v: f64) -> String {
    if v == 0.0 || !v.is_finite() {
        return "0".into();
    }
    let exp = v.abs().log10().floor() as i32;
    let s = if !(-4..3).contains(&exp) {
        format!("{v:.2e}")
    } else {
        let decimals = (2 - exp).max(0) as usize;
        format!("{v:.decimals$}")
    };
    if s.contains('.') && !s.contains('e') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    }
}

impl WriteHist {
    /// Adds a write that took `ns` nanoseconds.
    pub fn record(&mut self, ns: u64) {
        self.min = self.min.min(ns);
        self.max = self.max.max(ns);
        match self.bins.get_mut((ns / 1000) as usize) {
            Some(b) => *b += 1,
            None => self.over += 1,
        }
    }

    /// ddsperf's pub line (rate, min, histogram, share above the last bin, max), then a reset.
    pub fn take_line(&mut self, prefix: &str, dt_ns: f64) -> String {
        let cnt: u64 = self.bins.iter().sum::<u64>() + self.over;
        let peak = self.bins.iter().copied().max().unwrap_or(0);
        let hist: String = self
            .bins
            .iter()
            .map(|&b| match b {
                0 => ' ',
                b if b <= peak / 100 => '.',
                b if b <= peak / 10 => '_',
                b if b <= peak / 5 => '-',
                b if b <= 2 * peak / 5 => '=',
                b if b <= 3 * peak / 5 => 'x',
                b if b <= 4 * peak / 5 => 'X',
                _ => '@',
            })
            .collect();
        let avg = cnt as f64 / (dt_ns.max(1.0) / 1e9);
        let rate = if avg < 999.5 {
            format!("{:>5}", fmt_g3(avg))
        } else if avg < 1e6 {
            format!("{:>4}k", fmt_g3(avg / 1e3))
        } else {
            format!("{:>4}M", fmt_g3(avg / 1e6))
        };
        let min = if self.min == u64::MAX {
            " inf".to_string()
        } else {
            fmt_ns(self.min)
        };
        let pct = 100 * (self.over + cnt / 2).checked_div(cnt).unwrap_or(0);
        let line = format!(
            "{prefix}{rate}/s {min} |{hist}| {pct:3}% {}",
            fmt_ns(self.max)
        );
        *self = WriteHist::default();
        line
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sequence_tracking_counts_gaps_per_key() {
        let w = [1u8; 16];
        let mut s = SubStats::new(2);
        // Writer cycles keys 0,1,0,1 with seq 10,11,12,13.
        assert_eq!(s.record(w, 10, 0, 100), SeqCheck::InOrder);
        assert_eq!(s.record(w, 11, 1, 100), SeqCheck::InOrder);
        assert_eq!(s.record(w, 12, 0, 100), SeqCheck::InOrder);
        // seq 13 (key 1) lost, next for key 0 is 14 arriving fine, then key 1 gets 15.
        assert_eq!(s.record(w, 14, 0, 100), SeqCheck::InOrder);
        assert_eq!(s.record(w, 15, 1, 100), SeqCheck::Gap { lost: 2 });
        assert_eq!(s.total_lost(), 2);
        assert_eq!(s.total_received(), 5);
        assert_eq!(s.record(w, 0, 7, 100), SeqCheck::BadKey);
    }

    #[test]
    fn late_samples_are_not_lost_again() {
        // Issue 11: a block arriving late once counted as 2^32 - k - 1 lost samples ("lost 4294967296").
        let w = [2u8; 16];
        let mut s = SubStats::new(1);
        for seq in 0..3 {
            assert_eq!(s.record(w, seq, 0, 16), SeqCheck::InOrder);
        }
        assert_eq!(s.record(w, 5, 0, 16), SeqCheck::Gap { lost: 2 });
        assert_eq!(s.record(w, 3, 0, 16), SeqCheck::Late);
        assert_eq!(s.record(w, 4, 0, 16), SeqCheck::Late);
        assert_eq!(s.record(w, 5, 0, 16), SeqCheck::Late);
        assert_eq!(s.record(w, 6, 0, 16), SeqCheck::InOrder);
        assert_eq!(s.total_lost(), 2);
        assert_eq!(s.total_received(), 8);
        // Across the wrap of the 32-bit sequence number.
        let w = [3u8; 16];
        assert_eq!(s.record(w, u32::MAX - 1, 0, 16), SeqCheck::InOrder);
        assert_eq!(s.record(w, u32::MAX, 0, 16), SeqCheck::InOrder);
        assert_eq!(s.record(w, 0, 0, 16), SeqCheck::InOrder);
        assert_eq!(s.record(w, 2, 0, 16), SeqCheck::Gap { lost: 1 });
        assert_eq!(s.total_lost(), 3);
    }

    #[test]
    fn sub_line_format() {
        let mut s = SubStats::new(1);
        for i in 0..1000 {
            s.record([2; 16], i, 0, 1024);
        }
        let l = s.second_line(&prefix(42, 1.0), 1e9, false).expect("line");
        assert_eq!(
            l,
            "[42] 1.000  size 1024 total 1000 lost 0 delta 1000 lost 0 rate 1.00 kS/s 8.19 Mb/s (0.10 kS/s 0.82 Mb/s)"
        );
        assert_eq!(s.second_line(&prefix(42, 2.0), 1e9, false), None);
        assert!(s
            .second_line(&prefix(42, 3.0), 1e9, true)
            .expect("forced")
            .contains("delta 0 lost 0"));
    }

    #[test]
    fn latency_percentiles() {
        let mut l = LatencyStat::new();
        for v in 1..=100 {
            l.record(v * 1000);
        }
        let s = l.take_summary().expect("summary");
        assert_eq!(s.count, 100);
        assert_eq!(s.min_us, 1.0);
        assert_eq!(s.max_us, 100.0);
        assert_eq!(s.p50_us, 51.0);
        assert_eq!(s.p90_us, 91.0);
        assert_eq!(s.p99_us, 100.0);
        assert!(l.take_summary().is_none());
        assert_eq!(l.total, 100);
        let line = latency_line(&prefix(7, 1.0), "", "host:7", 12, &s);
        assert!(
            line.starts_with("[7] 1.000  host:7 size 12 mean 50.500us min 1.000us 50% 51.000us"),
            "{line}"
        );
        assert!(line.ends_with("cnt 100"));
    }

    #[test]
    fn write_histogram_line() {
        let mut h = WriteHist::default();
        for _ in 0..10 {
            h.record(500);
        }
        h.record(80_000_000);
        let l = h.take_line("[1] 1.000 ", 1e9);
        assert!(l.starts_with("[1] 1.000    11/s 500n |@"), "{l}");
        assert!(l.ends_with(" 80m"), "{l}");
    }
}
