//! Command line of `dds-perf`, compatible with Cyclone DDS's `ddsperf`:
//! `dds-perf [OPTIONS] MODE...` with modes `ping`, `pong`, `sub` and `pub`.

use std::fmt;
use std::time::Duration;

/// ddsperf's `-T` topics (the subset both stacks know).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TopicSel {
    /// KeyedSeq: seq, keyval, `sequence<octet>` (default).
    Ks,
    /// Keyed32.
    K32,
    /// Keyed256.
    K256,
    /// OneULong.
    Ou,
    /// Struct16.
    S16,
    /// Struct256.
    S256,
    /// Struct4k.
    S4k,
    /// Struct32k.
    S32k,
}

impl TopicSel {
    /// The topic-name suffix ddsperf uses ("DDSPerfRData" + suffix).
    pub fn suffix(self) -> &'static str {
        match self {
            TopicSel::Ks => "KS",
            TopicSel::K32 => "K32",
            TopicSel::K256 => "K256",
            TopicSel::Ou => "OU",
            TopicSel::S16 => "S16",
            TopicSel::S256 => "S256",
            TopicSel::S4k => "S4k",
            TopicSel::S32k => "S32k",
        }
    }

    fn parse(s: &str) -> Option<Self> {
        Some(match s {
            "KS" => TopicSel::Ks,
            "K32" => TopicSel::K32,
            "K256" => TopicSel::K256,
            "OU" => TopicSel::Ou,
            "S16" => TopicSel::S16,
            "S256" => TopicSel::S256,
            "S4k" => TopicSel::S4k,
            "S32k" => TopicSel::S32k,
            _ => return None,
        })
    }

    /// ddsperf's `topic_payload_size`: the size it reports for a sample.
    pub fn payload_size(self, baggage: u32) -> u32 {
        match self {
            TopicSel::Ks => 12 + baggage,
            TopicSel::K32 => 32,
            TopicSel::K256 => 256,
            TopicSel::Ou => 4,
            // sizeof() of the C structs: 16 octets + int64 + 2 x uint32, recursively.
            TopicSel::S16 => 32,
            TopicSel::S256 => 16 * 32 + 16,
            TopicSel::S4k => 16 * (16 * 32 + 16) + 16,
            TopicSel::S32k => 8 * (16 * (16 * 32 + 16) + 16) + 16,
        }
    }

    /// Whether the type has the `keyval` key.
    pub fn keyed(self) -> bool {
        self != TopicSel::Ou
    }
}

/// How a reader is serviced: in a listener on the receive thread (ddsperf's default), by a thread waiting
/// for data, or by a thread polling at 1 kHz.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TriggerMode {
    /// `listener`: serviced on the receive thread.
    Listener,
    /// `waitset`: a thread waits for data.
    Waitset,
    /// `polling`: a thread polls at 1 kHz.
    Polling,
}

