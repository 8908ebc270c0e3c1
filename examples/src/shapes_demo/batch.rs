//! The line output of `shapes` (when stdout is not a terminal, or with `--batch`): one line per sample sent
//! (publishing only) or received, until the duration or count is reached, then the summary.

use std::time::{Duration, Instant};

use dds_runtime::prelude::*;

use super::args::ShapesArgs;
use super::session::{ReceivedEvent, Session};
use super::tally::{Tally, WrittenSummary};
use crate::shutdown;

/// Runs the batch mode on a session whose readers and publications are set up; returns the exit code
/// (1 when subscribing and nothing was received).
pub fn run(session: &mut Session, a: &ShapesArgs) -> DdsResult<u8> {
    let duration = a.duration.unwrap_or(Duration::from_secs(10));
    let colors = a.publish_colors();
    let role = match (a.publishes(), a.subscribes()) {
        (true, true) => "publishing and subscribing",
        (true, false) => "publishing",
        _ => "subscribing",
    };
    let shown_colors = if a.publishes() {
        format!(", colors {}", colors.join(" "))
    } else {
        String::new()
    };
    println!(
        "shapes: {role} on topic '{}' in domain {} for {:.1} s{shown_colors}",
        a.topic,
        a.domain,
        duration.as_secs_f64()
    );
    let start = Instant::now();
    let mut got = Tally::default();
    while !shutdown::requested()
        && start.elapsed() < duration
        && a.count.is_none_or(|n| got.samples < n)
    {
        for p in session.tick(Instant::now())? {
            if !a.subscribes() && !a.quiet {
                println!(
                    "sent     {:<10} {:<8} x={:3} y={:3}",
                    p.topic, p.shape.color, p.shape.x, p.shape.y
                );
            }
        }
        let wait = session
            .next_write()
            .saturating_duration_since(Instant::now())
            .min(Duration::from_millis(50));
        session.wait_for_data(wait)?;
        for r in session.receive()? {
            let ReceivedEvent::Data { shape: d, latency } = r.event else {
                continue;
            };
            got.record(&d.color, latency);
            if !a.quiet {
                println!(
                    "received {:<10} {:<8} x={:3} y={:3} size={:2}  ({:.0} us)",
                    r.topic,
                    d.color,
                    d.x,
                    d.y,
                    d.shapesize,
                    latency.as_secs_f64() * 1e6
                );
            }
        }
    }
    // Last samples and acknowledgments before the summary.
    session.flush();
    let written = a.publishes().then(|| WrittenSummary {
        written: session.written(),
        shapes: colors.len(),
        rate_hz: session.rate_hz(),
    });
    for line in got.summary(start.elapsed(), written, a.subscribes()) {
        println!("{line}");
    }
    Ok(u8::from(a.subscribes() && got.samples == 0))
}
