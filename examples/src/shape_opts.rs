//! Command line of `shape_main`, the OMG interoperability suite's test program (omg-dds/dds-rtps,
//! `srcCxx/shape_main.cxx`): same flags, same defaults, same validation messages.

use std::fmt;
use std::ops::RangeInclusive;
use std::time::Duration;

/// DURABILITY kinds selectable with `-D`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DurabilityArg {
    /// `v`
    Volatile,
    /// `l`
    TransientLocal,
    /// `t`
    Transient,
    /// `p`
    Persistent,
}

/// What a publisher does with its instances before it exits (`--final-instance-state`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FinalInstanceState {
    /// `u`: unregister (and do not autodispose).
    Unregister,
    /// `d`: dispose.
    Dispose,
}

/// Presentation access scope (`--access-scope`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum AccessScope {
    /// `i`
    Instance,
    /// `t`
    Topic,
    /// `g`
    Group,
}

/// All options of shape_main, with its defaults.
#[derive(Debug, Clone, PartialEq)]
pub struct ShapeOptions {
    /// `-v d`: debug verbosity.
    pub debug: bool,
    /// `-d`: the domain.
    pub domain_id: u32,
    /// `-P`: publish.
    pub publish: bool,
    /// `-S`: subscribe.
    pub subscribe: bool,
    /// RELIABLE (`-r`, the default) or BEST_EFFORT (`-b`).
    pub reliable: bool,
    /// `-D`: durability kind.
    pub durability: DurabilityArg,
    /// 1 or 2.
    pub xcdr: u8,
    /// `None`: the default; `Some(0)`: KEEP_ALL; `Some(n)`: KEEP_LAST n.
    pub history_depth: Option<u32>,
    /// `None`: shared ownership.
    pub ownership_strength: Option<i32>,
    /// `-t`: the topic name (required).
    pub topic: Option<String>,
    /// `-c`: colour published, or the only colour printed by a subscriber.
    pub color: Option<String>,
    /// `-p`: a partition name.
    pub partition: Option<String>,
    /// `--time-filter`: minimum separation of a reader's samples (zero: off).
    pub time_filter: Duration,
    /// `-f`: deadline period (zero: off).
    pub deadline: Duration,
    /// `--lifespan`: lifespan of written samples (zero: infinite).
    pub lifespan: Duration,
    /// `-w`: print the samples written.
    pub print_writer_samples: bool,
    /// `-z`: size of the shapes written (0: growing).
    pub shapesize: i32,
    /// `-R`: read instead of take.
    pub use_read: bool,
    /// `--write-period`: time between two writes.
    pub write_period: Duration,
    /// `--read-period`: time between two reads or takes.
    pub read_period: Duration,
    /// 0: run until interrupted.
    pub num_iterations: u32,
    /// `--num-instances`: colours written (COLOR, COLOR1, COLOR2, ...).
    pub num_instances: u32,
    /// `--num-topics`: topics created (TOPIC, TOPIC1, ...).
    pub num_topics: u32,
    /// `--final-instance-state`: what a publisher does with its instances at the end.
    pub final_instance_state: Option<FinalInstanceState>,
    /// `--access-scope`: presentation access scope.
    pub access_scope: Option<AccessScope>,
    /// `--coherent`: coherent access.
    pub coherent: bool,
    /// `--ordered`: ordered access.
    pub ordered: bool,
    /// `--coherent-sample-count`: samples per coherent set.
    pub coherent_sample_count: u32,
    /// `--additional-payload-size`: bytes of 255 appended to each sample.
    pub additional_payload_size: u32,
    /// `true` unless `--take-read`: use take/read_next_instance.
    pub take_read_next_instance: bool,
    /// `--periodic-announcement`: SPDP period (zero: the default).
    pub periodic_announcement: Duration,
    /// `--datafrag-size`: fragment size (0: the default).
    pub datafrag_size: u32,
    /// `--cft`: content filter expression.
    pub cft_expression: Option<String>,
    /// `--size-modulo`: wraps the growing shapesize of `-z 0`.
    pub size_modulo: i32,
}