/// Everything the command line sets.
#[derive(Debug, Clone, PartialEq)]
pub struct PerfOptions {
    /// `-T`: the topic and type.
    pub topic: TopicSel,
    /// `-i`: the domain (`None`: the default domain).
    pub domain_id: Option<u32>,
    /// `-n`: number of key values the data cycles through.
    pub nkeyvals: u32,
    /// Reliable unless `-u`.
    pub reliable: bool,
    /// 0: KEEP_ALL, otherwise KEEP_LAST n.
    pub history_depth: u32,
    /// `-D`: run time limit.
    pub duration: Option<Duration>,
    /// How ping and pong readers are serviced (`ping`/`pong` `waitset|listener`); shared by both, like ddsperf.
    pub pingpong_trigger: TriggerMode,
    /// `-L`: match endpoints in the same participant.
    pub match_local: bool,
    /// `-1`: print sub stats every second even without data.
    pub substat_every_second: bool,
    /// `-c`: collect CPU and network statistics (accepted, not reported).
    pub collect_stats: bool,
    /// `-X`: extended statistics (accepted, not reported).
    pub extended_stats: bool,
    /// `-l`: report latency in `sub` mode.
    pub sublatency: bool,
    /// `-Q samples:N`: fewer received samples is a failure.
    pub min_samples: u64,
    /// `-Q roundtrips:N`: fewer round trips is a failure.
    pub min_roundtrips: u64,
    /// `-Q minmatch:N`: wait for this many matched participants.
    pub min_match: u32,
    /// `-Q maxwait:DUR`: how long to wait for `minmatch`.
    pub maxwait: Option<Duration>,
    /// `-Q initwait:DUR`: wait this long after matching before starting.
    pub initwait: Option<Duration>,
    /// `pub` rate in samples/s; `None`: not publishing; `Some(INFINITY)`: as fast as possible.
    pub pub_rate: Option<f64>,
    /// `pub burst N`: samples written per wake-up.
    pub burst: u32,
    /// Fraction of published samples that double as pings, 0..=1.
    pub ping_fraction: f64,
    /// KS baggage in bytes (ddsperf's `size` minus the 12-byte fixed part).
    pub baggage: u32,
    /// `ping` interval: `None` no pings; `Some(ZERO)`: ping as soon as all pongs are in.
    pub ping_interval: Option<Duration>,
    /// `sub` mode given.
    pub sub: Option<TriggerMode>,
    /// `pong` mode given (pongs are always answered; this only suppresses the 1 Hz default ping).
    pub pong: bool,
}

impl Default for PerfOptions {
    fn default() -> Self {
        PerfOptions {
            topic: TopicSel::Ks,
            domain_id: None,
            nkeyvals: 1,
            reliable: true,
            history_depth: 0,
            duration: None,
            pingpong_trigger: TriggerMode::Listener,
            match_local: false,
            substat_every_second: false,
            collect_stats: false,
            extended_stats: false,
            sublatency: false,
            min_samples: 0,
            min_roundtrips: 0,
            min_match: 0,
            maxwait: None,
            initwait: None,
            pub_rate: None,
            burst: 1,
            ping_fraction: 0.0,
            baggage: 0,
            ping_interval: None,
            sub: None,
            pong: false,
        }
    }
}

/// What to do.
#[derive(Debug, Clone, PartialEq)]
pub enum PerfCommand {
    /// Run with these options.
    Run(PerfOptions),
    /// Print the usage: asked for (`-h`, `--help`, `help`; exit 0), or no mode given (exit 3, as ddsperf).
    Usage {
        /// `-h`, `--help` or `help`.
        requested: bool,
    },
}

/// An argument error (ddsperf exits with 3).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ArgError(pub String);

impl fmt::Display for ArgError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for ArgError {}

fn err<T>(s: impl Into<String>) -> Result<T, ArgError> {
    Err(ArgError(s.into()))
}

/// The usage text.
pub fn usage(prog: &str) -> String {
    format!(
        "{prog} help | -h | --help  (this text)
{prog} sanity              (ping 1Hz)
{prog} [OPTIONS] MODE...

OPTIONS:
  -L                  allow matching with endpoints in the same process
  -T KS|K32|K256|OU   topic (KS is default)
     S16|S256|S4k|S32k
  -n N                number of key values to use for data (only for keyed topics)
  -u                  best-effort instead of reliable
  -k all|N            keep-all or keep-last-N for data (ping/pong is always keep-last-1)
  -D DUR              run for at most DUR seconds
  -Q KEY:VAL          success criteria: samples:N roundtrips:N minmatch:N maxwait:DUR initwait:DUR
  -1                  print \"sub\" stats every second, even when there is no data
  -l                  report latency in sub mode
  -i ID               use domain ID instead of the default domain

MODE... is zero or more of:
  ping [R[Hz]] [size S] [waitset|listener]
  pong [waitset|listener]
  sub [waitset|listener|polling]
  pub [R[Hz]] [size S] [burst N] [[ping] X%]

EXIT STATUS: 0 all is well; 1 matching issues or unexpected sample loss; 2 DDS failure; 3 bad arguments
"
    )
}

