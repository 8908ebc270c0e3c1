//! The README's main job: the `shapes` demo publishes and subscribes over RTPS in one process (two
//! participants), and also feeds a subscriber we did not write.

use std::process::Command;
use std::time::Duration;

use super::harness::{cyclone_peer, our_bin, require_netns, Proc, Skip};
use crate::check;

/// `received N samples [BLUE: a, RED: b]` → the per-colour counts.
fn summary_counts(line: &str) -> Vec<(String, u64)> {
    let Some(inner) = line.split('[').nth(1).and_then(|s| s.strip_suffix(']')) else {
        return Vec::new();
    };
    inner
        .split(", ")
        .filter_map(|p| {
            let (c, n) = p.split_once(": ")?;
            Some((c.to_string(), n.parse().ok()?))
        })
        .collect()
}

#[test]
fn shapes_demo_publishes_and_receives_both_colours() {
    let _ = demo();
}

fn demo() -> Result<(), Skip> {
    require_netns()?;
    let mut c = Command::new(our_bin("shapes")?);
    c.args(["--duration", "3", "--domain", "131"]);
    let mut p = Proc::spawn("shapes", c);
    let status = p.wait_exit(Duration::from_secs(20));
    check!(
        status.is_some_and(|s| s.success()),
        &[&p],
        "shapes did not exit 0"
    );
    let live = p.grep(|l| l.starts_with("received Square"));
    check!(
        live.iter().any(|l| l.contains("BLUE")) && live.iter().any(|l| l.contains("RED")),
        &[&p],
        "no live positions of both colours"
    );
    let summary = p.grep(|l| l.starts_with("received ") && l.contains(" samples ["));
    let counts = summary
        .first()
        .map(|l| summary_counts(l))
        .unwrap_or_default();
    // 10 Hz per colour for 3 s, minus discovery time.
    check!(
        counts.len() == 2 && counts.iter().all(|(_, n)| *n >= 10),
        &[&p],
        "summary {summary:?}"
    );
    Ok(())
}

#[test]
fn shapes_demo_feeds_a_cyclone_subscriber() {
    let _ = to_cyclone();
}

fn to_cyclone() -> Result<(), Skip> {
    require_netns()?;
    let peer = cyclone_peer()?;
    let d = "132";
    let mut c = Command::new("python3");
    c.arg("-u")
        .arg(peer)
        .args(["-S", "-t", "Square", "-d", d, "-r"]);
    let sub = Proc::spawn("cyclone sub", c);
    let mut c = Command::new(our_bin("shapes")?);
    c.args([
        "--pub-only",
        "--duration",
        "6",
        "--domain",
        d,
        "--color",
        "GREEN",
    ]);
    let mut publ = Proc::spawn("shapes --pub-only", c);
    let got = sub.wait_line(Duration::from_secs(15), |l| {
        l.starts_with("Square") && l.contains("GREEN")
    });
    check!(
        got.is_some(),
        &[&sub, &publ],
        "Cyclone received nothing from shapes"
    );
    let _ = publ.wait_exit(Duration::from_secs(15));
    Ok(())
}