impl Default for ShapeOptions {
    fn default() -> Self {
        ShapeOptions {
            debug: false,
            domain_id: 0,
            publish: false,
            subscribe: false,
            reliable: true,
            durability: DurabilityArg::Volatile,
            xcdr: 1,
            history_depth: None,
            ownership_strength: None,
            topic: None,
            color: None,
            partition: None,
            time_filter: Duration::ZERO,
            deadline: Duration::ZERO,
            lifespan: Duration::ZERO,
            print_writer_samples: false,
            shapesize: 20,
            use_read: false,
            write_period: Duration::from_millis(33),
            read_period: Duration::from_millis(100),
            num_iterations: 0,
            num_instances: 1,
            num_topics: 1,
            final_instance_state: None,
            access_scope: None,
            coherent: false,
            ordered: false,
            coherent_sample_count: 0,
            additional_payload_size: 0,
            take_read_next_instance: true,
            periodic_announcement: Duration::ZERO,
            datafrag_size: 0,
            cft_expression: None,
            size_modulo: 0,
        }
    }
}

/// What the command line asked for.
#[derive(Debug, Clone, PartialEq)]
pub enum Parsed {
    /// Run with these options; `warnings` are printed first (shape_main prints them as errors but runs).
    Run {
        /// The options.
        options: Box<ShapeOptions>,
        /// Warnings about options ignored in this role.
        warnings: Vec<String>,
    },
    /// `-h`/`--help`.
    Help,
}

/// A command-line error: the message shape_main prints before the usage text (exit code 1).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ParseError(pub Vec<String>);

impl fmt::Display for ParseError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.0.join("\n"))
    }
}

impl std::error::Error for ParseError {}

/// The usage text.
pub fn usage(prog: &str) -> String {
    format!(
        "{prog}: 
   --help, -h      : print this menu
   -v [e|d]        : set log message verbosity [e: ERROR, d: DEBUG]
   -P              : publish samples
   -S              : subscribe samples
   -d <int>        : domain id (default: 0)
   -b              : BEST_EFFORT reliability
   -r              : RELIABLE reliability
   -k <depth>      : keep history depth [0: KEEP_ALL]
   -f <interval>   : set a 'deadline' with interval (ms) [0: OFF]
   -s <strength>   : set ownership strength [-1: SHARED]
   -t <topic_name> : set the topic name
   -c <color>      : set color to publish (filter if subscriber)
   -p <partition>  : set a 'partition' string
   -D [v|l|t|p]    : set durability [v: VOLATILE,  l: TRANSIENT_LOCAL]
                                     t: TRANSIENT, p: PERSISTENT]
   -x [1|2]        : set data representation [1: XCDR, 2: XCDR2]
   -w              : print Publisher's samples
   -z <int>        : set shapesize (0: increase the size for every sample)
   -R              : use 'read()' instead of 'take()'
   --write-period <ms>: waiting period between 'write()' operations in ms. Default: 33ms
   --read-period <ms> : waiting period between 'read()' or 'take()' operations in ms. Default: 100ms
   --time-filter <interval> : apply 'time based filter' with interval in ms [0: OFF]
   --lifespan <int>      : indicates the lifespan of a sample in ms
   --num-iterations <int>: indicates the number of iterations of the main loop
   --num-instances <int>: indicates the number of instances a DataWriter writes
   --num-topics <int>: indicates the number of topics created (using the same type)
   --final-instance-state [u|d]: unregister or dispose the instances before exiting
   --access-scope [i|t|g]: sets Presentation.access_scope to INSTANCE, TOPIC or GROUP
   --coherent            : sets Presentation.coherent_access = true
   --ordered             : sets Presentation.ordered_access = true
   --coherent-sample-count <int>: samples per coherent set
   --additional-payload-size <bytes>: bytes added to the samples written
   --take-read           : uses take()/read() instead of take_next_instance()/read_next_instance()
   --periodic-announcement <ms> : periodic participant announcement period in ms. Default 0 (off)
   --datafrag-size <bytes> : set the data fragment size (default: 0, means not set)
   --cft <expression> : ContentFilteredTopic filter expression
   --size-modulo <int> : applies a modulo to the increasing shapesize (-z 0)
"
    )
}