const MODES: &[&str] = &["ping", "pong", "sub", "pub"];

fn is_mode(s: &str) -> bool {
    MODES.contains(&s)
}

fn pingpong_trigger(s: &str) -> Option<TriggerMode> {
    match s {
        "listener" => Some(TriggerMode::Listener),
        "waitset" => Some(TriggerMode::Waitset),
        _ => None,
    }
}

/// `%lf` followed by an optional unit: "1k" "10kHz" "inf".
fn parse_rate(s: &str) -> Option<f64> {
    let (num, unit) = split_number(s);
    if let Some(rest) = s.strip_prefix("inf") {
        return match rest {
            "" | "Hz" | "kHz" => Some(f64::INFINITY),
            _ => None,
        };
    }
    let v: f64 = num.parse().ok()?;
    let mult = match unit.trim_start() {
        "" | "Hz" => 1.0,
        "kHz" => 1000.0,
        _ => return None,
    };
    Some(v * mult)
}

fn split_number(s: &str) -> (&str, &str) {
    let end = s
        .char_indices()
        .take_while(|(i, c)| {
            c.is_ascii_digit() || *c == '.' || (*i == 0 && (*c == '-' || *c == '+'))
        })
        .map(|(i, c)| i + c.len_utf8())
        .last()
        .unwrap_or(0);
    (&s[..end], &s[end..])
}

/// `%u` with a size unit: B, k, M, kB, KiB, MB, MiB.
fn parse_size(s: &str) -> Option<u32> {
    let (num, unit) = split_number(s);
    let v: u32 = num.parse().ok()?;
    let mult = match unit.trim_start() {
        "" | "B" => 1,
        "k" | "kB" | "KiB" => 1024,
        "M" | "MB" | "MiB" => 1_048_576,
        _ => return None,
    };
    v.checked_mul(mult)
}

fn parse_seconds(s: &str) -> Option<Duration> {
    let v: f64 = s.parse().ok()?;
    (v > 0.0 && v.is_finite()).then(|| Duration::from_secs_f64(v))
}

/// Parses argv (without the program name).
pub fn parse(args: &[String]) -> Result<PerfCommand, ArgError> {
    let mut o = PerfOptions::default();
    let mut i = 0;
    // getopt("1cd:D:i:n:k:ulLK:T:Q:R:Xh"), stopping at the first non-option (the modes).
    while i < args.len() && args[i].starts_with('-') && args[i].len() > 1 {
        let a = &args[i];
        i += 1;
        if a == "--" {
            break;
        }
        if a == "--help" {
            return Ok(PerfCommand::Usage { requested: true });
        }
        let chars: Vec<char> = a[1..].chars().collect();
        let mut j = 0;
        while j < chars.len() {
            let c = chars[j];
            j += 1;
            let takes_arg = "dDinkKTQRW".contains(c);
            let val = if takes_arg {
                let rest: String = chars[j..].iter().collect();
                j = chars.len();
                if !rest.is_empty() {
                    rest
                } else if i < args.len() {
                    i += 1;
                    args[i - 1].clone()
                } else {
                    return err(format!("option requires an argument -- '{c}'"));
                }
            } else {
                String::new()
            };
            if let Some(usage) = set_option(&mut o, c, &val)? {
                return Ok(usage);
            }
        }
    }
    // ddsperf: ping/pong use a listener unless -L asks for local matching.
    if o.match_local {
        o.pingpong_trigger = TriggerMode::Waitset;
    }
    let modes = &args[i..];
    if modes.is_empty() {
        return Ok(PerfCommand::Usage { requested: false });
    }
    if modes.len() == 1 && modes[0] == "help" {
        return Ok(PerfCommand::Usage { requested: true });
    }
    if modes.len() == 1 && modes[0] == "sanity" {
        o.ping_interval = Some(Duration::from_secs(1));
    } else {
        parse_modes(&mut o, modes)?;
    }
    checked(o)
}

