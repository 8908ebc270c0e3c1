//! The command line of `shapes`.

use std::time::Duration;

use clap::Parser;

/// Bouncing shapes published and subscribed over real RTPS (two participants in one process).
///
/// In a terminal it shows them moving in a window (keys: p publish, t topic, c colour, s subscribe,
/// space pause, q quit); otherwise, or with --batch, it prints one line per sample and, after --duration
/// seconds or --count samples, a summary (exit 1 when a subscriber received nothing).
#[derive(Debug, Clone, PartialEq, Parser)]
#[command(name = "shapes", version)]
pub struct ShapesArgs {
    /// Only publish (any shape_main subscriber receives the shapes)
    #[arg(long, visible_alias = "pub", conflicts_with = "sub_only")]
    pub pub_only: bool,
    /// Only subscribe
    #[arg(long, visible_alias = "sub")]
    pub sub_only: bool,
    /// Topic to publish and subscribe (Square, Circle, Triangle, or any name)
    #[arg(short, long, default_value = "Square")]
    pub topic: String,
    /// Colour to publish, repeatable [default: BLUE and RED when publishing]
    #[arg(short = 'c', long = "color", value_name = "COLOR")]
    pub colors: Vec<String>,
    /// DDS domain id
    #[arg(short, long, default_value_t = 0)]
    pub domain: u32,
    /// Stop after SECS seconds [default: 10 in batch mode, until q in the window]
    #[arg(long, value_name = "SECS", value_parser = parse_duration)]
    pub duration: Option<Duration>,
    /// Stop after N received samples
    #[arg(long, value_name = "N")]
    pub count: Option<u64>,
    /// Samples per second of each published shape
    #[arg(long, value_name = "HZ", default_value_t = 10.0, value_parser = parse_rate)]
    pub rate: f64,
    /// Data representation written: 1 (XCDR1, as shape_main) or 2 (XCDR2); both are read
    #[arg(short = 'x', long = "xcdr", default_value_t = 1, value_parser = clap::value_parser!(u8).range(1..=2))]
    pub xcdr: u8,
    /// Batch mode: print only the summary
    #[arg(short, long)]
    pub quiet: bool,
    /// Batch mode (one line per sample) even when stdout is a terminal
    #[arg(long)]
    pub batch: bool,
}

impl ShapesArgs {
    /// Whether this run publishes.
    pub fn publishes(&self) -> bool {
        !self.sub_only
    }

    /// Whether this run subscribes.
    pub fn subscribes(&self) -> bool {
        !self.pub_only
    }

    /// The colours to publish: the given ones, or BLUE and RED.
    pub fn publish_colors(&self) -> Vec<String> {
        match (self.publishes(), self.colors.is_empty()) {
            (false, _) => Vec::new(),
            (true, true) => vec!["BLUE".into(), "RED".into()],
            (true, false) => self.colors.clone(),
        }
    }
}

fn parse_duration(s: &str) -> Result<Duration, String> {
    match s.parse::<f64>() {
        Ok(v) if v > 0.0 && v.is_finite() => Ok(Duration::from_secs_f64(v)),
        _ => Err("must be a number of seconds > 0".into()),
    }
}

fn parse_rate(s: &str) -> Result<f64, String> {
    match s.parse::<f64>() {
        Ok(v) if v > 0.0 && v <= 10_000.0 => Ok(v),
        _ => Err("must be in (0, 10000]".into()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(s: &str) -> Result<ShapesArgs, clap::Error> {
        ShapesArgs::try_parse_from(std::iter::once("shapes").chain(s.split_whitespace()))
    }

    #[test]
    fn defaults() {
        let a = parse("").expect("parses");
        assert_eq!(a.topic, "Square");
        assert_eq!(a.domain, 0);
        assert_eq!(a.rate, 10.0);
        assert_eq!(a.xcdr, 1);
        assert_eq!(a.duration, None);
        assert!(a.publishes() && a.subscribes() && !a.batch);
        assert_eq!(a.publish_colors(), ["BLUE", "RED"]);
    }

    #[test]
    fn every_option() {
        let a = parse("--pub -t Circle -c GREEN --color=RED -d 7 --duration 2.5 --count 9 --rate 20 -x 2 -q --batch")
            .expect("parses");
        assert!(a.publishes() && !a.subscribes());
        assert_eq!(a.topic, "Circle");
        assert_eq!(a.publish_colors(), ["GREEN", "RED"]);
        assert_eq!(a.domain, 7);
        assert_eq!(a.duration, Some(Duration::from_millis(2500)));
        assert_eq!(a.count, Some(9));
        assert_eq!(a.rate, 20.0);
        assert_eq!(a.xcdr, 2);
        assert!(a.quiet && a.batch);
        assert!(parse("--sub-only")
            .expect("parses")
            .publish_colors()
            .is_empty());
    }

    #[test]
    fn bad_values_are_errors() {
        for bad in [
            "--pub-only --sub-only",
            "--duration 0",
            "--rate 0",
            "--rate 20000",
            "-x 3",
            "--domain -1",
            "--bogus",
        ] {
            assert!(parse(bad).is_err(), "{bad}");
        }
    }
}