/// shape_main's getopt_long table (getopt string "hPSbrRwc:d:D:f:k:p:s:x:t:v:z:" and the long options): each
/// option as the token [`parse`] matches on (`-c`, `--write-period`), and whether it takes a value.
const OPTIONS: &[(&str, bool)] = &[
    ("-h", false),
    ("--help", false),
    ("-P", false),
    ("-S", false),
    ("-b", false),
    ("-r", false),
    ("-R", false),
    ("-w", false),
    ("-c", true),
    ("-d", true),
    ("-D", true),
    ("-f", true),
    ("-k", true),
    ("-p", true),
    ("-s", true),
    ("-x", true),
    ("-t", true),
    ("-v", true),
    ("-z", true),
    ("--write-period", true),
    ("--read-period", true),
    ("--final-instance-state", true),
    ("--access-scope", true),
    ("--coherent-sample-count", true),
    ("--additional-payload-size", true),
    ("--num-topics", true),
    ("--lifespan", true),
    ("--num-instances", true),
    ("--num-iterations", true),
    ("--time-filter", true),
    ("--periodic-announcement", true),
    ("--datafrag-size", true),
    ("--cft", true),
    ("--size-modulo", true),
    ("--coherent", false),
    ("--ordered", false),
    ("--take-read", false),
];

/// The clap argument of one [`OPTIONS`] entry, with the token as its id.
fn arg(token: &'static str, takes_value: bool) -> clap::Arg {
    let a = clap::Arg::new(token).value_name("VALUE");
    let a = match token.strip_prefix("--") {
        Some(long) => a.long(long),
        None => a.short(token.chars().nth(1).unwrap_or('?')),
    };
    if takes_value {
        // getopt takes the next word as the value whatever it looks like (`-s -1`).
        a.action(clap::ArgAction::Append)
            .num_args(1)
            .allow_hyphen_values(true)
    } else {
        a.action(clap::ArgAction::Count)
    }
}

/// shape_main's command line for clap: getopt_long's syntax (`-x2`, `-x 2`, `-Pw`, `--num-iterations=5`,
/// `--num-iterations 5`, unambiguous long prefixes, repeated options); words that are not options are
/// ignored, as shape_main does.
fn command() -> clap::Command {
    clap::Command::new("shape_main")
        .disable_help_flag(true)
        .disable_version_flag(true)
        .infer_long_args(true)
        .args(OPTIONS.iter().map(|&(t, v)| arg(t, v)))
        .arg(
            clap::Arg::new("ignored")
                .num_args(0..)
                .action(clap::ArgAction::Append)
                .hide(true),
        )
}

/// Splits argv (without the program name) into (option, value) pairs in command-line order.
fn tokenize(args: &[String]) -> Result<Vec<(String, Option<String>)>, String> {
    let m = command()
        .try_get_matches_from(std::iter::once("shape_main".to_string()).chain(args.iter().cloned()))
        .map_err(|e| {
            let text = e.to_string();
            let first = text.lines().next().unwrap_or_default();
            first.strip_prefix("error: ").unwrap_or(first).to_string()
        })?;
    let mut out: Vec<(usize, String, Option<String>)> = Vec::new();
    for &(id, takes_value) in OPTIONS {
        if m.value_source(id) != Some(clap::parser::ValueSource::CommandLine) {
            continue;
        }
        let Some(indices) = m.indices_of(id) else {
            continue;
        };
        if takes_value {
            let values = m.get_many::<String>(id).into_iter().flatten();
            out.extend(
                indices
                    .zip(values)
                    .map(|(i, v)| (i, id.to_string(), Some(v.clone()))),
            );
        } else {
            out.extend(indices.map(|i| (i, id.to_string(), None)));
        }
    }
    out.sort_by_key(|(i, _, _)| *i);
    Ok(out.into_iter().map(|(_, o, v)| (o, v)).collect())
}