/// One short option (`c`, with its value `val` when it takes one) of the getopt string; `Some` when it asks for
/// the usage text.
fn set_option(o: &mut PerfOptions, c: char, val: &str) -> Result<Option<PerfCommand>, ArgError> {
    match c {
        '1' => o.substat_every_second = true,
        'c' => o.collect_stats = true,
        'X' => o.extended_stats = true,
        'l' => o.sublatency = true,
        'L' => o.match_local = true,
        'u' => o.reliable = false,
        'h' => return Ok(Some(PerfCommand::Usage { requested: true })),
        'd' => return err(format!("-d {val}: network load reporting not supported")),
        'D' => o.duration = parse_seconds(val),
        'i' => {
            o.domain_id = Some(
                val.parse()
                    .map_err(|_| ArgError(format!("-i {val}: invalid domain id")))?,
            )
        }
        'n' => o.nkeyvals = val.parse().unwrap_or(0),
        'k' => {
            o.history_depth = if val == "all" {
                0
            } else {
                val.parse::<i64>().unwrap_or(0).clamp(0, 1 << 30) as u32
            }
        }
        'T' => {
            o.topic =
                TopicSel::parse(val).ok_or_else(|| ArgError(format!("-T {val}: unknown topic")))?
        }
        'Q' => parse_criterion(o, val)?,
        'R' | 'K' | 'W' => {}
        _ => return err(format!("invalid option -- '{c}'")),
    }
    Ok(None)
}
/// The options' consistency checks (ddsperf's), and the KS baggage less its fixed part.
fn checked(mut o: PerfOptions) -> Result<PerfCommand, ArgError> {
    if o.nkeyvals == 0 {
        o.nkeyvals = 1;
    }
    if o.topic == TopicSel::Ou && o.nkeyvals != 1 {
        return err(format!("-n {} invalid: topic OU has no key", o.nkeyvals));
    }
    if o.topic != TopicSel::Ks && o.baggage != 0 {
        return err(format!(
            "size {} invalid: only topic KS has a sequence",
            o.baggage
        ));
    }
    if o.baggage != 0 && o.baggage < 12 {
        return err(format!(
            "size {} invalid: too small to allow for overhead",
            o.baggage
        ));
    } else if o.baggage > 0 {
        o.baggage -= 12;
    }
    Ok(PerfCommand::Run(o))
}

fn parse_criterion(o: &mut PerfOptions, v: &str) -> Result<(), ArgError> {
    let bad = || ArgError(format!("-Q {v}: invalid success criterium"));
    let (k, val) = v.split_once(':').ok_or_else(bad)?;
    match k {
        "samples" => o.min_samples = val.parse().map_err(|_| bad())?,
        "roundtrips" => o.min_roundtrips = val.parse().map_err(|_| bad())?,
        "minmatch" => o.min_match = val.parse().map_err(|_| bad())?,
        "maxwait" => o.maxwait = Some(parse_seconds(val).ok_or_else(bad)?),
        "initwait" => o.initwait = Some(parse_seconds(val).ok_or_else(bad)?),
        "rss" => {}
        _ => return Err(bad()),
    }
    Ok(())
}

fn parse_modes(o: &mut PerfOptions, a: &[String]) -> Result<(), ArgError> {
    let mut i = 0;
    while i < a.len() {
        let mode = a[i].as_str();
        let end = mode_end(a, i + 1, mode == "pub");
        let args = &a[i + 1..end];
        match mode {
            "ping" => ping_mode(o, args)?,
            "pong" => {
                o.pong = true;
                for t in args {
                    o.pingpong_trigger = pingpong_trigger(t)
                        .ok_or_else(|| ArgError(format!("{t}: undefined pong mode")))?;
                }
            }
            "sub" => {
                o.sub = Some(TriggerMode::Listener);
                for t in args {
                    o.sub = Some(match t.as_str() {
                        "listener" => TriggerMode::Listener,
                        "waitset" => TriggerMode::Waitset,
                        "polling" => TriggerMode::Polling,
                        other => return err(format!("{other}: undefined subscription mode")),
                    });
                }
            }
            "pub" => pub_mode(o, args)?,
            other => return err(format!("{other}: unrecognized argument")),
        }
        i = end;
    }
    Ok(())
}