/// sscanf("%d")-like: leading integer, rest ignored; `None` when there is no number.
fn leading_int(s: &str) -> Option<i64> {
    let t = s.trim_start();
    let end = t
        .char_indices()
        .take_while(|(i, c)| c.is_ascii_digit() || (*i == 0 && (*c == '-' || *c == '+')))
        .map(|(i, c)| i + c.len_utf8())
        .last()?;
    t[..end].parse().ok()
}

fn first_char(s: &str) -> char {
    s.chars().next().unwrap_or('\0')
}

/// One option's value as shape_main reads it, and the errors found so far in the command line.
struct Value<'e> {
    text: String,
    /// The first character (`'\0'` when empty): what letter-valued options look at.
    c0: char,
    /// The leading integer, as `sscanf("%d")` reads it.
    num: Option<i64>,
    errors: &'e mut Vec<String>,
}

impl Value<'_> {
    fn error(&mut self, e: String) {
        self.errors.push(e);
    }

    /// "unrecognized value for WHAT C": the value is not what the option takes.
    fn unrecognized(&mut self, what: &str) {
        let e = format!("unrecognized value for {what} {}", self.c0);
        self.error(e);
    }

    /// The number if it is within `range`; otherwise the error `incorrect value for WHAT N` (`hint` after
    /// WHAT), or [`unrecognized`](Self::unrecognized) when there is none.
    fn int_in(&mut self, what: &str, hint: &str, range: RangeInclusive<i64>) -> Option<i64> {
        match self.num {
            Some(n) if range.contains(&n) => Some(n),
            Some(n) => {
                self.error(format!("incorrect value for {what}{hint} {n}"));
                None
            }
            None => {
                self.unrecognized(what);
                None
            }
        }
    }

    /// A period in milliseconds (zero after an error).
    fn ms(&mut self, what: &str) -> Duration {
        self.int_in(what, "", 0..=i64::MAX)
            .map_or(Duration::ZERO, |n| Duration::from_millis(n as u64))
    }

    /// A count of at least 1 (1 after an error).
    fn positive(&mut self, what: &str) -> u32 {
        self.int_in(what, ", it must be >=1", 1..=i64::MAX)
            .map_or(1, |n| n.min(i64::from(u32::MAX)) as u32)
    }
}

/// Parses shape_main's command line (argv without the program name).
pub fn parse(args: &[String]) -> Result<Parsed, ParseError> {
    let tokens = tokenize(args).map_err(|e| ParseError(vec![e]))?;
    let mut o = ShapeOptions::default();
    let mut errors = Vec::new();
    let mut access_scope_set = false;
    for (opt, val) in tokens {
        if opt == "-h" || opt == "--help" {
            return Ok(Parsed::Help);
        }
        let text = val.unwrap_or_default();
        let mut v = Value {
            c0: first_char(&text),
            num: leading_int(&text),
            text,
            errors: &mut errors,
        };
        access_scope_set |= opt == "--access-scope";
        if !(entity_option(&mut o, &opt, &mut v)
            || qos_option(&mut o, &opt, &mut v)
            || test_option(&mut o, &opt, &mut v))
        {
            errors.push(format!("unhandled option {opt}"));
        }
    }
    if !errors.is_empty() {
        return Err(ParseError(errors));
    }
    let mut warnings = Vec::new();
    validate(&mut o, access_scope_set, &mut warnings)?;
    Ok(Parsed::Run {
        options: Box::new(o),
        warnings,
    })
}