/// Where the arguments of a mode that start at `from` end: at the next mode's name. In `pub`, `ping X%`
/// is the ping fraction, not the `ping` mode.
fn mode_end(a: &[String], from: usize, publishing: bool) -> usize {
    let mut i = from;
    while i < a.len() {
        let fraction =
            publishing && a[i] == "ping" && a.get(i + 1).is_some_and(|n| n.ends_with('%'));
        if fraction {
            i += 2;
        } else if is_mode(&a[i]) {
            break;
        } else {
            i += 1;
        }
    }
    i
}

/// The value after a `size` or `burst` keyword.
fn value_of<'a>(args: &'a [String], i: usize, what: &str) -> Result<&'a str, ArgError> {
    args.get(i + 1)
        .map(String::as_str)
        .ok_or_else(|| ArgError(format!("argument missing in {what} specification")))
}

/// `ping [R[Hz]] [size S] [waitset|listener]`.
fn ping_mode(o: &mut PerfOptions, args: &[String]) -> Result<(), ArgError> {
    o.ping_interval = Some(Duration::ZERO);
    let mut i = 0;
    while i < args.len() {
        let t = args[i].as_str();
        if t == "size" {
            let v = value_of(args, i, "size")?;
            o.baggage = parse_size(v)
                .ok_or_else(|| ArgError(format!("{v}: invalid size specification")))?;
            i += 1;
        } else if let Some(m) = pingpong_trigger(t) {
            o.pingpong_trigger = m;
        } else if let Some(r) = parse_rate(t) {
            if r < 0.0 {
                return err(format!("{t}: invalid ping rate"));
            }
            o.ping_interval = if r == 0.0 {
                None
            } else if r.is_infinite() {
                Some(Duration::ZERO)
            } else {
                Some(Duration::from_secs_f64(1.0 / r))
            };
        } else {
            return err(format!("{t}: undefined ping mode"));
        }
        i += 1;
    }
    Ok(())
}

/// `pub [R[Hz]] [burst N] [size S] [[ping] X%]`.
fn pub_mode(o: &mut PerfOptions, args: &[String]) -> Result<(), ArgError> {
    o.pub_rate = Some(f64::INFINITY);
    o.burst = 1;
    let mut i = 0;
    while i < args.len() {
        let t = args[i].as_str();
        if t == "burst" {
            let v = value_of(args, i, t)?;
            let n: u32 = v
                .parse()
                .map_err(|_| ArgError(format!("{v}: invalid burst specification")))?;
            o.burst = n.max(1);
            i += 1;
        } else if t == "size" {
            let v = value_of(args, i, t)?;
            o.baggage = parse_size(v)
                .ok_or_else(|| ArgError(format!("{v}: invalid size specification")))?;
            i += 1;
        } else if let Some(p) = t.strip_suffix('%') {
            o.ping_fraction = percent(p)?;
        } else if t == "ping" && args.get(i + 1).is_some_and(|n| n.ends_with('%')) {
            o.ping_fraction = percent(args[i + 1].trim_end_matches('%'))?;
            i += 1;
        } else if let Some(r) = parse_rate(t) {
            if r < 0.0 {
                return err(format!("{t}: invalid publish rate"));
            }
            o.pub_rate = Some(r);
        } else {
            return err(format!("{t}: unrecognised publish specification"));
        }
        i += 1;
    }
    Ok(())
}

fn percent(p: &str) -> Result<f64, ArgError> {
    match p.parse::<f64>() {
        Ok(v) if (0.0..=100.0).contains(&v) => Ok(v / 100.0),
        _ => err(format!("{p}%: ping fraction out of range")),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn run(s: &str) -> PerfOptions {
        let a: Vec<String> = s.split_whitespace().map(String::from).collect();
        match parse(&a).expect("parses") {
            PerfCommand::Run(o) => o,
            PerfCommand::Usage { .. } => panic!("usage"),
        }
    }

    fn fails(s: &str) -> bool {
        let a: Vec<String> = s.split_whitespace().map(String::from).collect();
        parse(&a).is_err()
    }

    #[test]
    fn pub_modes() {
        let o = run("pub size 1k");
        assert_eq!(o.pub_rate, Some(f64::INFINITY));
        assert_eq!(o.baggage, 1024 - 12);
        let o = run("-TK32 -u -k 5 -n 4 pub 10kHz burst 3 50%");
        assert_eq!(o.topic, TopicSel::K32);
        assert!(!o.reliable);
        assert_eq!(o.history_depth, 5);
        assert_eq!(o.nkeyvals, 4);
        assert_eq!(o.pub_rate, Some(10_000.0));
        assert_eq!(o.burst, 3);
        assert!((o.ping_fraction - 0.5).abs() < 1e-9);
        assert_eq!(run("pub 100Hz 10%").pub_rate, Some(100.0));
        // `ping X%` inside `pub` is the ping fraction, not the `ping` mode.
        let o = run("pub 100Hz ping 20% sub");
        assert!((o.ping_fraction - 0.2).abs() < 1e-9);
        assert_eq!(o.ping_interval, None);
        assert_eq!(o.sub, Some(TriggerMode::Listener));
    }

    #[test]
    fn sub_ping_pong() {
        let o = run("-D 5 -i 7 sub pong");
        assert_eq!(o.duration, Some(Duration::from_secs(5)));
        assert_eq!(o.domain_id, Some(7));
        assert_eq!(o.sub, Some(TriggerMode::Listener));
        assert!(o.pong);
        assert_eq!(run("ping").ping_interval, Some(Duration::ZERO));
        assert_eq!(
            run("ping 10Hz size 100").ping_interval,
            Some(Duration::from_millis(100))
        );
        assert_eq!(run("ping 10Hz size 100").baggage, 88);
        assert_eq!(run("sanity").ping_interval, Some(Duration::from_secs(1)));
        assert_eq!(run("-k all sub polling").sub, Some(TriggerMode::Polling));
        assert_eq!(run("pong").pingpong_trigger, TriggerMode::Listener);
        assert_eq!(run("-L pong").pingpong_trigger, TriggerMode::Waitset);
        assert_eq!(run("ping waitset").pingpong_trigger, TriggerMode::Waitset);
        assert_eq!(
            run("-L pong listener").pingpong_trigger,
            TriggerMode::Listener
        );
        assert_eq!(run("-Qsamples:10 -Q minmatch:1 sub").min_samples, 10);
    }

    #[test]
    fn bad_arguments() {
        assert!(fails("-T XX sub"));
        assert!(fails("-TOU -n 3 pub"));
        assert!(fails("-TK32 pub size 100"));
        assert!(fails("pub size 4"));
        assert!(fails("pub fast"));
        assert!(fails("sub bogus"));
        assert!(fails("frob"));
        assert!(fails("-Q what:1 sub"));
    }

    #[test]
    fn help_and_usage() {
        let parse_str = |s: &str| {
            let a: Vec<String> = s.split_whitespace().map(String::from).collect();
            parse(&a)
        };
        for asked in ["--help", "-h", "help", "-u --help sub"] {
            assert_eq!(
                parse_str(asked),
                Ok(PerfCommand::Usage { requested: true }),
                "{asked}"
            );
        }
        assert_eq!(parse_str(""), Ok(PerfCommand::Usage { requested: false }));
        assert_eq!(parse_str("-u"), Ok(PerfCommand::Usage { requested: false }));
    }

    #[test]
    fn payload_sizes_match_ddsperf() {
        assert_eq!(TopicSel::Ks.payload_size(1012), 1024);
        assert_eq!(TopicSel::S16.payload_size(0), 32);
        assert_eq!(TopicSel::S256.payload_size(0), 528);
    }
}