/// The options that choose the entities (role, topic, colour, domain, partition, output); false when `opt`
/// is not one of them.
fn entity_option(o: &mut ShapeOptions, opt: &str, v: &mut Value<'_>) -> bool {
    match opt {
        "-v" => match v.c0 {
            'd' => o.debug = true,
            'e' => o.debug = false,
            _ => v.unrecognized("verbosity"),
        },
        "-w" => o.print_writer_samples = true,
        "-R" => o.use_read = true,
        "-P" => o.publish = true,
        "-S" => o.subscribe = true,
        "-c" => o.color = Some(std::mem::take(&mut v.text)),
        "-t" => o.topic = Some(std::mem::take(&mut v.text)),
        "-p" => o.partition = Some(std::mem::take(&mut v.text)),
        "-d" => {
            if let Some(n) = v.int_in("domain_id", "", 0..=i64::from(u32::MAX)) {
                o.domain_id = n as u32;
            }
        }
        "-z" => {
            if let Some(n) = v.int_in("shapesize", "", 0..=i64::MAX) {
                o.shapesize = n.min(i64::from(i32::MAX)) as i32;
            }
        }
        "--num-instances" => o.num_instances = v.positive("num-instances"),
        "--num-topics" => o.num_topics = v.positive("num-topics"),
        "--additional-payload-size" => {
            o.additional_payload_size = v.positive("additional-payload-size")
        }
        "--cft" => o.cft_expression = Some(std::mem::take(&mut v.text)),
        _ => return false,
    }
    true
}

/// The QoS options; false when `opt` is not one of them.
fn qos_option(o: &mut ShapeOptions, opt: &str, v: &mut Value<'_>) -> bool {
    match opt {
        "-b" => o.reliable = false,
        "-r" => o.reliable = true,
        "-D" => match v.c0 {
            'v' => o.durability = DurabilityArg::Volatile,
            'l' => o.durability = DurabilityArg::TransientLocal,
            't' => o.durability = DurabilityArg::Transient,
            'p' => o.durability = DurabilityArg::Persistent,
            _ => v.unrecognized("durability"),
        },
        "-x" => match v.c0 {
            '1' => o.xcdr = 1,
            '2' => o.xcdr = 2,
            _ => v.unrecognized("data representation"),
        },
        "-k" => {
            if let Some(n) = v.int_in("history_depth", "", 0..=i64::MAX) {
                o.history_depth = Some(n.min(i64::from(u32::MAX)) as u32);
            }
        }
        "-s" => match v.num {
            Some(-1) => o.ownership_strength = None,
            _ => {
                if let Some(n) = v.int_in("ownership_strength", "", 0..=i64::MAX) {
                    o.ownership_strength = Some(n.min(i64::from(i32::MAX)) as i32);
                }
            }
        },
        "-f" => o.deadline = v.ms("deadline_interval"),
        "--time-filter" => o.time_filter = v.ms("timebasedfilter_interval"),
        "--lifespan" => o.lifespan = v.ms("lifespan"),
        "--access-scope" => {
            o.access_scope = match v.c0 {
                'i' => Some(AccessScope::Instance),
                't' => Some(AccessScope::Topic),
                'g' => Some(AccessScope::Group),
                _ => {
                    v.unrecognized("coherent-sets");
                    None
                }
            }
        }
        "--coherent" => o.coherent = true,
        "--ordered" => o.ordered = true,
        "--datafrag-size" => {
            let hint = ", it must be <= 65535 bytes";
            if let Some(n) = v.int_in("datafrag-size", hint, 0..=65535) {
                o.datafrag_size = n as u32;
            }
        }
        _ => return false,
    }
    true
}

/// The options of the test scenario (periods, iterations, coherent sets, final state, filters); false
/// when `opt` is not one of them.
fn test_option(o: &mut ShapeOptions, opt: &str, v: &mut Value<'_>) -> bool {
    match opt {
        "--write-period" => o.write_period = v.ms("write-period"),
        "--read-period" => o.read_period = v.ms("read-period"),
        "--periodic-announcement" => o.periodic_announcement = v.ms("periodic-announcement"),
        "--num-iterations" => o.num_iterations = v.positive("num-iterations"),
        "--take-read" => o.take_read_next_instance = false,
        "--coherent-sample-count" => {
            let hint = ", it must be >=2";
            if let Some(n) = v.int_in("coherent-sample-count", hint, 2..=i64::MAX) {
                o.coherent_sample_count = n.min(i64::from(u32::MAX)) as u32;
            }
        }
        "--final-instance-state" => {
            let new = match v.c0 {
                'u' => Some(FinalInstanceState::Unregister),
                'd' => Some(FinalInstanceState::Dispose),
                _ => {
                    v.unrecognized("final-instance-state");
                    None
                }
            };
            if o.final_instance_state.zip(new).is_some_and(|(a, b)| a != b) {
                v.error("error, cannot configure unregister and dispose at the same time".into());
            }
            o.final_instance_state = new.or(o.final_instance_state);
        }
        "--size-modulo" => match v.num {
            Some(n) if n >= 1 => o.size_modulo = n.min(i64::from(i32::MAX)) as i32,
            _ => v.error("incorrect value for size-modulo, must be >=1".into()),
        },
        _ => return false,
    }
    true
}

/// shape_main's `validate()`: fatal combinations are errors, the rest warnings.
fn validate(
    o: &mut ShapeOptions,
    access_scope_set: bool,
    w: &mut Vec<String>,
) -> Result<(), ParseError> {
    if o.topic.is_none() {
        return Err(ParseError(vec!["please specify topic name [-t]".into()]));
    }
    if !o.publish && !o.subscribe {
        return Err(ParseError(vec![
            "please specify publish [-P] or subscribe [-S]".into(),
        ]));
    }
    if o.publish && o.subscribe {
        return Err(ParseError(vec![
            "please specify only one of: publish [-P] or subscribe [-S]".into(),
        ]));
    }
    if o.publish && o.color.is_none() {
        o.color = Some("BLUE".into());
        w.push("warning: color was not specified, defaulting to \"BLUE\"".into());
    }
    if o.publish && !o.time_filter.is_zero() {
        w.push(
            "warning: time base filter [--time-filter] ignored on publisher applications".into(),
        );
    }
    if o.publish && o.use_read {
        w.push("warning: use read [-R] ignored on publisher applications".into());
    }
    if o.publish && !o.take_read_next_instance {
        w.push("warning: --take-read ignored on publisher applications".into());
    }
    if o.publish && o.cft_expression.is_some() {
        w.push("warning: --cft ignored on publisher applications".into());
    }
    if o.subscribe && o.shapesize != 20 {
        w.push("warning: shapesize [-z] ignored on subscriber applications".into());
    }
    if o.subscribe && !o.lifespan.is_zero() {
        w.push("warning: --lifespan ignored on subscriber applications".into());
    }
    if o.subscribe && o.num_instances > 1 {
        w.push("warning: --num-instances ignored on subscriber applications".into());
    }
    if o.subscribe && o.final_instance_state.is_some() {
        w.push("warning: --final-instance-state ignored on subscriber applications".into());
    }
    if o.subscribe && o.coherent_sample_count > 0 {
        w.push("warning: --coherent-sample-count ignored on subscriber applications".into());
    }
    if !o.coherent && !o.ordered && o.coherent_sample_count > 0 {
        w.push("warning: --coherent-sample-count ignored because not coherent, or ordered access enabled".into());
    }
    if o.subscribe && o.additional_payload_size > 0 {
        w.push("warning: --additional-payload-size ignored on subscriber applications".into());
    }
    if !o.coherent && !o.ordered && access_scope_set {
        w.push("warning: --access-scope set but not coherent, or ordered access enabled".into());
    }
    if o.size_modulo > 0 && o.shapesize != 0 {
        w.push("warning: --size-modulo has no effect unless shapesize (-z) is set to 0".into());
    }
    if o.subscribe && o.color.is_some() && o.cft_expression.is_some() {
        return Err(ParseError(vec![
            "error: cannot specify both --cft and -c for subscriber applications".into(),
        ]));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn args(s: &str) -> Vec<String> {
        s.split_whitespace().map(String::from).collect()
    }

    fn run(s: &str) -> (ShapeOptions, Vec<String>) {
        match parse(&args(s)).expect("parses") {
            Parsed::Run { options, warnings } => (*options, warnings),
            Parsed::Help => panic!("help"),
        }
    }

    #[test]
    fn defaults_match_shape_main() {
        let (o, w) = run("-P -t Square");
        assert_eq!(o.color.as_deref(), Some("BLUE"));
        assert_eq!(
            w,
            vec!["warning: color was not specified, defaulting to \"BLUE\"".to_string()]
        );
        assert!(o.reliable);
        assert_eq!(o.xcdr, 1);
        assert_eq!(o.durability, DurabilityArg::Volatile);
        assert_eq!(o.write_period, Duration::from_millis(33));
        assert_eq!(o.read_period, Duration::from_millis(100));
        assert_eq!(o.shapesize, 20);
        assert!(o.take_read_next_instance);
    }

    #[test]
    fn short_options_attached_and_separate() {
        let (o, _) = run("-S -tCircle -x2 -d 17 -b -k 0 -D l -p A* -c RED");
        assert!(o.subscribe);
        assert_eq!(o.topic.as_deref(), Some("Circle"));
        assert_eq!(o.xcdr, 2);
        assert_eq!(o.domain_id, 17);
        assert!(!o.reliable);
        assert_eq!(o.history_depth, Some(0));
        assert_eq!(o.durability, DurabilityArg::TransientLocal);
        assert_eq!(o.partition.as_deref(), Some("A*"));
        assert_eq!(o.color.as_deref(), Some("RED"));
    }

    #[test]
    fn grouped_flags_and_long_options() {
        let (o, _) = run("-Pw -t Square --write-period=5 --num-iterations 10 --final-instance-state d --additional-payload-size 100000 --num-inst 3");
        assert!(o.publish && o.print_writer_samples);
        assert_eq!(o.write_period, Duration::from_millis(5));
        assert_eq!(o.num_iterations, 10);
        assert_eq!(o.final_instance_state, Some(FinalInstanceState::Dispose));
        assert_eq!(o.additional_payload_size, 100_000);
        assert_eq!(o.num_instances, 3);
    }

    #[test]
    fn errors_are_reported() {
        assert!(parse(&args("-P")).is_err());
        assert!(parse(&args("-t Square")).is_err());
        assert!(parse(&args("-P -S -t Square")).is_err());
        assert!(parse(&args("-P -t Square -x 3")).is_err());
        assert!(parse(&args("-P -t Square -d -1")).is_err());
        assert!(parse(&args("-P -t Square --num-iterations 0")).is_err());
        assert!(parse(&args("-P -t Square --bogus")).is_err());
        assert!(parse(&args(
            "-P -t Square --final-instance-state u --final-instance-state d"
        ))
        .is_err());
        assert!(parse(&args("-S -t Square -c RED --cft x")).is_err());
        assert_eq!(parse(&args("-h")), Ok(Parsed::Help));
        assert_eq!(parse(&args("--help")), Ok(Parsed::Help));
        assert!(parse(&args("-P -t Square -q")).is_err());
        assert!(parse(&args("-P -t")).is_err());
        assert!(parse(&args("-P -t Square --co")).is_err());
        assert!(parse(&args("-P -t Square --coh")).is_err());
    }

    #[test]
    fn getopt_order_values_and_leftovers() {
        let (o, _) = run("-b -P -r -t Square");
        assert!(o.reliable);
        let (o, _) = run("-r -P -b -t Square");
        assert!(!o.reliable);
        let (o, _) = run("stray -P -s -1 -t A -t B --ord --lifespan=7 more");
        assert_eq!(o.ownership_strength, None);
        assert_eq!(o.topic.as_deref(), Some("B"));
        assert!(o.ordered);
        assert_eq!(o.lifespan, Duration::from_millis(7));
        let (o, _) = run("-P -t Square -s 5 -d 3 -v d");
        assert_eq!(o.ownership_strength, Some(5));
        assert_eq!(o.domain_id, 3);
        assert!(o.debug);
    }

    #[test]
    fn subscriber_warnings() {
        let (_, w) = run("-S -t Square -z 30 --num-instances 2");
        assert!(w.iter().any(|l| l.contains("shapesize [-z] ignored")));
        assert!(w.iter().any(|l| l.contains("--num-instances ignored")));
    }
}
